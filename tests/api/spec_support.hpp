// spec_support.hpp — helpers of the tests that change a spec and look at
// one error or warning (test_plausibility.cpp, test_hints.cpp,
// test_softening_spec.cpp, test_cam_clay_spec.cpp).
#pragma once

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "test_support.hpp"

namespace hmpm::api::testing {

/// examples/NAME.json, parsed.
inline nlohmann::json example(const std::string& name) {
  return nlohmann::json::parse(read_text(source_path("examples/" + name + ".json")));
}

/// The message of the error (or, with `warning`, of the warning: the spec
/// must then be valid) at `path`; "" when there is none.
inline std::string issue_at(const nlohmann::json& spec, const std::string& path,
                            bool warning = false, const Limits& limits = {}) {
  const ParseResult r = parse_job(spec.dump(), limits);
  if (warning) {
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    if (r.job)
      for (const SpecError& w : r.job->warnings)
        if (w.path == path) return w.message;
    return "";
  }
  for (const SpecError& e : r.errors)
    if (e.path == path) return e.message;
  return "";
}

/// Fails unless parsing `spec` gives an error at `path` whose message holds
/// `part`; lists every error when it does not.
inline void expect_error(const nlohmann::json& spec, const std::string& path,
                         const std::string& part) {
  const ParseResult r = parse_job(spec.dump());
  bool found = false;
  std::string all;
  for (const SpecError& e : r.errors) {
    found = found || (e.path == path && e.message.find(part) != std::string::npos);
    all += "  " + e.path + ": " + e.message + "\n";
  }
  EXPECT_TRUE(found) << "wanted " << path << " (" << part << "), got:\n" << all;
}

/// The number right after `marker` in `message` (NaN when absent).
inline double number_after(const std::string& message, const std::string& marker) {
  const std::size_t at = message.find(marker);
  if (at == std::string::npos) return std::nan("");
  return std::stod(message.substr(at + marker.size()));
}

}  // namespace hmpm::api::testing
