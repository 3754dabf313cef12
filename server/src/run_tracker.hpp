// run_tracker.hpp — what a running job reached, from the solver's progress
// reports: simulated time, end time, steps taken and the range of the time
// step, for the store's run columns and the status document's `run`.
//
// The solver reports (hmpm::Progress) about every progress interval of wall
// time and once at the end; the step size between two reports is their mean
// (simulated time over steps), so dt_min/dt_max bound the mean step over
// each reporting interval: a cut-back shorter than one interval is averaged
// in. A run too short for any interval has one mean: end time over steps.
#pragma once

#include <algorithm>
#include <cstdint>

#include "hmpm/run.hpp"
#include "hmpm/server/store.hpp"

namespace hmpm::server {

class RunTracker {
 public:
  /// Takes one progress report; returns what the run has reached.
  const RunProgress& observe(const hmpm::Progress& p) {
    run_.percent = std::clamp(100.0 * p.fraction, 0.0, 100.0);
    run_.end_time = p.end_time;
    advance(p.step, p.time);
    return run_;
  }

  /// The run's end as RunResult reports it (steps taken, time reached).
  const RunProgress& finish(std::int64_t steps, double time) {
    if (steps > 0) advance(steps, time);
    return run_;
  }

  const RunProgress& current() const { return run_; }

 private:
  void advance(std::int64_t step, double time) {
    if (step > last_step_ && time > last_time_) {
      const double dt = (time - last_time_) / static_cast<double>(step - last_step_);
      run_.dt_min = run_.dt_min > 0 ? std::min(run_.dt_min, dt) : dt;
      run_.dt_max = std::max(run_.dt_max, dt);
      last_step_ = step;
      last_time_ = time;
    }
    run_.steps = std::max(run_.steps, step);
    run_.time = std::max(run_.time, time);
  }

  RunProgress run_;
  std::int64_t last_step_ = 0;
  double last_time_ = 0.0;
};

}  // namespace hmpm::server
