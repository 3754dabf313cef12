// server_setup.hpp — cpp-httplib 0.11.4 configured for hmpm-server.
//
// Everything that is about the connection rather than a resource: thread
// pool, timeouts, socket options, the checks before routing, the problem
// documents for errors httplib detects itself, the exception handler and the
// request log. A few sharp edges of this httplib version are handled here:
// - it enforces the body limit only for a declared Content-Length, so bodies
//   without one (chunked, or read-until-close) are refused with 411 before
//   routing;
// - without an exception handler it copies `e.what()` into a response
//   header, so one is installed that logs the text and answers a generic 500;
// - its default socket options set SO_REUSEPORT, which lets a second server
//   bind the same port and take half the connections: only SO_REUSEADDR is set.
#pragma once

#include <httplib.h>

#include "auth.hpp"
#include "context.hpp"
#include "routes.hpp"

namespace hmpm::server::http {

/// Configures `server` and installs the routes of `router`.
void configure_server(httplib::Server& server, Context& context, const Router& router,
                      const Authenticator& auth);

}  // namespace hmpm::server::http
