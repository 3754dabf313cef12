// failures.hpp — how a run fails: the reports of the phases' failure paths
// (internal). Threads may find failures in any order; the lowest particle
// index wins, so the report is the same for any thread count. Called from
// hot loops only on the failure path (strings are built there only).
#pragma once

#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>

#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// A number in a failure message (six significant digits).
inline std::string number(double v) {
  return format_significant(v, 6);
}

/// The first failure of a run (of the lowest particle index, or of the run).
struct Failures {
  std::mutex mutex;
  bool failed = false;         ///< written under the mutex, read between phases
  std::int64_t particle = -1;  ///< -1: a failure of the run, not of a particle
  std::string what, hint;
  /// For the hints: the stable step estimate of the stage in force, and
  /// whether set-up reported warnings.
  double stable_limit = 0.0;
  bool warned = false;
  /// The first collapse found (time.on_collapse): a scheme's or the time
  /// loop's finding, written between phases.
  RunResult::Collapse collapse;

  void record(std::size_t p, std::string text, std::string advice) {
    std::lock_guard<std::mutex> lock(mutex);
    const auto index = static_cast<std::int64_t>(p);
    if (failed && particle <= index) return;  // also keeps a fail_run (-1)
    failed = true;
    particle = index;
    what = std::move(text);
    hint = std::move(advice);
  }

  /// Forgets a failure (a strength-reduction trial that lost a particle
  /// fails as a trial, and the state goes back to the last converged one).
  void clear() {
    std::lock_guard<std::mutex> lock(mutex);
    failed = false;
    particle = -1;
    what.clear();
    hint.clear();
  }

  /// A failure of the whole run, not of a particle (reported without one).
  void fail_run(std::string text, std::string advice) {
    std::lock_guard<std::mutex> lock(mutex);
    failed = true;
    particle = -1;
    what = std::move(text);
    hint = std::move(advice);
  }

  void nonfinite(std::size_t p, const char* quantity) {
    std::string advice = "reduce time.dt or time.courant (the stable step estimate is " +
                         number(stable_limit) +
                         " s), and check moduli, densities and loads for unrealistic values";
    if (warned)
      advice +=
          "; see the warnings: a material is where the u-p equations with Darcy's rho_f a "
          "term grow (that warning says what to change; hydraulic.darcy_inertia = false always "
          "removes it)";
    record(p, std::string("the ") + quantity + " became non-finite: the run diverged",
           std::move(advice));
  }

  void left_grid(std::size_t p) {
    record(p, "the particle left the grid",
           "enlarge grid.min/grid.max so the grid contains the motion, or restrain the "
           "body with boundaries");
  }

  void volume(std::size_t p, double j) {
    record(p,
           "the particle volume became " + std::string(j <= 0 ? "negative or zero" : "non-finite") +
               " (volume ratio " + number(j) + " in one step)",
           "reduce time.dt or time.courant, refine the grid, or use a gimp/bspline "
           "shape_function for large deformations");
  }
};

/// False (and a failure of the run naming the formula's place in the spec)
/// when a traction or boundary value of `problem` is not finite at time t.
template <int Dim>
bool loads_finite_at(const Problem& problem, bool fluid, Failures& failures, double t) {
  // The first value that is not finite, with its place in the spec.
  const auto check = [&](const FieldOfTime* f, const Location& where) {
    if (!f || !*f) return true;
    const double v = (*f)(t);
    if (std::isfinite(v)) return true;
    const std::string value = std::isnan(v) ? "NaN" : (v > 0 ? "+infinity" : "-infinity");
    failures.fail_run("the formula at /" + where.text() + " gave " + value + " at t = " +
                          number(t) + " s (a load or boundary value, not the solution diverging)",
                      "make the formula at /" + where.text() +
                          " finite at every time from 0 to time.end (a spec's formulas are "
                          "checked at 1001 instants before the run; this time lies between them)");
    return false;
  };
  for (std::size_t i = 0; i < problem.tractions.size(); ++i)
    for (int a = 0; a < Dim; ++a)
      if (!check(&problem.tractions[i].traction[a],
                 Location{"tractions"} / i / "traction" / static_cast<std::size_t>(a)))
        return false;
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& b = problem.boundaries[i];
    for (int a = 0; a < Dim; ++a)
      if (b.velocity[a] &&
          !check(&*b.velocity[a], Location{"boundaries"} / i /
                                      (b.from_acceleration[a] ? "acceleration" : "velocity") /
                                      static_cast<std::size_t>(a)))
        return false;
    if (fluid && b.pore_pressure &&
        !check(&*b.pore_pressure, Location{"boundaries"} / i / "pore_pressure"))
      return false;
  }
  return true;
}

}  // namespace hmpm
