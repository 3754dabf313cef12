// materials/cam_clay_state.hpp — the initial state variables of Modified
// Cam-Clay particles (internal): the void ratio e0 and the
// preconsolidation pressure p'c, from the particle's own value where the
// material's p'c is a random field (Material::varying), the material's
// preconsolidation_pressure (a function of the particle's position) or
// from its overconsolidation ratio times the particle's initial mean
// effective stress (modified_cam_clay.hpp's floor below 100 Pa).
//
// Set-up calls it once the initial stresses are known (initial fields and
// the geostatic state) on the particles of the run and on the dormant ones
// of the bodies later stages add (their initial fields); a stage that gives
// a body Cam-Clay calls it again on that body's particles, whose state was
// reset (Simulation::switch_materials), with their stress at that moment.
// Runs at set-up and between stages only.
#pragma once

#include <algorithm>
#include <cstddef>
#include <variant>
#include <vector>

#include "hmpm/problem.hpp"
#include "material.hpp"
#include "state/particles.hpp"

namespace hmpm {

/// Writes e and p'c of every Cam-Clay particle p of `state` for which
/// `select(p)` holds and whose slots are not yet initialised (0).
template <int Dim, class Select>
void initialise_cam_clay_state(ParticleState<Dim>& state, const std::vector<Material>& materials,
                               const std::vector<MaterialConstants>& constants, Select&& select) {
  using M = constitutive::ModifiedCamClayModel;
  if (static_cast<int>(state.internal.size()) < M::state_variables) return;
  std::vector<double>& e = state.internal[M::void_ratio_slot];
  std::vector<double>& pc = state.internal[M::preconsolidation_slot];
  // The particles' own p'c where their material's is a random field
  // (VaryingConstants::value, generated at set-up).
  const std::vector<double>& varied =
      state.varying.value[static_cast<std::size_t>(MaterialParameter::preconsolidation_pressure)];
  std::vector<bool> varied_pc(materials.size(), false);
  for (std::size_t k = 0; k < materials.size(); ++k)
    for (const VaryingParameter& v : materials[k].varying)
      if (v.parameter == MaterialParameter::preconsolidation_pressure) varied_pc[k] = true;
  for (std::size_t p = 0; p < state.size(); ++p) {
    const std::size_t k = state.material[p];
    if (constants[k].model != Model::modified_cam_clay || !select(p)) continue;
    const auto& cc = std::get<ModifiedCamClay>(materials[k].plasticity);
    const Voigt& s = state.stress[p];
    const double mean = -(s[0] + s[1] + s[2]) / 3.0;
    if (!(pc[p] > 0.0) && varied_pc[k] && !varied.empty() && varied[p] > 0.0) {
      pc[p] = std::max(varied[p], constitutive::mean_stress_floor);  // a random field's
    } else if (!(pc[p] > 0.0) && cc.preconsolidation_pressure) {
      Vec3 x{0.0, 0.0, 0.0};
      for (int a = 0; a < Dim; ++a) x[static_cast<std::size_t>(a)] = state.x0[p][a];
      pc[p] = std::max(cc.preconsolidation_pressure(x), constitutive::mean_stress_floor);
    }
    constitutive::cam_clay_start_state(constants[k].cam_clay, mean, e[p], pc[p]);
  }
}

template <int Dim>
void initialise_cam_clay_state(ParticleState<Dim>& state, const std::vector<Material>& materials,
                               const std::vector<MaterialConstants>& constants) {
  initialise_cam_clay_state(state, materials, constants, [](std::size_t) { return true; });
}

}  // namespace hmpm
