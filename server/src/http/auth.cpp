// auth.cpp — see auth.hpp.
#include "auth.hpp"

#include <cctype>
#include <string_view>

#include "problem.hpp"

namespace hmpm::server::http {
namespace {

// Compares without an early exit, so the time taken does not reveal how
// many leading characters of a guessed token were right.
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = static_cast<unsigned char>(diff | (a[i] ^ b[i % (b.empty() ? 1 : b.size())]));
  }
  return diff == 0 && !b.empty();
}

}  // namespace

bool Authenticator::authorized(const httplib::Request& req) const {
  if (token_.empty()) return true;
  const std::string header = req.get_header_value("Authorization");
  constexpr std::string_view scheme = "bearer ";
  if (header.size() <= scheme.size()) return false;
  for (std::size_t i = 0; i < scheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(header[i])) != scheme[i]) return false;
  }
  return same_secret(header.substr(scheme.size()), token_);
}

void Authenticator::refuse(httplib::Response& res) const {
  res.set_header("WWW-Authenticate", "Bearer realm=\"hmpm\"");
  send_problem(res, 401, "unauthorized", "Unauthorized",
               "send 'Authorization: Bearer <token>' with the server's token");
}

}  // namespace hmpm::server::http
