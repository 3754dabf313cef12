// phases/particle_to_grid.hpp — clearing the grid and the first particle
// phase of the step: particles to nodes (internal).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "simulation.hpp"

namespace hmpm {

/// Zeroes every nodal sum (the one list of state/grid.hpp).
template <int Dim, class Shape>
inline void clear_grid(StepContext<Dim, Shape>& ctx) {
  ctx.for_nodes([&](std::int64_t b, std::int64_t e) { ctx.grid.clear(b, e); });
}

/// Phase 1: mass, momentum and effective-stress forces, and the fluid
/// storage and storage-weighted pressure, from particles to nodes. (The
/// body force sum_p N_ip m_p g is m_i g: update_nodal_momentum adds it.)
/// Locates each particle's stencil for the later phases of the step.
template <int Dim, class Shape>
inline void map_particles_to_grid(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                  std::size_t begin, std::size_t end) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  if constexpr (StencilT::factorised) {
    map_particles_to_grid_by_rows(ctx, out, begin, end);
    return;
  }
  StencilT s;
  NodeRange touched{ctx.grid.count, -1};
  // Local copies: Eigen's vector stores may alias anything for the
  // compiler, which otherwise reloads these pointers at every node.
  double* const mass_out = at<nodal::mass>(out);
  Vec* const momentum_out = at<nodal::momentum>(out);
  Vec* const force_out = at<nodal::force>(out);
  for (std::size_t p = begin; p < end; ++p) {
    ctx.template stencil_in_step<true, false>(p, s);
    touched.lo = std::min(touched.lo, s.node[0]);  // stencil nodes are in increasing order
    touched.hi = std::max(touched.hi, s.node[StencilT::N - 1]);
    const double m = ctx.particles.mass[p];
    const double vol = ctx.particles.volume[p];
    const Vec mv = m * ctx.particles.v[p];
    const Mat vol_sig = vol * active_stress<Dim>(ctx.particles.stress[p]);
    // Row by row (K consecutive nodes along axis 0): the addresses of a row's
    // nodes are one base plus constants, not an index computation per node
    // and array. The same sums in the same order as node by node.
    for (int r = 0; r < StencilT::N; r += StencilT::K) {
      const std::int64_t row = s.node[r];
      double* const mass_row = mass_out + row;
      Vec* const momentum_row = momentum_out + row;
      Vec* const force_row = force_out + row;
      for (int i = 0; i < StencilT::K; ++i) {
        const double w = s.w[r + i];
        mass_row[i] += w * m;
        momentum_row[i] += w * mv;
        force_row[i].noalias() -= vol_sig * s.grad(r + i);
      }
    }
    if (ctx.model.fluid) {
      const std::uint16_t mat = ctx.particles.material[p];
      if (!ctx.model.constants[mat].saturated) continue;
      const double n = ctx.particles.porosity[p];
      const double qv = ((1.0 - n) * ctx.model.inv_ks[mat] + n * ctx.model.inv_kf[mat]) * vol;
      const double qvp = qv * ctx.particles.pressure[p];
      for (int k = 0; k < StencilT::N; ++k) {
        at<nodal::storage>(out)[s.node[k]] += s.w[k] * qv;
        at<nodal::pressure>(out)[s.node[k]] += s.w[k] * qvp;
      }
    }
  }
  *out.touched = touched;
}

