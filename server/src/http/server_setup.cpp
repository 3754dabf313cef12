// server_setup.cpp — see server_setup.hpp.
#include "server_setup.hpp"

#include <sys/socket.h>

#include <charconv>
#include <chrono>
#include <optional>

#include "connection.hpp"
#include "exposure.hpp"
#include "job_log.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

using SteadyClock = std::chrono::steady_clock;

// When the current request reached routing, for the log line's duration.
thread_local SteadyClock::time_point request_start{};
thread_local bool request_timed = false;

std::optional<std::uint64_t> content_length(const httplib::Request& req) {
  if (!req.has_header("Content-Length")) return std::nullopt;
  const std::string v = req.get_header_value("Content-Length");
  std::uint64_t n = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
  if (ec != std::errc() || end != v.data() + v.size()) return std::nullopt;
  return n;
}

// SO_REUSEADDR only (a restart may bind while old connections sit in
// TIME_WAIT); never SO_REUSEPORT, so a port in use stays in use.
void socket_options(socket_t sock) {
  int yes = 1;
  setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
}

// The methods httplib parses; any other token fails its request-line parser
// (a 400 that the error handler turns into 501).
bool httplib_method(const std::string& m) {
  for (const char* known :
       {"GET", "HEAD", "POST", "PUT", "DELETE", "CONNECT", "OPTIONS", "TRACE", "PATCH", "PRI"}) {
    if (m == known) return true;
  }
  return false;
}

bool served_method(const std::string& m) {
  return m == "GET" || m == "HEAD" || m == "POST" || m == "PUT" || m == "PATCH" || m == "DELETE" ||
         m == "OPTIONS";
}

void not_implemented(httplib::Response& res, const std::string& method) {
  send_problem(res, 501, "not-implemented", "Not implemented",
               "method " + method.substr(0, 32) +
                   " is not implemented; hmpm-server serves GET, HEAD, POST, PUT, PATCH, DELETE "
                   "and OPTIONS");
}

// An error httplib found before routing (or a deadline of connection.hpp):
// the status it deserves, and the connection is closed after it, since what
// follows on it cannot be trusted to start a request.
void answer_unrouted_error(const httplib::Request& req, httplib::Response& res) {
  close_after_response();
  switch (current_stream_limit()) {
    case StreamLimit::head_timeout:
    case StreamLimit::body_timeout:
      return send_problem(res, 408, "request-timeout", "Request timeout",
                          "the request was not received within the server's time limit");
    case StreamLimit::head_too_large:
      return send_problem(res, 431, "headers-too-large", "Request header fields too large",
                          "the request line and headers exceed the server's limit of size or "
                          "number of header lines");
    case StreamLimit::malformed_head:
      return send_problem(res, 400, "bad-request", "Bad request",
                          "malformed request head: " + malformed_head_reason());
    case StreamLimit::none:
      break;
  }
  if (res.status == 400 && !req.method.empty() && !httplib_method(req.method) &&
      (req.version == "HTTP/1.1" || req.version == "HTTP/1.0")) {
    return not_implemented(res, req.method);
  }
  if (res.body.empty()) send_default_problem(res);
}

}  // namespace

