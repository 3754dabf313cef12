// routes.cpp — the route table of hmpm-server and the router that serves it.
#include "routes.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "connection.hpp"
#include "exposure.hpp"
#include "handlers.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

// A job id, or a prefix of one (at least 4 hex digits): handlers resolve it
// with find_job (jobs.cpp).
const std::string job = "/jobs/([0-9a-f]{4}[0-9a-f-]{0,32})";

// An ensemble id (in full).
const std::string ensemble = "/ensembles/([0-9a-f-]{36})";

constexpr std::array<Method, 5> all_methods{Method::get, Method::post, Method::put, Method::patch,
                                            Method::del};

}  // namespace

std::vector<Route> route_table() {
  return {
      {Method::get, "/health", Access::open, get_health},
      {Method::get, "/metrics", Access::token, get_metrics},
      {Method::post, "/jobs", Access::token, post_job},
      {Method::get,
       "/jobs",
       Access::token,
       list_jobs,
       {"status", "name", "limit", "processID", "type"}},
      {Method::post, "/validate", Access::token, validate_spec},
      {Method::get, job, Access::token, get_job},
      {Method::del, job, Access::token, dismiss_job},
      {Method::post, job + "/cancel", Access::token, cancel_job},
      {Method::get, job + "/spec", Access::token, get_job_spec},
      {Method::get, job + "/log", Access::token, get_job_log},
      {Method::get, job + "/results", Access::token, get_manifest},
      {Method::get, job + "/results/(.+)", Access::token, get_result_file},
      {Method::get, job + "/events", Access::token, stream_events},
      // Ensembles (contract v3, ensembles.cpp); their samples are /jobs.
      {Method::post, "/ensembles", Access::token, post_ensemble},
      {Method::get, "/ensembles", Access::token, list_ensembles, {"status", "limit"}},
      {Method::get, ensemble, Access::token, get_ensemble},
      {Method::del, ensemble, Access::token, delete_ensemble},
      {Method::post, ensemble + "/cancel", Access::token, cancel_ensemble},
      {Method::get, ensemble + "/results", Access::token, get_ensemble_manifest},
      {Method::get, ensemble + "/results/(.+)", Access::token, get_ensemble_file},
      {Method::get, "/fields", Access::open, get_fields},
      {Method::get, "/ui(/.*)?", Access::open, get_ui},
      // OGC API – Processes (ogc.cpp); its jobs are the /jobs routes above.
      {Method::get,
       "/",
       Access::open,
       get_landing_page,
       {"f"}},  // links only; a browser goes on to /ui
      {Method::get, "/conformance", Access::token, get_conformance, {"f"}},
      {Method::get, "/processes", Access::token, list_processes, {"f"}},
      {Method::get, "/processes/([^/]+)", Access::token, get_process, {"f"}},
      {Method::post, "/processes/([^/]+)/execution", Access::token, execute_process},
  };
}

const char* method_name(Method method) {
  switch (method) {
    case Method::get:
      return "GET";
    case Method::post:
      return "POST";
    case Method::put:
      return "PUT";
    case Method::patch:
      return "PATCH";
    case Method::del:
      return "DELETE";
  }
  return "";
}

Router::Router(std::vector<Route> routes, Context& context, const Authenticator& auth)
    : context_(context), auth_(auth) {
  for (Route& r : routes) {
    std::regex regex(r.pattern);
    routes_.push_back({std::move(r), std::move(regex)});
  }
}

bool Router::needs_token(const std::string& path) const {
  for (const Compiled& c : routes_) {
    if (c.route.access == Access::open && std::regex_match(path, c.regex)) return false;
  }
  return true;
}

std::string Router::allowed_methods(const std::string& path) const {
  std::string allow;
  for (Method m : all_methods) {
    for (const Compiled& c : routes_) {
      if (c.route.method != m || !std::regex_match(path, c.regex)) continue;
      allow += (allow.empty() ? "" : ", ") + std::string(method_name(m));
      if (m == Method::get) allow += ", HEAD";
      break;
    }
  }
  if (!allow.empty()) allow += ", OPTIONS";
  return allow;
}

void Router::answer_unrouted(const httplib::Request& req, httplib::Response& res) const {
  const std::string allow = allowed_methods(req.path);
  if (allow.empty()) return send_not_found(res, "no such resource: " + req.path);
  res.set_header("Allow", allow);
  send_problem(res, 405, "method-not-allowed", "Method not allowed",
               req.method + " is not supported on " + req.path);
}

