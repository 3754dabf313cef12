// job_log.hpp — one JSON object per line on stderr.
//
// Every HTTP request and every job transition is one line, so the log can be
// filtered with jq or shipped to any collector without a parser. Lines from
// different threads never interleave (one write per line under a mutex).
#pragma once

#include <nlohmann/json.hpp>

namespace hmpm::server {

/// Writes `fields` plus "ts" (RFC 3339) as one line to stderr. Never throws.
void log_line(nlohmann::ordered_json fields);

/// Turns logging off (tests that want a quiet stderr) or back on.
void set_logging_enabled(bool enabled);

}  // namespace hmpm::server
