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
inline void update_nodal_momentum(StepContext<Dim, Shape>& ctx, double t, double dt) {
  using Vec = VecD<Dim>;
  const double alpha = ctx.damping;
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = ctx.grid.mass[i];
      if (m <= ctx.model.mass_tolerance) {
        ctx.grid.velocity[i].setZero();
        ctx.grid.accel[i].setZero();
        continue;
      }
      Vec f = ctx.grid.force[i] + m * ctx.model.gravity;
      const Vec v0 = ctx.grid.momentum[i] / m;
      if (alpha > 0)
        for (int a = 0; a < Dim; ++a)
          f[a] -= alpha * std::abs(f[a]) * (v0[a] > 0 ? 1.0 : (v0[a] < 0 ? -1.0 : 0.0));
      ctx.grid.accel[i] = f / m;
      ctx.grid.velocity[i] = v0 + dt * ctx.grid.accel[i];
    }
  });
  apply_absorbing(ctx.model.constraints, ctx.grid, ctx.model.gravity, ctx.model.mass_tolerance, t,
                  dt);
  apply_velocity_constraints(ctx.model.constraints, ctx.grid, ctx.model.mass_tolerance, t, dt);
}

/// The re-mapped nodal velocity (momentum re-mapped from the updated
/// particle velocities over mass), its constraints at t_new, and in
/// saturated runs the nodal acceleration Darcy's rho_f a takes from it.
template <int Dim, class Shape>
inline void compute_remapped_nodal_velocity(StepContext<Dim, Shape>& ctx, double t_new, double dt) {
  using Vec = VecD<Dim>;
  gather_rigid_ties(ctx.model.constraints, ctx.grid);
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = ctx.grid.mass[i];
      ctx.grid.remap[i] = m > ctx.model.mass_tolerance ? Vec(ctx.grid.remap[i] / m) : Vec::Zero();
    }
  });
  apply_remap_constraints(ctx.model.constraints, ctx.grid, ctx.model.mass_tolerance, t_new);
  if (!ctx.model.fluid) return;
  // Darcy's rho_f a takes the acceleration of the re-mapped field,
  // (v_remap - v^n) / dt, at free components: it has passed through the
  // same particle-grid smoothing as the velocities the mass balance sees,
  // so the elastic part of rho_f a is never stronger than the pressure
  // diffusion that balances it (docs/verification.md). Prescribed and
  // rigid components keep the acceleration of update_nodal_momentum.
  const double inv_dt = 1.0 / dt;
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i) {
      const double m = ctx.grid.mass[i];
      if (m <= ctx.model.mass_tolerance) continue;
      const std::uint8_t fixed = ctx.model.constraints.prescribed_axes[static_cast<std::size_t>(i)];
      for (int a = 0; a < Dim; ++a)
        if (!(fixed & (1u << a)))
          ctx.grid.accel[i][a] = (ctx.grid.remap[i][a] - ctx.grid.momentum[i][a] / m) * inv_dt;
    }
  });
}

}  // namespace hmpm
