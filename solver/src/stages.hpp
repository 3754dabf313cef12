// stages.hpp — moving a Simulation from one stage of a staged job to the
// next (internal; Problem::stages). The particle state carries over; the
// Problem in force becomes the stage's (stage_problem), the particles of the
// bodies it adds join the run and those of the bodies it removes leave it
// (they wait, or stay, in dormant_), those of bodies it gives a new
// material take it (switch_materials), and everything compiled from the
// Problem or the particles (constraints, tractions, fluxes, reactions,
// gravity) is compiled again. The time loop (time_loop.hpp) makes a fresh
// scheme for each stage. Runs between steps only; allocates.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "boundary/constraints.hpp"
#include "boundary/tractions.hpp"
#include "materials/cam_clay_state.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
void Simulation<Dim, Shape>::move_stage_particles(std::size_t k) {
  const std::vector<bool> in = stage_bodies(job_, k);
  auto in_run = [&](std::int64_t id) {
    const auto after = std::upper_bound(body_begin_.begin(), body_begin_.end(), id);
    return in[static_cast<std::size_t>(after - body_begin_.begin() - 1)];
  };
  particles_.move_to(dormant_, [&](std::size_t p) { return !in_run(particles_.id[p]); });
  dormant_.move_to(particles_, [&](std::size_t p) { return in_run(dormant_.id[p]); });
  slot_.assign(static_cast<std::size_t>(job_particles_), -1);
  for (std::size_t p = 0; p < particles_.size(); ++p)
    slot_[static_cast<std::size_t>(particles_.id[p])] = static_cast<std::int64_t>(p);
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::switch_materials(const Stage& stage) {
  auto body_of = [&](std::int64_t id) {
    const auto after = std::upper_bound(body_begin_.begin(), body_begin_.end(), id);
    return static_cast<int>(after - body_begin_.begin() - 1);
  };
  for (ParticleState<Dim>* state : {&particles_, &dormant_})
    for (std::size_t p = 0; p < state->size(); ++p)
      for (const Stage::BodyMaterial& bm : stage.body_materials)
        if (bm.body == body_of(state->id[p])) {
          state->material[p] = static_cast<std::uint16_t>(bm.material);
          if (!state->plastic_strain.empty()) state->plastic_strain[p] = 0.0;
          for (std::vector<double>& v : state->internal) v[p] = 0.0;
        }
  // A body that becomes Cam-Clay starts from its stress now (its slots are 0).
  for (ParticleState<Dim>* state : {&particles_, &dormant_})
    initialise_cam_clay_state(*state, model_.problem.materials, model_.constants);
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::reset_displacement() {
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    particles_.x0[p] = particles_.x[p];
    particles_.strain[p].setZero();
  }
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::enter_stage(std::size_t k) {
  // Stage by stage (a resumed run replays the moves of the stages it skips),
  // so the particles end in the order an uninterrupted run gives them.
  if (!slot_.empty())
    for (std::size_t j = stage_ + 1; j <= k; ++j) move_stage_particles(j);
  // Stage by stage too: a resumed run then reads the particles' materials
  // (those in the run) from its checkpoint.
  for (std::size_t j = stage_ + 1; j <= k; ++j) switch_materials(job_.stages[j - 1]);
  // Stage by stage too: a resumed run reads the particle state after this.
  for (std::size_t j = stage_ + 1; j <= k; ++j)
    if (job_.stages[j - 1].reset_displacement) reset_displacement();
  // From the quasi-static scheme (no inertia: its velocities are the
  // step's mean rates, dx / dt) to an inertial one, the ground starts at
  // rest: a gravity-loading stage of one long step would otherwise hand its
  // whole settlement over as a velocity.
  const bool was_static = model_.problem.time.scheme == Scheme::quasi_static;
  stage_ = k;
  model_.problem = stage_problem(job_, k);
  if (was_static && model_.problem.time.scheme != Scheme::quasi_static)
    for (auto& v : particles_.v) v.setZero();
  for (int a = 0; a < Dim; ++a) model_.gravity[a] = model_.problem.gravity[a];
  // The loads are laid on the particles' initial faces: their initial
  // volumes, from the constant mass and the material's mixture density.
  std::vector<double> volume0(particles_.size());
  for (std::size_t p = 0; p < particles_.size(); ++p)
    volume0[p] = particles_.mass[p] / model_.constants[particles_.material[p]].mixture_density;
  model_.constraints =
      compile_constraints<Dim>(model_.problem, grid_, model_.grid_max, model_.fluid, particles_);
  model_.tractions = compile_tractions<Dim>(model_.problem, particles_, volume0, grid_);
  if (model_.fluid) {
    model_.fluxes = compile_fluxes<Dim>(model_.problem, particles_, volume0, grid_);
    model_.surface_pressures =
        compile_surface_pressures<Dim>(model_.problem, particles_, volume0, grid_);
  }
  if (model_.problem.output.reactions_interval > 0)
    setup_reactions<Dim>(reactions_, model_.constraints, grid_.count,
                         model_.problem.boundaries.size());
}

}  // namespace hmpm
