// problem.cpp — see problem.hpp.
#include "problem.hpp"

namespace hmpm::server::http {

std::string dump(const Json& doc) {
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

void send_json(httplib::Response& res, int status, const Json& doc) {
  res.status = status;
  res.set_content(dump(doc), "application/json");
}

void send_problem(httplib::Response& res, int status, const std::string& type,
                  const std::string& title, const std::string& detail, const Json& extra) {
  Json doc{{"type", type}, {"title", title}, {"status", status}, {"detail", detail}};
  for (const auto& [key, value] : extra.items()) doc[key] = value;
  res.status = status;
  res.set_content(dump(doc), "application/problem+json");
}

void send_not_found(httplib::Response& res, const std::string& what) {
  send_problem(res, 404, "not-found", "Not found", what);
}

void send_no_such_job(httplib::Response& res, const std::string& id) {
  send_not_found(res, "no job with id " + id);
}

void send_invalid_parameter(httplib::Response& res, const std::string& detail,
                            const std::string& name, const std::string& message,
                            const Json& extra) {
  Json members{{"errors", Json::array({Json{{"path", name}, {"message", message}}})}};
  for (const auto& [key, value] : extra.items()) members[key] = value;
  send_problem(res, 400, "invalid-parameter", "Invalid parameter", detail, members);
}

void send_too_large(httplib::Response& res, std::size_t limit_bytes) {
  send_problem(res, 413, "payload-too-large", "Payload too large",
               "the request body exceeds " + std::to_string(limit_bytes) + " bytes");
}

void send_store_failure(httplib::Response& res, bool no_space) {
  res.set_header("Retry-After", std::to_string(store_retry_after_s));
  if (no_space) {
    return send_problem(res, 507, "insufficient-storage", "Insufficient storage",
                        "no space left for the database (disk full, quota or file-size limit): "
                        "nothing was stored; retry later");
  }
  send_problem(res, 503, "store-unavailable", "Store unavailable",
               "the database cannot be written or read right now; nothing was stored, retry "
               "later");
}

void send_default_problem(httplib::Response& res) {
  switch (res.status) {
    case 400:
      return send_problem(res, 400, "bad-request", "Bad request",
                          "the request could not be read as HTTP");
    case 404:
      return send_not_found(res, "no such resource; see docs/api.md for the routes");
    case 413:
      return send_problem(res, 413, "payload-too-large", "Payload too large",
                          "the request body exceeds the server's limit");
    case 414:
      return send_problem(res, 414, "uri-too-long", "URI too long",
                          "the request target exceeds the server's limit");
    default:
      return send_problem(res, res.status, "http-error", "HTTP error",
                          "the request could not be served");
  }
}

}  // namespace hmpm::server::http
