// exit_codes.hpp — the exit statuses of hmpm's command-line tools, in one table.
//
// `hmpm` (run, validate, spec-keys) and `hmpm-server` return these values
// from main; scripts and the contract (hmpm run/validate: 0, 2, 3) rely on
// them. The two tools disagree on a bad command line (hmpm 1, hmpm-server 2)
// for historical reasons; both values are kept, each named for its tool,
// so that no script sees a different status.
#pragma once

namespace hmpm::api {

enum class ExitCode : int {
  ok = 0,            ///< both tools: success
  usage = 1,         ///< hmpm: bad command line, or SPEC cannot be read
  failure = 1,       ///< hmpm-server: cannot listen, store failure, service stopped on error
  invalid_spec = 2,  ///< hmpm run/validate: the spec is invalid (one "/pointer: message" per line)
  server_usage = 2,  ///< hmpm-server: bad command line (options)
  run_failed = 3,    ///< hmpm run: the run failed or its files could not be written
};

/// The value main returns.
constexpr int exit_status(ExitCode code) {
  return static_cast<int>(code);
}

}  // namespace hmpm::api
