// phases/grid.hpp — the grid phases of the step: the nodal momentum update
// and the re-mapped nodal velocity, each followed by the boundary
// constraints in their one order of precedence (boundary/apply.hpp)
// (internal).
#pragma once

#include <cmath>
#include <cstdint>

#include "boundary/apply.hpp"
#include "simulation.hpp"

namespace hmpm {

/// Grid update: momentum += dt (f + m g) (with local damping), the
/// dashpots of absorbing boundaries, then the velocity constraints at t + dt. Gives the Lagrangian
/// nodal velocity and the nodal acceleration used by the particles.
template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::update_nodal_momentum(double t, double dt) {
  const double alpha = damping_;
  for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = grid_.mass[i];
      if (m <= mass_tolerance_) {
        grid_.velocity[i].setZero();
        grid_.accel[i].setZero();
        continue;
      }
      Vec f = grid_.force[i] + m * gravity_;
      const Vec v0 = grid_.momentum[i] / m;
      if (alpha > 0)
        for (int a = 0; a < Dim; ++a)
          f[a] -= alpha * std::abs(f[a]) * (v0[a] > 0 ? 1.0 : (v0[a] < 0 ? -1.0 : 0.0));
      grid_.accel[i] = f / m;
      grid_.velocity[i] = v0 + dt * grid_.accel[i];
    }
  });
  apply_absorbing(constraints_, grid_, gravity_, mass_tolerance_, t, dt);
  apply_velocity_constraints(constraints_, grid_, mass_tolerance_, t, dt);
}

/// The re-mapped nodal velocity (momentum re-mapped from the updated
/// particle velocities over mass), its constraints at t_new, and in
/// saturated runs the nodal acceleration Darcy's rho_f a takes from it.
template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::compute_remapped_nodal_velocity(double t_new, double dt) {
  gather_rigid_ties(constraints_, grid_);
  for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = grid_.mass[i];
      grid_.remap[i] = m > mass_tolerance_ ? Vec(grid_.remap[i] / m) : Vec::Zero();
    }
  });
  apply_remap_constraints(constraints_, grid_, mass_tolerance_, t_new);
  if (!fluid_) return;
  // Darcy's rho_f a takes the acceleration of the re-mapped field,
  // (v_remap - v^n) / dt, at free components: it has passed through the
  // same particle-grid smoothing as the velocities the mass balance sees,
  // so the elastic part of rho_f a is never stronger than the pressure
  // diffusion that balances it (docs/verification.md). Prescribed and
  // rigid components keep the acceleration of update_nodal_momentum.
  const double inv_dt = 1.0 / dt;
  for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = grid_.mass[i];
      if (m <= mass_tolerance_) continue;
      const std::uint8_t fixed = constraints_.prescribed_axes[static_cast<std::size_t>(i)];
      for (int a = 0; a < Dim; ++a)
        if (!(fixed & (1u << a)))
          grid_.accel[i][a] = (grid_.remap[i][a] - grid_.momentum[i][a] / m) * inv_dt;
    }
  });
}

}  // namespace hmpm
