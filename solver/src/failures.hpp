// failures.hpp — how a run fails: the reports of the phases' failure paths
// (internal). Threads may find failures in any order; the lowest particle
// index wins, so the report is the same for any thread count. Called from
// hot loops only on the failure path (strings are built there only).
#pragma once

#include <cmath>
#include <mutex>
#include <string>
#include <utility>

#include "hmpm/format.hpp"
#include "hmpm/run.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
void Simulation<Dim, Shape>::record_failure(std::size_t p, std::string what, std::string hint) {
  std::lock_guard<std::mutex> lock(failure_mutex_);
  const auto index = static_cast<std::int64_t>(p);
  if (failed_ && failure_particle_ <= index) return;  // also keeps a fail_run (-1)
  failed_ = true;
  failure_particle_ = index;
  failure_ = std::move(what);
  failure_hint_ = std::move(hint);
}

/// A failure of the whole run, not of a particle (reported without one).
template <int Dim, class Shape>
void Simulation<Dim, Shape>::fail_run(std::string what, std::string hint) {
  std::lock_guard<std::mutex> lock(failure_mutex_);
  failed_ = true;
  failure_particle_ = -1;
  failure_ = std::move(what);
  failure_hint_ = std::move(hint);
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::fail_nonfinite(std::size_t p, const char* what) {
  std::string hint = "reduce time.dt or time.courant (the stable step estimate is " +
                     number(stable_.limit) +
                     " s), and check moduli, densities and loads for unrealistic values";
  if (!warnings_.empty())
    hint +=
        "; see the warnings: a material is where the u-p equations with Darcy's rho_f a "
        "term grow (that warning says what to change; hydraulic.darcy_inertia = false always "
        "removes it)";
  record_failure(p, std::string("the ") + what + " became non-finite: the run diverged",
                 std::move(hint));
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::fail_left_grid(std::size_t p) {
  record_failure(p, "the particle left the grid",
                 "enlarge grid.min/grid.max so the grid contains the motion, or restrain the "
                 "body with boundaries");
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::fail_volume(std::size_t p, double j) {
  record_failure(p,
                 "the particle volume became " +
                     std::string(j <= 0 ? "negative or zero" : "non-finite") + " (volume ratio " +
                     number(j) + " in one step)",
                 "reduce time.dt or time.courant, refine the grid, or use a gimp/bspline "
                 "shape_function for large deformations");
}

template <int Dim, class Shape>
bool Simulation<Dim, Shape>::loads_finite_at(double t) {
  // The first value that is not finite, with its place in the spec.
  const auto check = [&](const FieldOfTime* f, const Location& where) {
    if (!f || !*f) return true;
    const double v = (*f)(t);
    if (std::isfinite(v)) return true;
    const std::string value = std::isnan(v) ? "NaN" : (v > 0 ? "+infinity" : "-infinity");
    fail_run("the formula at /" + where.text() + " gave " + value + " at t = " + number(t) +
                 " s (a load or boundary value, not the solution diverging)",
             "make the formula at /" + where.text() +
                 " finite at every time from 0 to time.end (a spec's formulas are checked at "
                 "1001 instants before the run; this time lies between them)");
    return false;
  };
  for (std::size_t i = 0; i < problem_.tractions.size(); ++i)
    for (int a = 0; a < Dim; ++a)
      if (!check(&problem_.tractions[i].traction[a],
                 Location{"tractions"} / i / "traction" / static_cast<std::size_t>(a)))
        return false;
  for (std::size_t i = 0; i < problem_.boundaries.size(); ++i) {
    const Boundary& b = problem_.boundaries[i];
    for (int a = 0; a < Dim; ++a)
      if (b.velocity[a] &&
          !check(&*b.velocity[a], Location{"boundaries"} / i /
                                      (b.from_acceleration[a] ? "acceleration" : "velocity") /
                                      static_cast<std::size_t>(a)))
        return false;
    if (fluid_ && b.pore_pressure &&
        !check(&*b.pore_pressure, Location{"boundaries"} / i / "pore_pressure"))
      return false;
  }
  return true;
}

template <int Dim, class Shape>
std::string Simulation<Dim, Shape>::number(double v) {
  return format_significant(v, 6);
}

}  // namespace hmpm
