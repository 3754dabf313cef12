// phases/grid_to_particle.hpp — nodal velocities and accelerations back to
// the particles: the FLIP velocity update with the MUSL re-map, and the
// particle motion (internal).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "simulation.hpp"

namespace hmpm {

/// Phase 3: FLIP update of particle velocities, v_p += dt sum N_i a_i, and
/// re-mapping of the updated momentum (MUSL, Eq. 26).
template <int Dim, class Shape>
inline void update_particle_velocities_and_remap(StepContext<Dim, Shape>& ctx,
                                                 const Scatter<Dim>& out, std::size_t begin,
                                                 std::size_t end, double dt) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using AxesAhead = typename StepContext<Dim, Shape>::AxesAhead;
  using Vec = VecD<Dim>;
  StencilT s;
  // A local copy: the compiler otherwise reloads the pointer at every node
  // (Eigen's vector stores may alias it).
  Vec* const remap_out = at<nodal::remap>(out);
  AxesAhead ahead;
  // The same for the arrays read and written per particle (the stores to
  // remap_out may alias them for the compiler, which then reloads the
  // particle's velocity it has just stored).
  const Vec* const accel = ctx.grid.accel.data();
  const double* const mass = ctx.particles.mass.data();
  Vec* const velocity = ctx.particles.v.data();
  for (std::size_t p = begin; p < end; ++p) {
    const auto& f = ctx.template axes_ahead</*Located=*/true, /*Grad=*/false>(p, begin, end, ahead);
    if constexpr (StencilT::factorised) {  // row by row (StencilT::Axes)
      Vec a = Vec::Zero();
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto&) {
        f.add_scaled(a, wr, f.row_sum(f.w[0], accel + row));
      });
      const double m = mass[p];
      Vec v = velocity[p];
      f.add_scaled(v, dt, a);
      velocity[p] = v;
      Vec mv;
      for (int c = 0; c < Dim; ++c) mv[c] = m * v[c];
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto&) {
        Vec rmv;
        for (int c = 0; c < Dim; ++c) rmv[c] = wr * mv[c];
        for (int i = 0; i < 3; ++i) f.add_scaled(remap_out[row + i], f.w[0][i], rmv);
      });
    } else {
      ctx.template stencil_in_step<false, true>(p, s);
      Vec a = Vec::Zero();
      for (int k = 0; k < StencilT::N; ++k) a += s.w[k] * ctx.grid.accel[s.node[k]];
      ctx.particles.v[p] += dt * a;
      const Vec mv = ctx.particles.mass[p] * ctx.particles.v[p];
      for (int k = 0; k < StencilT::N; ++k) remap_out[s.node[k]] += s.w[k] * mv;
    }
  }
}

/// Moves the particle with the Lagrangian nodal velocity v. One test per
/// axis catches both failures: a non-finite position (the comparisons are
/// false for NaN) and a position outside the grid. A non-finite particle
/// velocity, stress or force makes the nodal velocities, hence the
/// position, non-finite in the same or the next step.
template <int Dim, class Shape>
__attribute__((always_inline)) inline void displace_particle(StepContext<Dim, Shape>& ctx,
                                                             std::size_t p, VecD<Dim> v,
                                                             double dt) {
  using Vec = VecD<Dim>;
  const Vec dx = v * dt;
  Vec& x = ctx.particles.x[p];
  x += dx;
  // Branch-free: one test per axis, which a NaN position also fails.
  int inside = 1;
  for (int a = 0; a < Dim; ++a)
    inside &= static_cast<int>(x[a] >= ctx.grid.origin[a]) &
              static_cast<int>(x[a] <= ctx.model.grid_max[a]);
  if (!inside) [[unlikely]] {
    if (!x.allFinite() || !ctx.particles.v[p].allFinite())
      ctx.failures.nonfinite(p, "velocity");
    else if (!return_to_wall(ctx, p))
      ctx.failures.left_grid(p);
  }
}

/// A particle that crossed a grid face where a wall holds the material
/// goes back onto the face: at the face node nearest to it the wall
/// prescribes (or ties) the normal velocity component, and that component
/// does not point out of the grid. The continuum cannot cross such a wall;
/// a particle does when the shape functions give it a velocity the wall's
/// nodes do not have (the clamped quadratic B-spline gives the node next to
/// the wall 1/8 of the weight at the wall, so a settling particle on a floor
/// creeps through it). False, and nothing changed, when the particle left
/// through a face with no wall, or one whose velocity carries it out.
template <int Dim, class Shape>
__attribute__((noinline)) bool return_to_wall(StepContext<Dim, Shape>& ctx, std::size_t p) {
  using Vec = VecD<Dim>;
  Vec x = ctx.particles.x[p];
  std::int64_t node = 0;
  for (int a = 0; a < Dim; ++a) {
    const double xi = std::clamp((x[a] - ctx.grid.origin[a]) * ctx.grid.inv_h[a], 0.0,
                                 static_cast<double>(ctx.grid.cells[a]));
    node += std::lround(xi) * ctx.grid.stride[a];
  }
  const auto i = static_cast<std::size_t>(node);
  for (int a = 0; a < Dim; ++a) {
    const bool below = x[a] < ctx.grid.origin[a];
    const bool above = x[a] > ctx.model.grid_max[a];
    if (!below && !above) continue;
    if (!(ctx.model.constraints.prescribed_axes[i] & (1u << a))) return false;
    const double v = ctx.grid.velocity[i][a];
    if (below ? v < 0.0 : v > 0.0) return false;
    x[a] = below ? ctx.grid.origin[a] : ctx.model.grid_max[a];
  }
  ctx.particles.x[p] = x;
  return true;
}

}  // namespace hmpm
