// store/write_probe.hpp — the write half of a store's /health probe, at most
// once a second (health checks may come far more often); in between, the
// last write's outcome stands. Shared by the SQLite and PostgreSQL stores.
#pragma once

#include <chrono>
#include <mutex>
#include <string>

#include "hmpm/server/store.hpp"

namespace hmpm::server {

/// What one probe write found.
struct ProbeOutcome {
  std::string error;  ///< "" when written
  bool no_space = false;
};

class WriteProbe {
 public:
  /// Runs `write` (returning a ProbeOutcome) unless it ran less than a
  /// second ago; throws StoreFailure with the outcome's error, if any.
  template <class Write>
  void check(Write&& write) {
    const auto now = std::chrono::steady_clock::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (now - last_ < std::chrono::seconds(1)) {
        if (!last_outcome_.error.empty())
          throw StoreFailure(last_outcome_.error, last_outcome_.no_space);
        return;
      }
      last_ = now;
    }
    const ProbeOutcome outcome = write();
    std::lock_guard<std::mutex> lock(mutex_);
    last_outcome_ = outcome;
    if (!outcome.error.empty()) throw StoreFailure(outcome.error, outcome.no_space);
  }

 private:
  std::mutex mutex_;
  std::chrono::steady_clock::time_point last_{};
  ProbeOutcome last_outcome_;
};

}  // namespace hmpm::server
