// schemes/semi_implicit_rules.cpp — the semi-implicit scheme's stable-step
// rule and its check of a user dt (the problem-level half of
// semi_implicit_scheme.hpp).
//
// The pressure increment is implicit (a backward-Euler mass balance with the
// pressure's effect on the velocity and on Darcy's rho_f a substituted), so
// neither the fluid's stiffness (the undrained wave) nor the hydraulic
// diffusion bounds dt. The momentum of the skeleton stays explicit: dt <=
// h/(c_d sqrt(d)), c_d = sqrt(E_oed/rho) the drained P-wave speed of the
// mixture (rho the mixture density), over the materials that have
// particles (docs/schemes.md).
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
#include "schemes/state_step.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

namespace {

StableStep semi_implicit_stable_step(const Problem& problem) {
  StableStep s;
  const double h = min_cell_size(problem);
  const double d = problem.dimension;
  s.mechanical = std::numeric_limits<double>::infinity();
  s.hydraulic = std::numeric_limits<double>::infinity();  // no diffusion limit
  s.steady_mechanical = std::numeric_limits<double>::infinity();
  const std::vector<bool> with_particles = materials_with_particles(problem);
  // Varying parameters at their largest: the stiffest particle's wave.
  const std::vector<Material> limiting = limiting_materials(problem);
  for (std::size_t i = 0; i < limiting.size(); ++i) {
    if (!with_particles[i]) continue;
    const MaterialConstants mc = material_constants(limiting[i], problem.gravity_constant);
    const double c = std::sqrt(mc.constrained_modulus / mc.mixture_density);
    s.wave_speed = std::max(s.wave_speed, c);
    s.mechanical = std::min(s.mechanical, h / (c * std::sqrt(d)));
    if (stiffness_follows_state(mc))
      s.follows_state = true;
    else
      s.steady_mechanical = std::min(s.steady_mechanical, h / (c * std::sqrt(d)));
  }
  s.limit = s.mechanical;
  s.chosen = problem.time.dt ? *problem.time.dt : problem.time.courant * s.limit;
  s.steps = fixed_step_count(problem.time.end - problem.time.start, s.chosen);
  follow_state(problem, s);
  return s;
}

void check_semi_implicit_step(const Problem& problem, const StableStep& s,
                              std::vector<ProblemIssue>& issues) {
  if (!problem.time.dt || *problem.time.dt <= s.limit * (1.0 + 1e-12)) return;
  auto fmt = [](double v) { return format_significant(v, 4); };
  std::string message = "is ";
  message += fmt(*problem.time.dt);
  message += " s, above the semi_implicit stable limit ";
  message += fmt(s.limit);
  message += " s (the skeleton's wave h/(c sqrt(d)) with drained wave speed c = sqrt(E_oed/rho) = ";
  message += fmt(s.wave_speed);
  message += " m/s); use dt <= ";
  message += format_upper_bound(s.limit);
  message += ", omit dt to let the solver choose ";
  message += fmt(problem.time.courant * s.limit);
  message += " s, or use time.scheme \"quasi_static\" for a slow process without inertia";
  issues.push_back({{"time", "dt"}, std::move(message)});
}

}  // namespace

const SchemeRules& semi_implicit_scheme_rules() {
  static const SchemeRules rules{semi_implicit_stable_step, check_semi_implicit_step};
  return rules;
}

}  // namespace hmpm