void configure_server(httplib::Server& http, Context& context, const Router& router,
                      const Authenticator& auth) {
  const ServiceConfig& config = context.config;
  // Threads and the connection deadlines: HardenedServer (connection.hpp).
  http.set_socket_options(socket_options);
  http.set_payload_max_length(config.max_body_bytes);
  http.set_keep_alive_timeout(2);  // bounds how long shutdown waits for idle connections
  http.set_keep_alive_max_count(100);
  // Headers and body go out in separate writes: without TCP_NODELAY, Nagle's
  // algorithm and the client's delayed ACK add ~40 ms to every response.
  http.set_tcp_nodelay(true);
  http.set_read_timeout(10);

  http.set_pre_routing_handler([&router, &auth, &config](const httplib::Request& req,
                                                         httplib::Response& res) {
    request_start = SteadyClock::now();
    request_timed = true;
    note_routed();
    const auto length = content_length(req);
    if (!host_allowed(req, config)) {
      if (length.value_or(0) > 0) close_after_response();
      send_problem(res, 421, "misdirected-request", "Misdirected request",
                   "this server does not answer to Host '" +
                       req.get_header_value("Host").substr(0, 100) +
                       "'; use its address, or start it with --allowed-host NAME");
      return httplib::Server::HandlerResponse::Handled;
    }
    limit_ranges(req);
    add_cors_headers(req, config, res);
    if (!served_method(req.method)) {
      if (length.value_or(0) > 0) close_after_response();
      not_implemented(res, req.method);
      return httplib::Server::HandlerResponse::Handled;
    }
    const bool body_method = req.method == "POST" || req.method == "PUT" || req.method == "PATCH";
    if (req.has_header("Transfer-Encoding") || (body_method && !req.has_header("Content-Length"))) {
      res.set_header("Connection", "close");
      close_after_response();
      send_problem(res, 411, "length-required", "Length required",
                   "send the body with a Content-Length header (Content-Length: 0 when there is "
                   "none, e.g. curl -d ''); chunked or unterminated bodies are not accepted");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (req.has_header("Content-Length") && !length) {
      res.set_header("Connection", "close");
      close_after_response();
      send_problem(res, 400, "bad-request", "Bad request", "Content-Length is not a number");
      return httplib::Server::HandlerResponse::Handled;
    }
    const bool write = body_method || req.method == "DELETE";
    if (write && !origin_allowed(req, config)) {
      if (length.value_or(0) > 0) close_after_response();
      send_problem(res, 403, "cross-origin-refused", "Cross-origin write refused",
                   "a page from " + req.get_header_value("Origin").substr(0, 100) +
                       " may not change this server's jobs; start the server with "
                       "--allowed-origin ORIGIN to allow it");
      return httplib::Server::HandlerResponse::Handled;
    }
    // The token is checked before a body is read: a refused body is never
    // read into memory; the connection drains it briefly and closes.
    if (router.needs_token(req.path) && !auth.authorized(req)) {
      if (length.value_or(0) > 0) close_after_response();
      auth.refuse(res);
      return httplib::Server::HandlerResponse::Handled;
    }
    if (body_not_json(req)) {
      close_after_response();
      send_problem(res, 415, "unsupported-media-type", "Unsupported media type",
                   "send the body as JSON with 'Content-Type: application/json' (curl: -H "
                   "'Content-Type: application/json' --data-binary @spec.json)");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });

  // `Expect: 100-continue` (curl, for large bodies): refuse before the body is sent.
  http.set_expect_100_continue_handler(
      [&config, &router, &auth](const httplib::Request& req, httplib::Response& res) {
        // Any answer but 100 leaves the body unread on the connection: close it.
        if (content_length(req).value_or(0) > config.max_body_bytes) {
          close_after_response();
          send_too_large(res, config.max_body_bytes);
          return 413;
        }
        if (router.needs_token(req.path) && !auth.authorized(req)) {
          close_after_response();
          auth.refuse(res);
          return 401;
        }
        return 100;
      });

  http.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
        if (!request_routed() || current_stream_limit() != StreamLimit::none) {
          answer_unrouted_error(req, res);
        } else if (res.body.empty()) {
          send_default_problem(res);
        }
        return httplib::Server::HandlerResponse::Handled;
      }));

  http.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown exception";
        std::optional<bool> store_no_space;  // set: the store failed (503/507, not a bug)
        try {
          std::rethrow_exception(std::move(ep));
        } catch (const StoreFailure& e) {
          what = e.what();
          store_no_space = e.no_space();
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        log_line({{"event", store_no_space ? "store_error" : "error"},
                  {"method", req.method},
                  {"path", req.path},
                  {"detail", what}});
        res = httplib::Response();
        if (store_no_space) return send_store_failure(res, *store_no_space);
        send_problem(res, 500, "internal-error", "Internal server error",
                     "the server could not complete the request; its log has the details");
      });

  http.set_logger([&context](const httplib::Request& req, const httplib::Response& res) {
    context.metrics.count_request(res.status);
    Json line{{"event", "request"},
              {"method", req.method},
              {"path", req.path},
              {"status", res.status},
              {"remote", req.remote_addr}};
    if (request_timed) {
      line["ms"] =
          std::chrono::duration<double, std::milli>(SteadyClock::now() - request_start).count();
      request_timed = false;
    }
    log_line(std::move(line));
  });

  router.install(http);
}

}  // namespace hmpm::server::http
