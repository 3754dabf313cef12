// schemes/state_step.hpp — the explicit and semi-implicit stable step when a
// soil's stiffness changes with its state (internal).
//
// Modified Cam-Clay's bulk modulus K = (1 + e) p'/kappa grows with the mean
// effective stress: a step chosen once from a reference stiffness is unstable
// where the soil is stiffer and needlessly small where it is softer. With an
// automatic dt the explicit and semi-implicit schemes therefore ask for the
// step before each one (StableStep::follows_state, fixed false): the
// mechanical limit h/(c sqrt(d)) of the stiffest particle now, with the
// materials of constant stiffness and the hydraulic limit as the rules
// computed them, times time.courant. One pass over the particles, reading
// three numbers each; nothing for runs without such a material.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"
#include "state/particles.hpp"

namespace hmpm {

/// Material `mc`'s elastic stiffness changes with its state.
inline bool stiffness_follows_state(const MaterialConstants& mc) {
  return mc.model == Model::modified_cam_clay;
}

/// After a scheme's rule: with an automatic dt and a material whose
/// stiffness follows its state, the steps are the scheme's to choose.
inline void follow_state(const Problem& problem, StableStep& s) {
  if (!s.follows_state || problem.time.dt) {
    s.follows_state = false;
    return;
  }
  s.fixed = false;
  s.plan = {s.chosen, s.chosen, 1.0};
}

/// The mechanical stable limit h/(c sqrt(d)) over the particles whose
/// stiffness follows their state, at their state now (inf if none): c the
/// P-wave speed sqrt((K + 4G/3 [+ 1/Q when undrained]) / rho) with Cam-Clay's
/// K = (1 + e) max(p', floor)/kappa and G = K shear_factor, rho the
/// material's initial density (its density grows as it compresses: the
/// speed is then lower, so the step is on the safe side).
template <int Dim>
double state_mechanical_limit(const ParticleState<Dim>& particles,
                              const std::vector<MaterialConstants>& constants, double h,
                              bool undrained) {
  using M = constitutive::ModifiedCamClayModel;
  double stiffest = 0.0;  // the largest P-wave modulus over density, m^2/s^2
  if (static_cast<int>(particles.internal.size()) < M::state_variables)
    return std::numeric_limits<double>::infinity();
  const std::vector<double>& e = particles.internal[M::void_ratio_slot];
  const std::size_t n = particles.size();
  for (std::size_t p = 0; p < n; ++p) {
    const MaterialConstants& mc = constants[particles.material[p]];
    if (!stiffness_follows_state(mc)) continue;
    const auto& s = particles.stress[p];
    const double mean = -(s[0] + s[1] + s[2]) / 3.0;  // p', compression positive
    // e not yet set (0) reads as e0, as the update does.
    const double v = 1.0 + (e[p] > 0.0 ? e[p] : mc.cam_clay.initial_void_ratio);
    const double k = v * std::max(mean, constitutive::mean_stress_floor) / mc.cam_clay.kappa;
    double modulus = k * (1.0 + 4.0 / 3.0 * mc.cam_clay.shear_factor);
    if (undrained && mc.saturated) modulus += 1.0 / mc.storage;
    stiffest = std::max(stiffest, modulus / mc.mixture_density);
  }
  if (!(stiffest > 0)) return std::numeric_limits<double>::infinity();
  return h / (std::sqrt(stiffest) * std::sqrt(static_cast<double>(Dim)));
}

/// The step before each one of a scheme whose StableStep follows state:
/// time.courant times the smallest of the constant limits and the state's.
/// `s` the StableStep of `problem` under the scheme.
template <int Dim>
double state_stable_dt(const Problem& problem, const StableStep& s,
                       const std::vector<MaterialConstants>& constants,
                       const ParticleState<Dim>& particles, bool undrained) {
  const double limit =
      std::min({s.steady_mechanical, s.hydraulic,
                state_mechanical_limit(particles, constants, min_cell_size(problem), undrained)});
  return problem.time.courant * limit;
}

}  // namespace hmpm
