// phases/pore_pressure.hpp — the pore pressure phases of saturated runs:
// nodal pressure from the particles, its force on the mixture, the nodal
// pressure increment from the fluid flux, and the particle pressure and
// position update (internal).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "boundary/apply.hpp"
#include "simulation.hpp"

namespace hmpm {

/// A node condition on the pore water that the soil has left (issue 38):
/// per pressure or seepage constraint, whether some node of it has soil
/// (`has_soil(node)`: a saturated particle's stencil reaches it). One that
/// had soil at an earlier step of the stage and has none now no longer
/// drains anything: the soil it drained (settled below its nodes, or moved
/// away) is then undrained, which the rest of the run would report as a
/// successful run with frozen settlement and suction. The run stops there,
/// naming the condition and what to use instead (surface_pressures, which
/// move with the soil).
template <class HasSoil>
inline void check_drained_contact(Constraints& constraints, Failures& failures, double t,
                                  HasSoil&& has_soil) {
  auto touches = [&](const std::vector<std::int64_t>& nodes) {
    for (std::int64_t i : nodes)
      if (has_soil(i)) return true;
    return false;
  };
  auto left = [&](std::size_t boundary, const char* what) {
    failures.fail_run(
        "boundaries[" + std::to_string(boundary) + "]." + what +
            " reaches no soil any more at t = " + number(t) +
            " s: no saturated particle's shape functions reach its nodes (the soil settled or "
            "moved away from them), so the soil it drained is undrained from here on and the "
            "results would be wrong",
        "pose the drained surface on the soil itself with surface_pressures ({\"particles\": "
        "..., \"face\": \"y+\", \"pore_pressure\": 0} or \"seepage\": true), which moves "
        "with the soil wherever it lies in the grid (docs/job-spec.md, where to put drained "
        "boundaries); or end the condition with a stage when it should lapse");
  };
  for (PressureConstraint& c : constraints.pressure) {
    const bool now = touches(c.nodes);
    if (c.reached && !now) return left(c.boundary, "pore_pressure");
    c.reached = c.reached || now;
  }
  for (SeepageFace& face : constraints.seepage) {
    const bool now = touches(face.nodes);
    if (face.reached && !now) return left(face.boundary, "seepage");
    face.reached = face.reached || now;
  }
}

/// Nodal pressure = storage-weighted average of particle pressures, then
/// prescribed values at time t.
template <int Dim, class Shape>
inline void compute_nodal_pressure(StepContext<Dim, Shape>& ctx, double t) {
  check_drained_contact(ctx.model.constraints, ctx.failures, t,
                        [&](std::int64_t i) { return ctx.grid.storage[i] > 0; });
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
      ctx.grid.pressure[i] =
          ctx.grid.storage[i] > 0 ? ctx.grid.pressure[i] / ctx.grid.storage[i] : 0.0;
  });
  apply_pressure_constraints(ctx.model.constraints, ctx.grid, t);
  apply_seepage_pressure(ctx.model.constraints, ctx.grid);
}

/// Phase 2 (saturated): the pore pressure interpolated from the nodes,
/// p_hat = sum N_j p_j, enters the total stress: f_i += V p_hat grad N_i.
template <int Dim, class Shape>
inline void map_pore_pressure_force(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                    std::size_t begin, std::size_t end) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using AxesAhead = typename StepContext<Dim, Shape>::AxesAhead;
  using Vec = VecD<Dim>;
  StencilT s;
  AxesAhead ahead;
  Vec* const force_out = at<nodal::force>(out);
  for (std::size_t p = begin; p < end; ++p) {
    const auto& f = ctx.template axes_ahead<true>(p, begin, end, ahead);
    if (!ctx.model.constants[ctx.particles.material[p]].saturated) continue;
    if constexpr (StencilT::factorised) {  // row by row (StencilT::Axes)
      double p_hat = 0.0;
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto&) {
        p_hat += wr * f.row_sum(f.w[0], &ctx.grid.pressure[row]);
      });
      const double vp = ctx.particles.volume[p] * p_hat;
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto& dr) {
        // vp grad N of node i: (dw_i vp wr, w_i vp dr_1, ..)
        const double along = vp * wr;
        for (int i = 0; i < 3; ++i) {
          Vec& to = force_out[row + i];
          to[0] += f.dw[0][i] * along;
          for (int a = 1; a < Dim; ++a) to[a] += f.w[0][i] * (vp * dr[a]);
        }
      });
    } else {
      ctx.template stencil_in_step<true, true>(p, s);
      double p_hat = 0.0;
      for (int k = 0; k < StencilT::N; ++k) p_hat += s.w[k] * ctx.grid.pressure[s.node[k]];
      const double vp = ctx.particles.volume[p] * p_hat;
      for (int k = 0; k < StencilT::N; ++k) force_out[s.node[k]] += vp * s.grad(k);
    }
  }
}

