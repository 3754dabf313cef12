// calibration.cpp — the machine speed of the wall-time estimate: a fixed
// small explicit problem (2D, linear shape functions, elastic, saturated,
// 24 x 24 cells with 2 x 2 particles each: 2304 reference particles, 200
// steps) run five times on one thread; the median of solve seconds /
// (the model's work for it, in reference particle-steps) is the
// calibration. About 0.04 s per run on the development machine, so well
// under a second in all; the median discards a run slowed by other
// processes.
#include <algorithm>
#include <array>

#include "cost_model.hpp"
#include "hmpm/api/job.hpp"

namespace hmpm::api {
namespace {

constexpr const char* reference_spec = R"json({
  "name": "calibration", "dimension": 2,
  "grid": {"min": [0, 0], "max": [1, 1], "cells": [24, 24]},
  "materials": {"soil": {"model": "linear_elastic", "density": 2650, "youngs_modulus": 1e7,
    "poisson_ratio": 0.3, "hydraulic": {"porosity": 0.3, "hydraulic_conductivity": 1e-5,
    "fluid_bulk_modulus": 1e8, "fluid_density": 1000}}},
  "bodies": [{"material": "soil", "box": {"min": [0, 0], "max": [1, 1]}, "particles_per_cell": 2}],
  "gravity": [0, -9.81],
  "boundaries": [{"nodes": {"box": {"min": [0, 0], "max": [1, 0]}}, "velocity": [0, 0]},
                 {"nodes": {"box": {"min": [0, 1], "max": [1, 1]}}, "pore_pressure": 0}],
  "time": {"end": 4e-3, "dt": 2e-5}
})json";

}  // namespace

Calibration calibrate(int threads) {
  Calibration c;
  c.threads = std::max(threads, 1);
  const ParseResult parsed = parse_job(reference_spec);
  if (!parsed.job) return c;  // cannot happen: the spec is fixed (tested)
  const Problem& p = parsed.job->problem;
  // The model's seconds for this run with one second per reference
  // particle-step, less its fixed part: what a measured second scales.
  Calibration unit;
  unit.seconds_per_particle_step = 1.0;
  const double steps = static_cast<double>(parsed.job->cost.steps);
  const double fixed = cost::scheme_cost(p, Scheme::explicit_scheme, Calibration{0.0, 1, false})
                           .wall_seconds;  // the per-run overhead alone
  const double work = cost::scheme_cost(p, Scheme::explicit_scheme, unit).wall_seconds - fixed;
  if (!(work > 0) || !(steps > 0)) return c;
  RunOptions options;
  options.threads = 1;
  std::array<double, 5> per{};
  for (double& v : per) {
    const RunResult r = run(p, options);
    if (r.status != RunStatus::successful || !(r.solve_seconds > 0)) return c;
    v = r.solve_seconds / work;
  }
  std::sort(per.begin(), per.end());
  c.seconds_per_particle_step = per[2];
  c.measured = true;
  return c;
}

}  // namespace hmpm::api
