// connection.hpp — how hmpm-server holds a connection: deadlines, head limits, threads.
//
// cpp-httplib 0.11.4 (Debian's compiled build) reads a request with a
// timeout per recv() only, so a client sending one header byte a second
// keeps a thread for ever; it takes any number of header lines; and its
// socket stream refuses to write to a client that half-closed after sending
// (it peeks for EOF before every write). Its compile-time limits cannot be
// changed, but the connection loop can: `HardenedServer` overrides the
// per-connection entry point (`process_and_close_socket`, virtual in the
// library) and drives httplib's own request parser (`process_request`)
// through a `Stream` of its own that
// - gives the request head (request line and headers) a total deadline and a
//   size and line-count limit, and the body a deadline of its own;
// - writes whatever the client's read side allows, half-closed or not;
// - drains, for a bounded time, a body the server refused without reading it
//   (a 401 before the body), so the client sees the answer instead of a reset.
// Its task queue grows with the connections (one thread each, as httplib
// needs) up to `max_connections`, so idle or slow connections cannot take the
// threads `/health` and everyone else need; beyond that a connection is
// answered 503 and closed at once.
#pragma once

#include <httplib.h>

#include <atomic>
#include <cstddef>
#include <string>
#include <string_view>

namespace hmpm::server::http {

struct ConnectionLimits {
  double head_timeout_s = 10.0;  ///< request line + headers, in total
  double body_timeout_s = 60.0;  ///< the whole body, in total
  /// An answer waits for its client as long as the socket's send queue
  /// shrinks; one that has not shrunk for this long (a stalled reader) ends
  /// the connection. Long enough for readers that pause between bursts
  /// (curl --limit-rate reads about 50 s worth at once, then waits).
  double send_stall_s = 120.0;
  std::size_t max_head_bytes = 65536;
  std::size_t max_header_count = 100;
  std::size_t core_threads = 24;      ///< threads kept ready
  std::size_t max_connections = 256;  ///< served at once; 503 and close beyond
  double linger_s = 1.0;              ///< draining an unread body after a refusal
};

/// Why the current request's head or body was cut off (for the status the
/// error handler answers); per thread, reset for every request.
enum class StreamLimit { none, head_timeout, head_too_large, body_timeout, malformed_head };
StreamLimit current_stream_limit();
/// For StreamLimit::malformed_head: what is wrong with the head (for the 400).
const std::string& malformed_head_reason();

/// What is wrong with a complete request head (request line, header lines
/// and the blank line, as received), or "" when it is well formed. Stricter
/// than httplib, which skips lines it cannot parse and takes the first of
/// repeated fields, so that the server and a proxy in front of it never
/// read one request two ways: every line ends in CRLF; no NUL, no other
/// control character but HTAB in a field; no folded lines (obs-fold); every
/// field line is `token ":" value` (no white space before the colon); at
/// most one Content-Length value; HTTP/1.1 with exactly one Host.
std::string head_problem(std::string_view head);

/// The pre-routing handler calls note_routed(): the head of the current
/// request was read and parsed (errors after it are the handlers').
void note_routed();
bool request_routed();

/// Asks the connection loop to close the connection once the current
/// response is written (its request body, if any, was not read).
void close_after_response();

class HardenedServer : public httplib::Server {
 public:
  explicit HardenedServer(ConnectionLimits limits);

  /// Raises the listen backlog of a bound socket (httplib's is 5, so a burst
  /// of connections would see SYNs dropped and retried a second later).
  void widen_backlog(int backlog);

  /// Connections being served now.
  std::size_t open_connections() const { return open_.load(); }

 private:
  bool process_and_close_socket(socket_t sock) override;

  ConnectionLimits limits_;
  std::atomic<std::size_t> open_{0};
};

}  // namespace hmpm::server::http
