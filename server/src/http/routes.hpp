// routes.hpp — the one route table and the router built from it.
//
// Each row says method, path pattern (ECMAScript regex, whole path), whether
// the Bearer token is needed, the handler and the query parameters the route
// accepts. Registration with cpp-httplib, the 404/405 answers, the `Allow`
// header, the pre-routing token check and the 400 for an unknown query
// parameter all read this table; nothing else lists paths, methods or
// parameters. To add an endpoint: a row in routes.cpp and a handler in the
// resource's file (handlers.hpp).
#pragma once

#include <httplib.h>

#include <regex>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "auth.hpp"
#include "context.hpp"

namespace hmpm::server::http {

enum class Method { get, post, put, patch, del };
/// "GET", "POST", ...
const char* method_name(Method method);

enum class Access {
  open,   ///< no token needed (health probes)
  token,  ///< Bearer token needed when the server has one
};

using Handler = void (*)(Context&, const httplib::Request&, httplib::Response&);
/// For routes with a request body: the body, read in full (bounded) before the call.
using BodyHandler = void (*)(Context&, const httplib::Request&, httplib::Response&,
                             const std::string& body);

struct Route {
  Route(Method method, std::string pattern, Access access,
        std::variant<Handler, BodyHandler> handler, std::vector<std::string> query = {})
      : method(method),
        pattern(std::move(pattern)),
        access(access),
        handler(handler),
        query(std::move(query)) {}

  Method method;
  std::string pattern;
  Access access;
  std::variant<Handler, BodyHandler> handler;
  /// The query parameters the handler reads; any other one is a 400
  /// invalid-parameter naming it and these (none listed: none accepted).
  std::vector<std::string> query;
};

/// Every route of hmpm-server (routes.cpp).
std::vector<Route> route_table();

class Router {
 public:
  Router(std::vector<Route> routes, Context& context, const Authenticator& auth);

  /// Registers every route, then OPTIONS and the 404/405 fallback for every method.
  void install(httplib::Server& server) const;

  /// False only for paths an Access::open route serves; every other path,
  /// unknown ones too, needs the token (a client without it learns nothing).
  bool needs_token(const std::string& path) const;

  /// The methods served on `path`, as for `Allow` ("GET, HEAD, DELETE,
  /// OPTIONS"); empty when no route matches. HEAD comes with GET (httplib
  /// serves it), OPTIONS with any (answered 204 with this list).
  std::string allowed_methods(const std::string& path) const;

 private:
  struct Compiled {
    Route route;
    std::regex regex;
  };
  void register_route(httplib::Server& server, const Compiled& c) const;
  void answer_unrouted(const httplib::Request& req, httplib::Response& res) const;
  /// Answers 400 and returns false when `req` has a query parameter `route`
  /// does not accept.
  static bool query_accepted(const Route& route, const httplib::Request& req,
                             httplib::Response& res);

  std::vector<Compiled> routes_;
  Context& context_;
  const Authenticator& auth_;
};

}  // namespace hmpm::server::http
