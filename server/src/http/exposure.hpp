// exposure.hpp — what a request must show before any handler sees it, so
// that a web page cannot use a server it can reach (loopback included):
//
// - Host: the listening address (the address the connection arrived on, the
//   --host given, localhost on loopback) or a name of --allowed-host; any
//   other is 421 (a DNS-rebinding page sends its own name);
// - Origin: a write (POST, PUT, PATCH, DELETE) that carries an Origin must
//   come from the server's own origin (the dashboard) or one of
//   --allowed-origin (403 otherwise); only those get CORS headers;
// - a POST with a body must say `Content-Type: application/json` (415
//   otherwise: an HTML form or a "simple" cross-site request cannot);
// - Range: several ranges are ignored (the whole answer, 200), and so is a
//   Range whose If-Range the route cannot check (all but result files).
#pragma once

#include <httplib.h>

#include "hmpm/server/service.hpp"

namespace hmpm::server::http {

/// Whether the request's Host names this server (no Host, HTTP/1.0: yes).
bool host_allowed(const httplib::Request& req, const ServiceConfig& config);

/// Whether a write from the request's Origin (none: not a browser's
/// cross-site request) is accepted.
bool origin_allowed(const httplib::Request& req, const ServiceConfig& config);

/// Adds CORS headers for an origin of --allowed-origin (nothing otherwise).
void add_cors_headers(const httplib::Request& req, const ServiceConfig& config,
                      httplib::Response& res);

/// A POST whose body is not declared JSON (a body, and a media type other
/// than application/json).
bool body_not_json(const httplib::Request& req);

/// Clears the request's ranges where they would cost more than they save:
/// several ranges (httplib would build a multipart answer in memory, one
/// copy per range), or an If-Range the route cannot compare (every route but
/// result files, which check it against their ETag).
void limit_ranges(const httplib::Request& req);

/// Bounds the cost of compressing the answer: httplib's brotli runs at
/// quality 11 (about 1 MB/s of JSON, 30 times gzip's CPU), so bodies above
/// `brotli_max_bytes` are compressed with gzip instead when the client takes
/// it (or sent as they are): "br" is taken out of the request's
/// Accept-Encoding, which httplib reads when it writes the answer.
void bound_compression(const httplib::Request& req, const httplib::Response& res);
constexpr std::size_t brotli_max_bytes = std::size_t{32} * 1024;

}  // namespace hmpm::server::http
