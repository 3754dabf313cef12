// strength_reduction.hpp — the factor of safety by strength reduction
// (Problem::strength_reduction; internal).
//
// After the last stage (the gravity state, an excavation...), with the
// loads of the job's end held: the strength of every Mohr-Coulomb and
// Drucker-Prager material is divided by F,
//   c_F = c / F,   tan(phi_F) = tan(phi) / F,   psi_F = min(psi, phi_F),
// the tensile strength by F as well, and a softening material's residual
// c and phi alike (a particle's own c and phi where they
// are random fields), and the quasi-static scheme looks for
// equilibrium from the converged state at the previous F
// (QuasiStaticScheme::strength_reduce: Newton with the consistent tangent,
// prescribed displacements held, pore pressures held). F starts at 1 and
// rises by `increment`; a value that does not converge is halved back
// towards the last converged one (a bisection) until the two are within
// `resolution`. A trial fails in one of three ways:
//  - no equilibrium within strength_reduction.max_iterations Newton
//    iterations (100 by default, each with a backtracking line search:
//    QuasiStaticScheme::backtrack). With perfectly plastic soil, past the
//    factor of safety no stress field within the reduced strength
//    balances gravity and the loads (Griffiths & Lane 1999, Geotechnique
//    49(3), use this criterion with an iteration ceiling);
//  - equilibrium only after a slide: a particle moved further than
//    strength_reduction.displacement_limit since F = 1 (by default 0.5 %
//    of the soil's height, soil_height()). The updated-Lagrangian
//    geometry of a slope that has slid 0.05-0.5 m is a new, flatter
//    equilibrium that small-strain analysis does not have: without this,
//    F is where no slide can reach equilibrium any more, which depends on
//    the grid (docs/verification.md: 4 % between 1 and 0.25 m cells with
//    psi = 0; with psi = phi trials converged after dilatant slides of
//    metres). F moves by about 1 % per doubling of the limit (measured
//    with psi = phi at 0.5 m cells: 25, 49 and 100 mm);
//  - a converged state that loses a particle (it leaves the grid, or its
//    volume or a value stops being finite).
// A failed trial puts the state back to the last converged F (a copy).
// The displacement since F = 1 is kept at every converged F. The mechanism
// (displacement and plastic strain since
// F = 1 at the largest converged F) is the run's last snapshot.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "collapse_watch.hpp"
#include "failures.hpp"
#include "materials/material.hpp"
#include "schemes/quasi_static_scheme.hpp"
#include "simulation.hpp"
#include "time_loop.hpp"