/// Phase 1 for the factorised stencils (StencilT::Axes), row by row: the
/// mass, momentum and force of a node go to the thread's NodeRecord (two
/// aligned four-lane read-modify-writes per node), copied to the nodal sums
/// after the loop.
template <int Dim, class Shape>
inline void map_particles_to_grid_by_rows(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                          std::size_t begin, std::size_t end) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using AxesAhead = typename StepContext<Dim, Shape>::AxesAhead;
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  if constexpr (StencilT::factorised) {  // (explicit instantiation compiles it for every shape)
    NodeRange touched{ctx.grid.count, -1};
    using shape::Lanes;
    NodeRecord* const records = out.records;
    AxesAhead ahead;
    double* const storage_out = at<nodal::storage>(out);
    double* const pressure_out = at<nodal::pressure>(out);
    for (std::size_t p = begin; p < end; ++p) {
      const auto& f = ctx.template axes_ahead<false>(p, begin, end, ahead);
      const double m = ctx.particles.mass[p];
      const double vol = ctx.particles.volume[p];
      const Vec mv = m * ctx.particles.v[p];
      const Mat vol_sig = vol * active_stress<Dim>(ctx.particles.stress[p]);
      // A node's record gains w [m, m v] and -vol sigma grad N (NodeRecord).
      Lanes mass_momentum = {m, 0.0, 0.0, 0.0};
      for (int a = 0; a < Dim; ++a) mass_momentum[1 + a] = mv[a];
      Lanes column[Dim];
      for (int b = 0; b < Dim; ++b) {
        column[b] = Lanes{0.0, 0.0, 0.0, 0.0};
        for (int a = 0; a < Dim; ++a) column[b][a] = vol_sig(a, b);
      }
      auto add = [&](NodeRecord& r, Lanes mm, Lanes force) {
        Lanes lanes_a, lanes_b;
        std::memcpy(&lanes_a, r.a, sizeof lanes_a);
        std::memcpy(&lanes_b, r.b, sizeof lanes_b);
        lanes_a += mm;
        lanes_b -= force;
        std::memcpy(r.a, &lanes_a, sizeof lanes_a);
        std::memcpy(r.b, &lanes_b, sizeof lanes_b);
      };
      const std::uint16_t mat = ctx.particles.material[p];
      const bool fluid = ctx.model.fluid && ctx.model.constants[mat].saturated;
      double qv = 0.0, qvp = 0.0;  // storage Q V and Q V p
      if (fluid) {
        const double n = ctx.particles.porosity[p];
        qv = ((1.0 - n) * ctx.model.inv_ks[mat] + n * ctx.model.inv_kf[mat]) * vol;
        qvp = qv * ctx.particles.pressure[p];
      }
      touched.lo = std::min(touched.lo, f.first());
      touched.hi = std::max(touched.hi, f.last(ctx.grid.stride));
      const Lanes wx0 = Lanes{} + f.w[0][0], wx1 = Lanes{} + f.w[0][1], wx2 = Lanes{} + f.w[0][2];
      const Lanes dx0 = Lanes{} + f.dw[0][0], dx1 = Lanes{} + f.dw[0][1],
                  dx2 = Lanes{} + f.dw[0][2];
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto& dr) {
        const Lanes mm = wr * mass_momentum;
        const Lanes along = wr * column[0];
        Lanes across = dr[1] * column[1];
        for (int c = 2; c < Dim; ++c) across += dr[c] * column[c];
        NodeRecord* const r = records + row;
        add(r[0], wx0 * mm, dx0 * along + wx0 * across);
        add(r[1], wx1 * mm, dx1 * along + wx1 * across);
        add(r[2], wx2 * mm, dx2 * along + wx2 * across);
      });
      if (fluid) {
        const double wx[3] = {f.w[0][0], f.w[0][1], f.w[0][2]};
        f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto&) {
          const double sq = wr * qv, sp = wr * qvp;
          for (int i = 0; i < 3; ++i) {
            storage_out[row + i] += wx[i] * sq;
            pressure_out[row + i] += wx[i] * sp;
          }
        });
      }
    }
    *out.touched = touched;
    double* const mass_out = at<nodal::mass>(out);
    Vec* const momentum_out = at<nodal::momentum>(out);
    Vec* const force_out = at<nodal::force>(out);
    for (std::int64_t i = touched.lo; i <= touched.hi; ++i) {
      NodeRecord& r = records[i];
      mass_out[i] += r.a[0];
      for (int a = 0; a < Dim; ++a) {
        momentum_out[i][a] += r.a[1 + a];
        force_out[i][a] += r.b[a];
      }
      r = NodeRecord{};
    }
  }
}

/// Surface loads at time t (boundary/tractions.hpp) added to the nodal force.
template <int Dim, class Shape>
inline void apply_surface_loads(StepContext<Dim, Shape>& ctx, double t) {
  apply_tractions<Dim, Shape>(ctx.model.tractions, ctx.particles, ctx.grid, t,
                              [&ctx](std::int64_t i) { return ctx.grid.mass[i] > 0.0; });
}

template <int Dim, class Shape>
inline void apply_boundary_fluxes(StepContext<Dim, Shape>& ctx, double t) {
  // The nodes with storage: those the saturated particles reach.
  apply_fluxes<Dim, Shape>(ctx.model.fluxes, ctx.particles, ctx.grid, t,
                           [&ctx](std::int64_t i) { return ctx.grid.storage[i] > 0.0; });
}

/// Surface pressures (boundary/surface_pressures.hpp) at time t into the
/// nodal flux, with the particles' pressure interpolated from the nodal
/// field at the start of the step (the explicit scheme; serial: few
/// particles).
template <int Dim, class Shape>
inline void apply_surface_pressure_fluxes(StepContext<Dim, Shape>& ctx, double t) {
  using StencilT = shape::Stencil<Dim, Shape>;
  StencilT s;
  double w[StencilT::N];
  for_surface_particles<Dim>(
      ctx.model.surface_pressures, ctx.particles, ctx.model.constants, t,
      [&](std::size_t p, double c, double p_face, bool seepage, const VecD<Dim>& face) {
        ctx.template stencil_in_step<false, true>(p, s);
        double p_bar = 0.0;
        for (int k = 0; k < StencilT::N; ++k) p_bar += s.w[k] * ctx.grid.pressure[s.node[k]];
        const double q = surface_inflow(c, p_face, p_bar, seepage);
        face_weights<Dim, Shape>(s, face, ctx.grid, ctx.particles, p, w);
        for (int k = 0; k < StencilT::N; ++k) ctx.grid.flux[s.node[k]] += w[k] * q;
      });
}

}  // namespace hmpm
