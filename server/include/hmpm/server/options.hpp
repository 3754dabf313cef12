// options.hpp — the hmpm-server command line, parsed into a ServiceConfig.
//
// Kept apart from main() so the tests can check every flag and every way to
// get one wrong. Problems come back as a message, never as an exit.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hmpm/server/service.hpp"

namespace hmpm::server {

struct ParsedOptions {
  std::optional<ServiceConfig> config;  ///< set when `error` is empty and not `help`
  std::string error;                    ///< what is wrong, for stderr
  bool help = false;                    ///< --help was given
};

/// Parses `args` (without the program name). `env_token` is HMPM_TOKEN (may
/// be null); --token or --token-file wins over it; an empty token in any of
/// them is an error, as is a non-loopback --host without a token unless
/// --allow-no-token is given.
ParsedOptions parse_options(const std::vector<std::string>& args, const char* env_token);

/// True for localhost, 127.0.0.0/8 and ::1.
bool is_loopback_host(const std::string& host);
/// The --help text.
std::string usage();

}  // namespace hmpm::server
