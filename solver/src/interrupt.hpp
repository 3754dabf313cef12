// interrupt.hpp — the cooperative stop of a run's set-up (internal): the
// RunOptions cancel flag and wall-time limit, checked while particles are
// generated, their initial-field formulas evaluated and the geostatic state
// computed, so a job with an expensive set-up honours DELETE and its wall
// time as the time loop does. The clock of the wall-time limit starts here,
// before set-up, and the time loop keeps it.
//
// Set-up loops call `poll(i)` once per item: it costs a mask test, and every
// `period` items one relaxed atomic load and one clock read. A stop throws
// SetupInterrupted, which run_simulation turns into the run's result.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <utility>

#include "hmpm/format.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// Thrown by SetupInterrupt when set-up must stop; status is cancelled or failed.
struct SetupInterrupted {
  RunStatus status;
  std::string message;
};

class SetupInterrupt {
 public:
  using Clock = std::chrono::steady_clock;
  /// Items between two checks: a few hundred microseconds of set-up work
  /// even with long formulas, and the check itself (~20 ns) well under 1 %.
  static constexpr std::uint64_t period = 256;

  SetupInterrupt() = default;
  SetupInterrupt(const std::atomic<bool>* cancel, double wall_time_limit_s)
      : cancel_(cancel), limit_s_(wall_time_limit_s) {}

  /// When the run (set-up included) started: the wall-time limit counts from here.
  Clock::time_point start() const { return start_; }

  /// What set-up is doing, for the message of a stop ("generating particles").
  void stage(const char* what) { stage_ = what; }

  /// Checks every `period`-th call (i counts the items of a loop).
  void poll(std::uint64_t i) const {
    if ((i & (period - 1)) == 0) check();
  }

  /// Throws SetupInterrupted if the run was cancelled or is over its wall time.
  void check() const {
    if (cancel_ && cancel_->load(std::memory_order_relaxed))
      throw SetupInterrupted{RunStatus::cancelled,
                             std::string("cancelled during set-up (") + stage_ + ")"};
    if (limit_s_ > 0) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
      if (elapsed > limit_s_)
        throw SetupInterrupted{
            RunStatus::failed,
            "wall-time limit of " + format_significant(limit_s_, 6) + " s reached during set-up (" +
                stage_ + ", after " + format_significant(elapsed, 3) +
                " s), before the first step. What to change: use fewer particles or simpler "
                "initial-field formulas, or ask for a longer limit."};
    }
  }

 private:
  const std::atomic<bool>* cancel_ = nullptr;
  double limit_s_ = 0.0;
  Clock::time_point start_ = Clock::now();
  const char* stage_ = "set-up";
};

}  // namespace hmpm
