// clock.hpp — wall-clock timestamps as the service writes them.
//
// Status documents, log lines and the database all carry RFC 3339 UTC
// timestamps with millisecond precision ("2026-11-22T04:23:46.123Z"); being
// fixed-width, they also sort correctly as text.
#pragma once

#include <chrono>
#include <string>

namespace hmpm::server {

/// `t` as RFC 3339 UTC with milliseconds.
std::string format_rfc3339(std::chrono::system_clock::time_point t);

/// The current time as RFC 3339 UTC with milliseconds.
std::string now_rfc3339();

}  // namespace hmpm::server
