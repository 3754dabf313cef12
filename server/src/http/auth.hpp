// auth.hpp — the Bearer token check, the one place that decides it.
//
// Which routes need the token is a column of the route table (routes.hpp);
// this class only answers "does this request carry the token" and writes the
// 401. The router calls it where cpp-httplib lets a request be refused: before
// routing for requests without a body, on `Expect: 100-continue` before the
// body is sent, and after a body was read (so an unread body is never left
// on a kept-alive connection).
#pragma once

#include <httplib.h>

#include <string>

namespace hmpm::server::http {

class Authenticator {
 public:
  /// `token` empty: every request is authorized.
  explicit Authenticator(std::string token) : token_(std::move(token)) {}

  /// True when no token is configured or `Authorization: Bearer <token>` matches
  /// (compared in time independent of where a guess goes wrong).
  bool authorized(const httplib::Request& req) const;

  /// 401 with `WWW-Authenticate` and a problem document.
  void refuse(httplib::Response& res) const;

 private:
  std::string token_;
};

}  // namespace hmpm::server::http
