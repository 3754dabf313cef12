// failures.hpp — how a run fails: the reports of the phases' failure paths
// (internal). Threads may find failures in any order; the lowest particle
// index wins, so the report is the same for any thread count. Called from
// hot loops only on the failure path (strings are built there only).
#pragma once

#include <mutex>
#include <string>
#include <utility>

#include "hmpm/format.hpp"
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
        "term grow (stiffer fluid_bulk_modulus or hydraulic.darcy_inertia = false)";
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
std::string Simulation<Dim, Shape>::number(double v) {
  return format_significant(v, 6);
}

}  // namespace hmpm
