// schemes/explicit_scheme.hpp — the explicit u-p scheme (internal).
//
// The momentum-based MUSL cycle of the seed paper (§3.4), extended with the
// fluid mass balance of the u-p formulation: forward Euler in time for the
// nodal momenta and the nodal pore pressure. Its stable step is the smaller
// of the mechanical limit h/(c sqrt(d)) (c the undrained P-wave speed) and
// the diffusion limit h^2/(2 d c_h) of forward Euler on the pressure
// equation, over the materials that have particles (explicit_rules.cpp).
#pragma once

#include <cstddef>

#include "phases/grid.hpp"
#include "phases/grid_to_particle.hpp"
#include "phases/particle_to_grid.hpp"
#include "phases/pore_pressure.hpp"
#include "phases/reactions.hpp"
#include "phases/stress_and_flux.hpp"
#include "schemes/time_scheme.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
class ExplicitScheme final : public TimeScheme {
 public:
  using Sim = Simulation<Dim, Shape>;
  using Out = typename Sim::Out;

  explicit ExplicitScheme(Sim& sim) : sim_(sim) {}

  StableStep stable_step(const Problem& problem) const override {
    return explicit_scheme_rules().stable_step(problem);
  }

  /// Advances the state from t to t + dt. Sets the simulation's failure on
  /// the first problem.
  void step(double t, double dt) override {
    if (!set_local_damping(t)) return;
    sim_.clear_grid();
    map_particles_to_grid();
    if (sim_.fluid_) {
      sim_.compute_nodal_pressure(t);
      map_pore_pressure_force();
    }
    sim_.apply_surface_loads(t);
    sim_.update_nodal_momentum(t, dt);
    if (sim_.reactions_due_) sim_.tally_reactions(/*with_extra=*/false);
    update_particle_velocities_and_remap(dt);
    sim_.compute_remapped_nodal_velocity(t + dt, dt);
    update_particle_stress_and_fluid_flux(dt);
    if (sim_.fluid_) {
      sim_.apply_boundary_fluxes(t);
      sim_.update_nodal_pressure(t + dt, dt);
      update_particle_pressure_and_position(dt);
    }
  }

 private:
  /// The local damping coefficient of the step; false (a failure of the
  /// run, before the step changes anything) outside [0, 1).
  bool set_local_damping(double t) {
    const Problem& problem = sim_.problem_;
    sim_.damping_ = problem.local_damping ? problem.local_damping(t) : 0.0;
    if (sim_.damping_ >= 0.0 && sim_.damping_ < 1.0) return true;
    sim_.fail_run("local_damping is " + Sim::number(sim_.damping_) + " at t = " + Sim::number(t) +
                      " s, outside [0, 1)",
                  "keep the local_damping formula between 0 and 1 (exclusive) at all times");
    return false;
  }

  // The particle phases, over the threads, with the nodal sums each scatters.
  void map_particles_to_grid() {
    using namespace nodal;
    const unsigned sums =
        bit(mass) | bit(momentum) | bit(force) | (sim_.fluid_ ? bit(storage) | bit(pressure) : 0u);
    sim_.for_particles(sums, [&](const Out& out, std::size_t b, std::size_t e) {
      sim_.map_particles_to_grid(out, b, e);
    });
  }
  void map_pore_pressure_force() {
    sim_.for_particles(nodal::bit(nodal::force), [&](const Out& out, std::size_t b, std::size_t e) {
      sim_.map_pore_pressure_force(out, b, e);
    });
  }
  void update_particle_velocities_and_remap(double dt) {
    sim_.for_particles(nodal::bit(nodal::remap), [&](const Out& out, std::size_t b, std::size_t e) {
      sim_.update_particle_velocities_and_remap(out, b, e, dt);
    });
  }
  void update_particle_stress_and_fluid_flux(double dt) {
    if (sim_.fluid_) {
      sim_.for_particles(nodal::bit(nodal::flux), [&](const Out& out, std::size_t b,
                                                      std::size_t e) {
        if (sim_.plastic_)
          sim_.template update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/true>(
              out, b, e, dt);
        else
          sim_.template update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/false>(
              out, b, e, dt);
      });
    } else {
      sim_.for_particles(0u, [&](const Out& out, std::size_t b, std::size_t e) {
        if (sim_.plastic_)
          sim_.template update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/true>(
              out, b, e, dt);
        else
          sim_.template update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/false>(
              out, b, e, dt);
      });
    }
  }
  void update_particle_pressure_and_position(double dt) {
    sim_.for_particles(0u, [&](const Out&, std::size_t b, std::size_t e) {
      sim_.update_particle_pressure_and_position(b, e, dt);
    });
  }

  Sim& sim_;
};

}  // namespace hmpm