/// Grid: ds p/dt from the scattered flux (forward Euler: dp = dt flux /
/// storage); free nodes advance, prescribed nodes take their value at t + dt.
template <int Dim, class Shape>
inline void update_nodal_pressure(StepContext<Dim, Shape>& ctx, double t_new, double dt) {
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
      ctx.grid.dp[i] = ctx.grid.storage[i] > 0 ? dt * ctx.grid.flux[i] / ctx.grid.storage[i] : 0.0;
  });
  apply_pressure_increment_constraints(ctx.model.constraints, ctx.grid, t_new);
  apply_seepage_increment(ctx.model.constraints, ctx.grid);
}

/// Phase 5 (saturated): particle pressure state += sum N dp_i (FLIP);
/// reported pressure = sum N p_i^{n+1}; particles move.
template <int Dim, class Shape>
inline void update_particle_pressure_and_position(StepContext<Dim, Shape>& ctx, std::size_t begin,
                                                  std::size_t end, double dt) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using AxesAhead = typename StepContext<Dim, Shape>::AxesAhead;
  using Vec = VecD<Dim>;
  StencilT s;
  AxesAhead ahead;
  for (std::size_t p = begin; p < end; ++p) {
    const auto& f = ctx.template axes_ahead</*Located=*/true, /*Grad=*/false>(p, begin, end, ahead);
    const bool saturated = ctx.model.constants[ctx.particles.material[p]].saturated;
    // Weights only: this pass needs no gradient. v: the Lagrangian nodal
    // velocity at the particle, which moves it.
    double dp = 0.0, p_new = 0.0;
    Vec v = Vec::Zero();
    if constexpr (StencilT::factorised) {  // row by row (StencilT::Axes)
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto&) {
        if (saturated) {
          const double* const d = &ctx.grid.dp[row];
          const double* const pr = &ctx.grid.pressure[row];
          const double pn[3] = {pr[0] + d[0], pr[1] + d[1], pr[2] + d[2]};
          dp += wr * f.row_sum(f.w[0], d);
          p_new += wr * f.row_sum(f.w[0], pn);
        }
        f.add_scaled(v, wr, f.row_sum(f.w[0], &ctx.grid.velocity[row]));
      });
    } else {
      ctx.template stencil_in_step<false, true>(p, s);
      if (saturated) {
        for (int k = 0; k < StencilT::N; ++k) {
          const std::int64_t i = s.node[k];
          dp += s.w[k] * ctx.grid.dp[i];
          p_new += s.w[k] * (ctx.grid.pressure[i] + ctx.grid.dp[i]);
        }
      }
      for (int k = 0; k < StencilT::N; ++k) v += s.w[k] * ctx.grid.velocity[s.node[k]];
    }
    if (saturated) {
      ctx.particles.pressure[p] += dp;
      ctx.particles.pressure_out[p] = p_new;
      if (!std::isfinite(p_new)) ctx.failures.nonfinite(p, "pore pressure");
    }
    displace_particle(ctx, p, v, dt);
  }
}

}  // namespace hmpm