bool Router::query_accepted(const Route& route, const httplib::Request& req,
                            httplib::Response& res) {
  for (const auto& [name, value] : req.params) {
    if (std::find(route.query.begin(), route.query.end(), name) != route.query.end()) continue;
    std::string accepted;
    for (const std::string& q : route.query) accepted += (accepted.empty() ? "" : ", ") + q;
    const std::string detail =
        "unknown query parameter '" + name + "': " + req.method + " " + req.path +
        (accepted.empty() ? " takes no query parameters" : " accepts " + accepted);
    send_invalid_parameter(res, detail, name, "unknown parameter", Json{{"accepted", route.query}});
    return false;
  }
  return true;
}

namespace {

using PlainRegistrar = httplib::Server& (httplib::Server::*)(const std::string&,
                                                             httplib::Server::Handler);
using BodyRegistrar = httplib::Server& (
    httplib::Server::*)(const std::string&, httplib::Server::HandlerWithContentReader);

// httplib's registration function for `method`.
PlainRegistrar plain_registrar(Method method) {
  constexpr std::array<PlainRegistrar, 5> by_method{&httplib::Server::Get, &httplib::Server::Post,
                                                    &httplib::Server::Put, &httplib::Server::Patch,
                                                    &httplib::Server::Delete};
  return by_method[static_cast<std::size_t>(method)];
}

// The same for handlers that read the body; null for GET and DELETE.
BodyRegistrar body_registrar(Method method) {
  constexpr std::array<BodyRegistrar, 5> by_method{
      nullptr, &httplib::Server::Post, &httplib::Server::Put, &httplib::Server::Patch, nullptr};
  return by_method[static_cast<std::size_t>(method)];
}

}  // namespace

void Router::register_route(httplib::Server& server, const Compiled& c) const {
  const Route& route = c.route;
  const bool guarded = route.access == Access::token;
  if (const auto* plain = std::get_if<Handler>(&route.handler)) {
    (server.*plain_registrar(route.method))(
        route.pattern,
        [this, &route, guarded, f = *plain](const httplib::Request& req, httplib::Response& res) {
          // Requests with a body skipped the pre-routing check; check here.
          if (guarded && !auth_.authorized(req)) return auth_.refuse(res);
          if (!query_accepted(route, req, res)) return;
          f(context_, req, res);
          bound_compression(req, res);
        });
    return;
  }
  // A body route reads through a content reader: that bypasses httplib's
  // own form parsing, which refuses `application/x-www-form-urlencoded`
  // bodies (what `curl -d` sends) above 8 KiB.
  const BodyRegistrar registrar = body_registrar(route.method);
  if (!registrar)
    throw std::logic_error("route " + route.pattern + ": GET and DELETE take no body");
  (server.*registrar)(route.pattern,
                      [this, &route, guarded, f = std::get<BodyHandler>(route.handler)](
                          const httplib::Request& req, httplib::Response& res,
                          const httplib::ContentReader& reader) {
                        const std::size_t limit = context_.config.max_body_bytes;
                        std::string body;
                        bool too_large = false;
                        const bool complete = reader([&](const char* data, std::size_t n) {
                          if (body.size() + n > limit) {
                            too_large = true;
                            return false;
                          }
                          body.append(data, n);
                          return true;
                        });
                        if (!complete) {
                          if (too_large || res.status == 413) return send_too_large(res, limit);
                          close_after_response();  // the rest of the body is still on the wire
                          if (current_stream_limit() == StreamLimit::body_timeout) {
                            return send_problem(res, 408, "request-timeout", "Request timeout",
                                                "the request body did not arrive within the "
                                                "server's time limit");
                          }
                          return send_problem(res, 400, "bad-request", "Bad request",
                                              "the request body could not be read");
                        }
                        if (guarded && !auth_.authorized(req)) return auth_.refuse(res);
                        if (!query_accepted(route, req, res)) return;
                        f(context_, req, res, body);
                        bound_compression(req, res);
                      });
}

void Router::install(httplib::Server& server) const {
  for (const Compiled& c : routes_) register_route(server, c);
  // OPTIONS: 204 with Allow on a path some route serves, 404 elsewhere.
  server.Options(".*", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string allow = allowed_methods(req.path);
    if (allow.empty()) return send_not_found(res, "no such resource: " + req.path);
    res.set_header("Allow", allow);
    res.status = 204;
  });
  // Anything else: 405 on a path some route serves, 404 elsewhere.
  for (Method m : all_methods) {
    (server.*plain_registrar(m))(".*", [this](const httplib::Request& req, httplib::Response& res) {
      answer_unrouted(req, res);
    });
  }
}

}  // namespace hmpm::server::http
