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
#include "schemes/state_step.hpp"
#include "schemes/time_scheme.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
class ExplicitScheme final : public TimeScheme {
 public:
  using Context = StepContext<Dim, Shape>;
  using Out = Scatter<Dim>;

  explicit ExplicitScheme(Context c) : c_(c) {}

  StableStep stable_step(const Problem& problem) const override {
    return explicit_scheme_rules().stable_step(problem);
  }

  /// With an automatic dt and a soil whose stiffness follows its state
  /// (StableStep::follows_state): the stable step at the particles' state
  /// now (schemes/state_step.hpp).
  double next_dt(double /*t*/) override {
    return state_stable_dt(c_.model.problem, c_.model.stable, c_.model.constants, c_.particles,
                           /*undrained=*/true);
  }

  /// Advances the state from t to t + dt. Sets the simulation's failure on
  /// the first problem.
  void step(double t, double dt) override {
    if (!set_local_damping(t)) return;
    hmpm::clear_grid(c_);
    map_particles_to_grid();
    if (c_.model.fluid) {
      hmpm::compute_nodal_pressure(c_, t);
      map_pore_pressure_force();
    }
    hmpm::apply_surface_loads(c_, t);
    hmpm::update_nodal_momentum(c_, t, dt);
    if (c_.reactions.due) hmpm::tally_reactions(c_, /*with_extra=*/false);
    update_particle_velocities_and_remap(dt);
    hmpm::compute_remapped_nodal_velocity(c_, t + dt, dt);
    update_particle_stress_and_fluid_flux(dt);
    if (c_.model.fluid) {
      hmpm::apply_boundary_fluxes(c_, t);
      if (!c_.model.surface_pressures.empty()) hmpm::apply_surface_pressure_fluxes(c_, t);
      hmpm::update_nodal_pressure(c_, t + dt, dt);
      update_particle_pressure_and_position(dt);
    }
  }

 private:
  /// The local damping coefficient of the step; false (a failure of the
  /// run, before the step changes anything) outside [0, 1).
  bool set_local_damping(double t) {
    const Problem& problem = c_.model.problem;
    c_.damping = problem.local_damping ? problem.local_damping(t) : 0.0;
    if (c_.damping >= 0.0 && c_.damping < 1.0) return true;
    c_.failures.fail_run(
        "local_damping is " + number(c_.damping) + " at t = " + number(t) + " s, outside [0, 1)",
        "keep the local_damping formula between 0 and 1 (exclusive) at all times");
    return false;
  }

  // The particle phases, over the threads, with the nodal sums each scatters.
  void map_particles_to_grid() {
    using namespace nodal;
    const unsigned sums = bit(mass) | bit(momentum) | bit(force) |
                          (c_.model.fluid ? bit(storage) | bit(pressure) : 0u);
    c_.for_particles(sums, [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_particles_to_grid(c_, out, b, e);
    });
  }
  void map_pore_pressure_force() {
    c_.for_particles(nodal::bit(nodal::force), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_pore_pressure_force(c_, out, b, e);
    });
  }
  void update_particle_velocities_and_remap(double dt) {
    c_.for_particles(nodal::bit(nodal::remap), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::update_particle_velocities_and_remap(c_, out, b, e, dt);
    });
  }
  void update_particle_stress_and_fluid_flux(double dt) {
    if (c_.model.fluid) {
      c_.for_particles(nodal::bit(nodal::flux), [&](const Out& out, std::size_t b, std::size_t e) {
        if (c_.model.plastic)
          hmpm::update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/true>(c_, out, b,
                                                                                        e, dt);
        else
          hmpm::update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/false>(c_, out, b,
                                                                                         e, dt);
      });
    } else {
      c_.for_particles(0u, [&](const Out& out, std::size_t b, std::size_t e) {
        if (c_.model.plastic)
          hmpm::update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/true>(c_, out, b,
                                                                                         e, dt);
        else
          hmpm::update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/false>(c_, out,
                                                                                          b, e, dt);
      });
    }
  }
  void update_particle_pressure_and_position(double dt) {
    c_.for_particles(0u, [&](const Out&, std::size_t b, std::size_t e) {
      hmpm::update_particle_pressure_and_position(c_, b, e, dt);
    });
  }

  Context c_;
};

}  // namespace hmpm
