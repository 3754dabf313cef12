// schemes/explicit_rules.cpp — the explicit scheme's stable-step rule and
// its check of a user dt (the problem-level half of explicit_scheme.hpp).
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

/// Per material: some body of it has particles. Only those limit the step
/// (a material no body uses has no wave and no diffusion). When none has
/// (a Problem check_problem refuses anyway), every material counts.
std::vector<bool> materials_with_particles(const Problem& problem) {
  std::vector<bool> used(problem.materials.size(), false);
  bool any = false;
  const std::vector<BodyLayout> layouts = body_layouts(problem, LayoutDetail::counts);
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    if (body.material < 0 || body.material >= static_cast<int>(used.size())) continue;
    if (body.particles_per_cell < 1 || layouts[b].count == 0) continue;
    used[static_cast<std::size_t>(body.material)] = true;
    any = true;
  }
  if (!any) used.assign(used.size(), true);
  return used;
}

namespace {

/// The explicit limits over the materials that have particles.
StableStep explicit_stable_step(const Problem& problem) {
  StableStep s;
  const double h = min_cell_size(problem);
  const double d = problem.dimension;
  s.mechanical = std::numeric_limits<double>::infinity();
  s.hydraulic = std::numeric_limits<double>::infinity();
  s.steady_mechanical = std::numeric_limits<double>::infinity();
  const std::vector<bool> with_particles = materials_with_particles(problem);
  // Surface pressures (boundary/surface_pressures.hpp): a particle's face
  // conductance C w_i N_j adds at most 4 C / (Q V) = 8 c_h / l^2 to the
  // largest eigenvalue of the lumped pressure equation (per node w_i is at
  // most 4 times the weight of the storage the particle gives it), l the shortest
  // particle length along a face's normal: the cell over the most particles
  // per cell, shortened by a fifth for a particle compressed as it settles.
  double face_length = std::numeric_limits<double>::infinity();
  if (!problem.surface_pressures.empty()) {
    int ppc = 1;
    for (const Body& body : problem.bodies) ppc = std::max(ppc, body.particles_per_cell);
    for (const SurfacePressure& sp : problem.surface_pressures) {
      const int a = std::clamp(sp.axis, 0, 2);
      const double cell = (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a];
      face_length = std::min(face_length, 0.8 * cell / ppc);
    }
  }
  // Varying parameters at their largest: the stiffest particle's wave and
  // the most conductive particle's diffusion limit the step.
  const std::vector<Material> limiting = limiting_materials(problem);
  for (std::size_t i = 0; i < limiting.size(); ++i) {
    if (!with_particles[i]) continue;
    const Material& m = limiting[i];
    const MaterialConstants mc = material_constants(m, problem.gravity_constant);
    const double c = std::sqrt(mc.undrained_p_modulus / mc.mixture_density);
    s.wave_speed = std::max(s.wave_speed, c);
    // Explicit central differences with lumped mass: omega_max <= sqrt(d) 2c/h,
    // stable for dt <= 2/omega_max = h / (c sqrt(d)).
    s.mechanical = std::min(s.mechanical, h / (c * std::sqrt(d)));
    if (stiffness_follows_state(mc))
      s.follows_state = true;
    else
      s.steady_mechanical = std::min(s.steady_mechanical, h / (c * std::sqrt(d)));
    if (m.hydraulic) {
      // Forward Euler on dp/dt = c_h lap p with lumped storage:
      // lambda_max = 4 d c_h / h^2 (plus the surface pressures' term),
      // stable for dt <= 2/lambda_max.
      const double c_h = mc.permeability_over_gamma / mc.storage;
      const double limit =
          std::isfinite(face_length)
              ? 2.0 / (4.0 * d * c_h / (h * h) + 8.0 * c_h / (face_length * face_length))
              : h * h / (2.0 * d * c_h);
      s.hydraulic = std::min(s.hydraulic, limit);
    }
  }
  s.limit = std::min(s.mechanical, s.hydraulic);
  s.chosen = problem.time.dt ? *problem.time.dt : problem.time.courant * s.limit;
  s.steps = fixed_step_count(problem.time.end - problem.time.start, s.chosen);
  follow_state(problem, s);
  return s;
}

/// A user dt above the explicit limit cannot run.
void check_explicit_step(const Problem& problem, const StableStep& s,
                         std::vector<ProblemIssue>& issues) {
  if (!problem.time.dt || *problem.time.dt <= s.limit * (1.0 + 1e-12)) return;
  auto fmt = [](double v) { return format_significant(v, 4); };
  std::string why = s.hydraulic < s.mechanical
                        ? "the explicit hydraulic diffusion limit h^2/(2 d k/(gamma_w Q))" +
                              std::string(problem.surface_pressures.empty()
                                              ? ""
                                              : " with the surface pressures' face term")
                        : "the mechanical limit h/(c sqrt(d)) with undrained wave speed c = " +
                              fmt(s.wave_speed) + " m/s";
  issues.push_back({{"time", "dt"},
                    "is " + fmt(*problem.time.dt) + " s, above the stable limit " + fmt(s.limit) +
                        " s (" + why + "); use dt <= " + format_upper_bound(s.limit) +
                        " or omit dt to let the solver choose " + fmt(0.5 * s.limit) + " s"});
}

}  // namespace

const SchemeRules& explicit_scheme_rules() {
  static const SchemeRules rules{explicit_stable_step, check_explicit_step};
  return rules;
}

}  // namespace hmpm
