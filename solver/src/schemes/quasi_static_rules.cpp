// schemes/quasi_static_rules.cpp — the quasi-static scheme's step plan and
// its checks of the time control (the problem-level half of
// quasi_static_scheme.hpp).
//
// Backward Euler on the u-p equations without inertia is unconditionally
// stable: any dt runs, accuracy alone limits it. The step plan:
//   time.dt              fixed steps of dt (the last one ends at time.end);
//   time.growth          dt_0 = initial, dt_{n+1} = min(max, growth dt_n);
//   neither (automatic)  dt_0 = 0.1 h_min^2 / c_v (a tenth of the
//                        consolidation time of the smallest cell, c_v the
//                        largest coefficient of consolidation of the
//                        saturated materials), growth 1.2, max time.end / 20.
// Varying steps are shortened to land on the output instants.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "materials/varying.hpp"
#include "particle_layout.hpp"
#include "schemes/quasi_static_plan.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

StepGrowth quasi_static_growth(const Problem& problem) {
  if (problem.time.growth) return *problem.time.growth;
  const double end = problem.time.end - problem.time.start;  // the stage's length
  StepGrowth g;
  g.max = end / 20.0;
  g.growth = 1.2;
  double cv = 0.0;
  // Varying parameters at their largest (the fastest diffusion sets the first step).
  for (const Material& m : limiting_materials(problem)) {
    if (!m.hydraulic) continue;
    const MaterialConstants mc = material_constants(m, problem.gravity_constant);
    cv = std::max(cv, mc.permeability_over_gamma / (1.0 / mc.constrained_modulus + mc.storage));
  }
  const double h = min_cell_size(problem);
  g.initial = cv > 0 ? std::min(g.max, 0.1 * h * h / cv) : g.max;
  if (!(g.initial > 0)) g.initial = g.max;
  return g;
}

std::int64_t growth_step_count(const StepGrowth& g, double end) {
  if (!(g.initial > 0) || !(end > 0)) return 1;
  double t = 0.0, dt = g.initial;
  std::int64_t n = 0;
  // Growing part, then constant steps of the last length.
  while (t + dt < end && dt < g.max && g.growth > 1.0) {
    t += dt;
    ++n;
    dt = std::min(g.max, dt * g.growth);
  }
  return n + fixed_step_count(end - t, dt);
}

namespace {

StableStep quasi_static_stable_step(const Problem& problem) {
  StableStep s;
  const double end = problem.time.end - problem.time.start;  // the stage's length
  // Unconditionally stable: no limit below the whole run.
  s.mechanical = s.hydraulic = s.limit = end;
  for (const Material& m : limiting_materials(problem)) {
    const MaterialConstants mc = material_constants(m, problem.gravity_constant);
    s.wave_speed = std::max(s.wave_speed, std::sqrt(mc.constrained_modulus / mc.mixture_density));
  }
  if (problem.time.dt) {
    s.chosen = *problem.time.dt;
    s.steps = fixed_step_count(end, s.chosen);
    s.fixed = true;
    return s;
  }
  const StepGrowth g = quasi_static_growth(problem);
  s.chosen = g.initial;
  s.plan = g;
  s.steps = growth_step_count(g, end);
  s.fixed = false;
  return s;
}

void check_quasi_static(const Problem& problem, const StableStep&,
                        std::vector<ProblemIssue>& issues) {
  auto fmt = [](double v) { return format_significant(v, 4); };
  const TimeControl& t = problem.time;
  if (t.dt && t.growth)
    issues.push_back({{"time", "dt"}, "gives both a fixed dt and a growth object; keep one"});
  if (t.dt && !(*t.dt > 0))
    issues.push_back({{"time", "dt"}, "must be > 0 s (or omit it for automatic steps)"});
  if (t.growth) {
    const StepGrowth& g = *t.growth;
    if (!(g.initial > 0))
      issues.push_back({{"time", "dt", "initial"}, "must be > 0 s, e.g. " + fmt(t.end / 1000)});
    if (!(g.max >= g.initial))
      issues.push_back({{"time", "dt", "max"}, "must be >= initial (" + fmt(g.initial) + " s)"});
    if (!(g.growth >= 1.0)) issues.push_back({{"time", "dt", "growth"}, "must be >= 1 (e.g. 1.2)"});
  }
  // Friction walls: the scheme's Newton system has no Coulomb slip (no
  // active set of sticking and slipping nodes), so a friction wall would
  // act as frictionless; refused rather than run as something else.
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i)
    if (problem.boundaries[i].friction)
      issues.push_back(
          {Location{"boundaries"} / i / "friction",
           "is not supported by the quasi-static scheme: its Newton iterations have no "
           "Coulomb slip, so the wall would act as frictionless. For a wall that does not slip "
           "(a rough base), prescribe its tangential velocity too (e.g. \"velocity\": [0, 0]) "
           "and remove friction; for a smooth one, remove friction; for Coulomb slip use the "
           "explicit or semi_implicit scheme (a staged job can load gravity quasi-statically on "
           "a fixed base and then switch scheme and boundaries)"});
  const ImplicitControl& c = t.implicit;
  if (!(c.tolerance > 0 && c.tolerance < 1))
    issues.push_back({{"time", "implicit", "tolerance"}, "must be in (0, 1), e.g. 1e-8"});
  if (c.max_iterations < 1)
    issues.push_back({{"time", "implicit", "max_iterations"}, "must be >= 1, e.g. 25"});
  if (c.max_cutbacks < 0)
    issues.push_back({{"time", "implicit", "max_cutbacks"}, "must be >= 0, e.g. 8"});
  if (!(c.linear_tolerance > 0 && c.linear_tolerance < 1))
    issues.push_back({{"time", "implicit", "linear_tolerance"}, "must be in (0, 1), e.g. 1e-12"});
}

}  // namespace

const SchemeRules& quasi_static_scheme_rules() {
  static const SchemeRules rules{quasi_static_stable_step, check_quasi_static};
  return rules;
}

}  // namespace hmpm