namespace hmpm {

/// The strength of `m` divided by `factor` (c, tan(phi), the tensile
/// strength; the dilatancy angle at most the reduced friction angle).
inline Material reduced_strength(Material m, double factor) {
  constexpr double degree = 3.14159265358979323846 / 180.0;
  std::visit(
      [factor](auto& model) {
        using T = std::decay_t<decltype(model)>;
        if constexpr (std::is_same_v<T, MohrCoulomb> || std::is_same_v<T, DruckerPrager>) {
          model.cohesion /= factor;
          model.tensile_strength /= factor;
          model.friction_angle_deg =
              std::atan(std::tan(model.friction_angle_deg * degree) / factor) / degree;
          model.dilatancy_angle_deg = std::min(model.dilatancy_angle_deg, model.friction_angle_deg);
        }
        if constexpr (std::is_same_v<T, MohrCoulomb>) {
          if (model.softening) {  // the residual strength is reduced alike
            MohrCoulomb::Softening& s = *model.softening;
            s.residual_cohesion /= factor;
            s.residual_friction_angle_deg =
                std::atan(std::tan(s.residual_friction_angle_deg * degree) / factor) / degree;
            s.residual_dilatancy_angle_deg =
                std::min(s.residual_dilatancy_angle_deg, s.residual_friction_angle_deg);
          }
        }
      },
      m.plasticity);
  return m;
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::reduce_strength(RunResult& result, double t,
                                             const RunOptions& options) {
  const StrengthReduction& sr = *job_.strength_reduction;
  RunResult::StrengthReductionResult& out = result.strength_reduction;
  out.done = true;
  // The mechanism is what the reduction adds: displacement and plastic
  // strain from here.
  reset_displacement();
  std::fill(particles_.plastic_strain.begin(), particles_.plastic_strain.end(), 0.0);
  QuasiStaticScheme<Dim, Shape> scheme(context());
  std::vector<MaterialConstants> reduced;
  // Where c or phi varies (a random field), every particle's return reads
  // its own strength constants (particles_.varying, also the particles of
  // homogeneous materials then): those are reduced with the materials' and
  // put back when the reduction ends.
  VaryingConstants& varying = particles_.varying;
  const std::vector<constitutive::MohrCoulombConstants> own_mohr_coulomb = varying.mohr_coulomb;
  const std::vector<constitutive::DruckerPragerConstants> own_drucker_prager =
      varying.drucker_prager;
  struct Restore {
    VaryingConstants& v;
    const std::vector<constitutive::MohrCoulombConstants>& mc;
    const std::vector<constitutive::DruckerPragerConstants>& dp;
    ~Restore() {
      v.mohr_coulomb = mc;
      v.drucker_prager = dp;
    }
  } restore{varying, own_mohr_coulomb, own_drucker_prager};
  auto reduce_own_strength = [&](double factor) {
    if (varying.mohr_coulomb.empty() && varying.drucker_prager.empty()) return;
    const std::vector<Material>& materials = model_.problem.materials;
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      Material m = materials[particles_.material[p]];
      for (const VaryingParameter& v : m.varying)
        set_parameter(m, v.parameter, varying.value[static_cast<std::size_t>(v.parameter)][p]);
      const MaterialConstants c =
          material_constants(reduced_strength(m, factor), model_.problem.gravity_constant);
      if (!varying.mohr_coulomb.empty()) varying.mohr_coulomb[p] = c.mohr_coulomb;
      if (!varying.drucker_prager.empty()) varying.drucker_prager[p] = c.drucker_prager;
    }
  };
  out.displacement_limit = sr.displacement_limit ? *sr.displacement_limit
                                                 : StrengthReduction::slide_fraction *
                                                       soil_height(model_.problem, particles_);
  ParticleState<Dim> saved;  // the state before each trial
  std::string why;           // what failed the last failing trial
  double f = 1.0, step = sr.increment;
  out.factors.push_back(f);
  out.max_displacement.push_back(0.0);
  while (f < sr.max_factor) {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) {
      result.status = RunStatus::cancelled;
      result.message = "cancelled during the strength reduction at F = " + number(f);
      return;
    }
    const double next = std::min(f + step, sr.max_factor);
    reduced.clear();
    for (const Material& m : model_.problem.materials)
      reduced.push_back(
          material_constants(reduced_strength(m, next), model_.problem.gravity_constant));
    reduce_own_strength(next);
    ++out.attempts;
    // A converged trial moves the particles: a trial that then loses one
    // (it leaves the grid, its volume inverts) has gone past the
    // mechanism, and the state goes back to the last converged F.
    saved = particles_;
    const bool converged = scheme.strength_reduce(reduced, t, sr.max_iterations);
    const double moved = converged ? scheme.max_displacement() : 0.0;
    if (converged && !(moved > out.displacement_limit)) {
      f = next;
      out.factors.push_back(f);
      out.max_displacement.push_back(moved);
      continue;
    }
    if (converged) {  // in equilibrium only after sliding further than displacement_limit
      particles_ = saved;
      ++out.past_displacement_limit;
      why = "equilibrium only after a slide of " + number(moved) +
            " m, more than strength_reduction.displacement_limit " +
            number(out.displacement_limit) + " m";
    } else if (failures_.failed) {
      if (failures_.particle < 0) return;  // a failure of the run: it fails
      particles_ = saved;
      why = "its equilibrium lost a particle (" + failures_.what + ")";
      failures_.clear();
      ++out.lost_particle;
    } else {
      why = "no equilibrium within " + std::to_string(sr.max_iterations) +
            " Newton iterations (strength_reduction.max_iterations)";
    }
    out.failed_at = next;
    if (next - f <= sr.resolution * (1.0 + 1e-9)) break;
    step = 0.5 * (next - f);
  }
  out.factor = f;
  out.message =
      std::isnan(out.failed_at)
          ? "strength reduction: the soil is in equilibrium up to F = " + number(f) +
                " (strength_reduction.max_factor): the factor of safety is at least that"
          : "strength reduction: factor of safety F = " + number(f) +
                " (converged at F = " + number(f) + "; at F = " + number(out.failed_at) + " " +
                why + "; largest displacement since F = 1: " + number(out.max_displacement.back()) +
                " m)";
  out.backtracks = scheme.backtracks();
  RunResult part;
  scheme.report(part);
  add_iterations(result.iterations, part.iterations);
}

}  // namespace hmpm
