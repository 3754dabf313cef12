// setup.hpp — building a Simulation from a Problem (internal; included by
// the simulation_instance.cpp instantiations): the grid, the material
// constants, the particles, the compiled constraints and loads, and the
// geostatic initial state. Runs once per run; allocates, never per step.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "boundary/constraints.hpp"
#include "boundary/tractions.hpp"
#include "geostatic.hpp"
#include "materials/cam_clay_state.hpp"
#include "materials/varying.hpp"
#include "particle_layout.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
Simulation<Dim, Shape>::Simulation(const Problem& problem, const RunOptions& options)
    : job_(problem), interrupt_(options.cancel, options.wall_time_limit_s) {
  model_.problem = stage_problem(problem, 0);
  setup_grid();
  setup_materials();
  setup_particles();
  setup_stages();
  interrupt_.stage("compiling boundaries and tractions");
  interrupt_.check();
  model_.constraints =
      compile_constraints<Dim>(model_.problem, grid_, model_.grid_max, model_.fluid, particles_);
  model_.tractions = compile_tractions<Dim>(model_.problem, particles_, particles_.volume, grid_);
  if (model_.fluid) {
    model_.fluxes = compile_fluxes<Dim>(model_.problem, particles_, particles_.volume, grid_);
    model_.surface_pressures =
        compile_surface_pressures<Dim>(model_.problem, particles_, particles_.volume, grid_);
  }
  if (model_.problem.output.reactions_interval > 0)
    setup_reactions<Dim>(reactions_, model_.constraints, grid_.count,
                         model_.problem.boundaries.size());
  setup_geostatic();
  // Cam-Clay's e0 and p'c, from the initial stresses just set.
  initialise_cam_clay_state(particles_, model_.problem.materials, model_.constants);
  initialise_cam_clay_state(dormant_, model_.problem.materials, model_.constants);
  interrupt_.check();
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_grid() {
  for (int a = 0; a < Dim; ++a) {
    grid_.cells[a] = model_.problem.grid.cells[a];
    grid_.origin[a] = model_.problem.grid.min[a];
    grid_.h[a] = (model_.problem.grid.max[a] - model_.problem.grid.min[a]) / grid_.cells[a];
    grid_.inv_h[a] = 1.0 / grid_.h[a];
  }
  for (int a = 0; a < Dim; ++a) model_.grid_max[a] = model_.problem.grid.max[a];
  grid_.count = 1;
  for (int a = 0; a < Dim; ++a) {
    grid_.stride[a] = grid_.count;
    grid_.count *= grid_.cells[a] + 1;
  }
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_materials() {
  for (const Material& m : model_.problem.materials) {
    model_.constants.push_back(material_constants(m, model_.problem.gravity_constant));
    const Hydraulic h = m.hydraulic.value_or(Hydraulic{});
    model_.inv_ks.push_back(std::isinf(h.solid_bulk_modulus) ? 0.0 : 1.0 / h.solid_bulk_modulus);
    model_.inv_kf.push_back(1.0 / h.fluid_bulk_modulus);
    model_.fluid = model_.fluid || m.hydraulic.has_value();
    model_.plastic = model_.plastic || model_.constants.back().model != Model::linear_elastic;
  }
  for (const Body& body : model_.problem.bodies)
    model_.state_variables =
        std::max(model_.state_variables,
                 state_variable_count(model_.constants[static_cast<std::size_t>(body.material)]));
  for (const Stage& s : job_.stages)  // materials a stage gives a body
    for (const Stage::BodyMaterial& bm : s.body_materials)
      model_.state_variables =
          std::max(model_.state_variables,
                   state_variable_count(model_.constants[static_cast<std::size_t>(bm.material)]));
  for (const ProblemIssue& w : problem_warnings(job_))
    warnings_.push_back(w.where.text().append(": ").append(w.message));
  for (int a = 0; a < Dim; ++a) model_.gravity[a] = model_.problem.gravity[a];
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_particles() {
  const bool gimp = std::is_same_v<Shape, shape::Gimp>;
  interrupt_.stage("generating particles and evaluating their initial fields");
  const std::vector<BodyLayout> layouts = body_layouts(model_.problem);
  std::int64_t count = 0;
  for (const BodyLayout& l : layouts) count += l.count;
  particles_.resize(static_cast<std::size_t>(count), model_.fluid, gimp, model_.state_variables,
                    model_.plastic);
  grid_.resize(model_.fluid);
  std::size_t p = 0;
  double cell_volume = 1.0;
  for (int a = 0; a < Dim; ++a) cell_volume *= grid_.h[a];
  for (std::size_t b = 0; b < model_.problem.bodies.size(); ++b) {
    const Body& body = model_.problem.bodies[b];
    const BodyLayout& layout = layouts[b];
    const MaterialConstants& mc = model_.constants[static_cast<std::size_t>(body.material)];
    const int ppc = body.particles_per_cell;
    for (std::size_t k = 0; k < layout.positions.size(); ++k) {
      interrupt_.poll(p);
      const Vec3& x3 = layout.positions[k];
      const double v0 = layout.volumes[k];
      for (int a = 0; a < Dim; ++a) particles_.x[p][a] = x3[a];
      particles_.x0[p] = particles_.x[p];
      particles_.volume[p] = v0;
      particles_.mass[p] = mc.mixture_density * v0;
      particles_.material[p] = static_cast<std::uint16_t>(body.material);
      // GIMP half-length in cell units: of the sub-cell, or of the cube
      // of a points body's particle volume.
      if (gimp) {
        const double lp = body.points ? 0.5 * std::pow(v0 / cell_volume, 1.0 / Dim) : 0.5 / ppc;
        particles_.half_length[p] = std::max(lp, shape::Gimp::min_half_length);
        particles_.box_inverse[p] = 0.5 / particles_.half_length[p];
      }
      const InitialFields& init = body.initial;
      for (int a = 0; a < Dim; ++a)
        if (init.velocity[a]) particles_.v[p][a] = init.velocity[a](x3);
      for (int c = 0; c < 6; ++c)
        if (init.effective_stress[c]) particles_.stress[p][c] = init.effective_stress[c](x3);
      if (model_.fluid && mc.saturated) {
        const double p0 = init.pore_pressure ? init.pore_pressure(x3) : 0.0;
        particles_.pressure[p] = p0;
        particles_.pressure_out[p] = p0;
        particles_.porosity[p] = mc.porosity;
      }
      ++p;
    }
  }
  setup_varying(layouts);
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_varying(const std::vector<BodyLayout>& layouts) {
  const std::vector<Material>& materials = model_.problem.materials;
  std::array<bool, material_parameter_count> varies{};
  bool strength = false;
  for (const Material& m : materials)
    for (const VaryingParameter& v : m.varying) {
      varies[static_cast<std::size_t>(v.parameter)] = true;
      strength = strength || v.parameter == MaterialParameter::cohesion ||
                 v.parameter == MaterialParameter::friction_angle;
    }
  if (std::none_of(varies.begin(), varies.end(), [](bool v) { return v; })) return;
  interrupt_.stage("generating the random fields of material parameters");
  // Each material's values at its particles, in the job's order (the
  // particles are still in that order: stages move them later).
  std::vector<std::vector<std::vector<double>>> values(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    if (!materials[m].varying.empty()) values[m] = varying_values(model_.problem, m, layouts);
  const std::size_t n = particles_.size();
  VaryingConstants& out = particles_.varying;
  for (int k = 0; k < material_parameter_count; ++k)
    if (varies[static_cast<std::size_t>(k)]) out.value[static_cast<std::size_t>(k)].resize(n);
  auto has_model = [&](Model model) {
    return std::any_of(model_.constants.begin(), model_.constants.end(),
                       [&](const MaterialConstants& c) { return c.model == model; });
  };
  if (varies[static_cast<std::size_t>(MaterialParameter::youngs_modulus)]) out.elastic.resize(n);
  if (varies[static_cast<std::size_t>(MaterialParameter::hydraulic_conductivity)])
    out.permeability_over_gamma.resize(n);
  if (strength && has_model(Model::mohr_coulomb)) out.mohr_coulomb.resize(n);
  if (strength && has_model(Model::drucker_prager)) out.drucker_prager.resize(n);
  std::vector<Material> own = materials;               // a particle's material, its values set
  std::vector<std::size_t> next(materials.size(), 0);  // each material's next particle
  for (std::size_t p = 0; p < n; ++p) {
    interrupt_.poll(p);
    const std::uint16_t mat = particles_.material[p];
    Material& m = own[mat];
    const std::size_t j = next[mat]++;
    for (std::size_t i = 0; i < m.varying.size(); ++i)
      set_parameter(m, m.varying[i].parameter, values[mat][i][j]);
    for (int k = 0; k < material_parameter_count; ++k)
      if (!out.value[static_cast<std::size_t>(k)].empty())
        out.value[static_cast<std::size_t>(k)][p] =
            parameter_of(m, static_cast<MaterialParameter>(k));
    const MaterialConstants c = m.varying.empty()
                                    ? model_.constants[mat]
                                    : material_constants(m, model_.problem.gravity_constant);
    if (!out.elastic.empty()) out.elastic[p] = c.elastic;
    if (!out.permeability_over_gamma.empty())
      out.permeability_over_gamma[p] = c.permeability_over_gamma;
    if (!out.mohr_coulomb.empty()) out.mohr_coulomb[p] = c.mohr_coulomb;
    if (!out.drucker_prager.empty()) out.drucker_prager[p] = c.drucker_prager;
  }
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_stages() {
  job_particles_ = static_cast<std::int64_t>(particles_.size());
  bool moves = false, switches = false;
  for (const Stage& s : job_.stages) {
    moves = moves || !s.add_bodies.empty() || !s.remove_bodies.empty();
    switches = switches || !s.body_materials.empty();
  }
  if (!moves && !switches) return;
  interrupt_.stage("setting the stages' bodies aside");
  // Each particle's body (a stage switching a body's material needs it
  // too) by its job index.
  std::int64_t first = 0;
  for (const BodyLayout& l : body_layouts(model_.problem, LayoutDetail::counts)) {
    body_begin_.push_back(first);
    first += l.count;
  }
  particles_.id.resize(particles_.size());
  for (std::size_t p = 0; p < particles_.size(); ++p)
    particles_.id[p] = static_cast<std::int64_t>(p);
  if (!moves) return;
  dormant_.resize(0, model_.fluid, std::is_same_v<Shape, shape::Gimp>, model_.state_variables,
                  model_.plastic);
  move_stage_particles(0);
}

/// Geostatic initial state (Problem::initial_state.geostatic): effective
/// stress and pore pressure from the layered closed form at every particle.
/// The reported pressure is the closed form; the transported pressure state
/// is then corrected so that the nodal pressure the first step computes
/// from it (a storage-weighted average, biased by a fraction of a cell at
/// boundary nodes where particles lie on one side only) is the hydrostatic
/// nodal field itself. Its interpolation then gives back the closed form at
/// every particle, so pressure, effective stress and weight balance at
/// every node and the ground stays at rest.
template <int Dim, class Shape>
void Simulation<Dim, Shape>::setup_geostatic() {
  if (!model_.problem.initial_state.geostatic) return;
  interrupt_.stage("computing the geostatic state");
  // Without the bodies a stage adds (their particles wait in dormant_).
  const GeostaticState g = geostatic_state(
      body_begin_.empty() ? model_.problem : initial_ground(model_.problem), &interrupt_);
  if (g.vertical.size() != particles_.size())
    throw std::invalid_argument(
        "the geostatic state has " + std::to_string(g.vertical.size()) +
        " particles where the "
        "first stage has " +
        std::to_string(particles_.size()) +
        ": a body a stage adds overlaps the ground; make them meet without overlapping");
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    geostatic_voigt(g, p, particles_.stress[p].data());
    if (model_.fluid && model_.constants[particles_.material[p]].saturated) {
      particles_.pressure[p] = g.pressure[p];
      particles_.pressure_out[p] = g.pressure[p];
    }
  }
  if (model_.fluid) balance_initial_pressure_state();
}

/// Richardson iteration on the particle pressure state s until the nodal
/// pressure mapped from it interpolates back to the reported pressure at
/// every saturated particle: s += p_out - N W s (N W is similar to a
/// symmetric matrix with eigenvalues in [0, 1], so it converges wherever
/// the target is an interpolated nodal field; about 100 sweeps to
/// round-off, independent of the grid size). Set-up only.
template <int Dim, class Shape>
void Simulation<Dim, Shape>::balance_initial_pressure_state() {
  double scale = 0.0;
  for (double v : particles_.pressure_out) scale = std::max(scale, std::abs(v));
  if (scale == 0.0) return;
  StepContext<Dim, Shape> ctx = context();
  StencilT s;
  double checkpoint = std::numeric_limits<double>::infinity();
  interrupt_.stage("balancing the initial pore pressure");
  for (int iteration = 0; iteration < 500; ++iteration) {
    interrupt_.check();
    std::fill(grid_.storage.begin(), grid_.storage.end(), 0.0);
    std::fill(grid_.pressure.begin(), grid_.pressure.end(), 0.0);
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      interrupt_.poll(p);
      const std::uint16_t mat = particles_.material[p];
      if (!model_.constants[mat].saturated) continue;
      ctx.template stencil_of<false>(p, s);
      const double n = particles_.porosity[p];
      const double qv =
          ((1.0 - n) * model_.inv_ks[mat] + n * model_.inv_kf[mat]) * particles_.volume[p];
      for (int k = 0; k < StencilT::N; ++k) {
        grid_.storage[s.node[k]] += s.w[k] * qv;
        grid_.pressure[s.node[k]] += s.w[k] * qv * particles_.pressure[p];
      }
    }
    compute_nodal_pressure(ctx, 0.0);
    double residual = 0.0;
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      if (!model_.constants[particles_.material[p]].saturated) continue;
      ctx.template stencil_of<false>(p, s);
      double p_hat = 0.0;
      for (int k = 0; k < StencilT::N; ++k) p_hat += s.w[k] * grid_.pressure[s.node[k]];
      const double r = particles_.pressure_out[p] - p_hat;
      particles_.pressure[p] += r;
      residual = std::max(residual, std::abs(r));
    }
    if (residual <= 1e-15 * scale) break;
    // Where the target is not an interpolated nodal field (B-splines next
    // to the clamped boundary) the residual stalls: stop when 50 sweeps
    // have not halved it.
    if (iteration % 50 == 0) {
      if (residual > 0.5 * checkpoint) break;
      checkpoint = residual;
    }
  }
  std::fill(grid_.storage.begin(), grid_.storage.end(), 0.0);
  std::fill(grid_.pressure.begin(), grid_.pressure.end(), 0.0);
}

}  // namespace hmpm
