// drain.hpp — ending the connections a stopping server still holds.
//
// cpp-httplib's stop() closes the listener, but listen_after_bind() returns
// only when every connection thread has ended, and a client that trickles a
// request one byte per second keeps its thread reading for ever (each recv
// meets its read timeout). After a bounded drain, Service::stop() shuts
// down the sockets of the connections that are left, so their reads and
// writes fail at once, the threads end and the store is closed as usual.
// cpp-httplib 0.11.4 hands no accepted socket to the application, so they
// are found among the process's descriptors: connected TCP sockets whose
// local port is the server's.
#pragma once

namespace hmpm::server::http {

/// shutdown(2) on every connected TCP socket of this process whose local
/// port is `port` (not the listener). Returns how many were shut down.
int shut_down_connections(int port);

}  // namespace hmpm::server::http
