// phases/pressure_projection.hpp — the phases of the semi-implicit scheme's
// pressure projection (schemes/semi_implicit_scheme.hpp): the fluid flux of
// the predicted velocity, the pressure Laplacian, and the force of the
// pressure increment (internal).
#pragma once

#include <array>
#include <cstdint>

#include "simulation.hpp"

namespace hmpm {

/// The nodes one node couples to through a particle stencil of K nodes per
/// axis: a box of (2K - 1)^Dim offsets, ordered like node indices (last axis
/// slowest), so entry o > center is a node of larger index. The pressure
/// Laplacian is stored per node over this box (box[node * size + o]).
template <int Dim, int K>
struct CouplingBox {
  static constexpr int width = 2 * K - 1;
  static constexpr int size = Dim == 1 ? width : (Dim == 2 ? width * width : width * width * width);
  static constexpr int center = (size - 1) / 2;
  static constexpr int nodes = Dim == 1 ? K : (Dim == 2 ? K * K : K * K * K);

  /// offset[k][l]: the box entry of stencil node l seen from stencil node k
  /// (stencil nodes numbered as shape::Stencil numbers them, axis 0 fastest).
  static constexpr std::array<std::array<int, nodes>, nodes> offsets() {
    std::array<std::array<int, nodes>, nodes> t{};
    for (int k = 0; k < nodes; ++k)
      for (int l = 0; l < nodes; ++l) {
        int o = 0, scale = 1, kk = k, ll = l;
        for (int a = 0; a < Dim; ++a) {
          o += (ll % K - kk % K + K - 1) * scale;
          kk /= K;
          ll /= K;
          scale *= width;
        }
        t[static_cast<std::size_t>(k)][static_cast<std::size_t>(l)] = o;
      }
    return t;
  }

  /// Node index difference of box entry o on a grid of the given strides.
  static std::int64_t node_offset(int o, const std::int64_t* stride) {
    std::int64_t d = 0;
    for (int a = 0; a < Dim; ++a) {
      d += static_cast<std::int64_t>(o % width - (K - 1)) * stride[a];
      o /= width;
    }
    return d;
  }
};

/// Predictor flux (saturated particles): the explicit scheme's mass-balance
/// right-hand side, V (grad N_i . w* - N_i div v*), with the predicted
/// re-mapped nodal velocity v* (nodal remap, map_predicted_velocity) and
/// the acceleration a* of update_nodal_momentum
/// and w* = -k/gw (grad p^n - rho_f b + rho_f a*), scattered to nodal flux.
template <int Dim, class Shape>
inline void map_predicted_fluid_flux(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                     std::size_t begin, std::size_t end) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using Vec = VecD<Dim>;
  StencilT s;
  double* const flux_out = at<nodal::flux>(out);
  for (std::size_t p = begin; p < end; ++p) {
    const MaterialConstants& mc = ctx.model.constants[ctx.particles.material[p]];
    if (!mc.saturated) continue;
    ctx.template stencil_in_step<true, true>(p, s);
    double div_v = 0.0;
    Vec grad_p = Vec::Zero(), a = Vec::Zero();
    for (int k = 0; k < StencilT::N; ++k) {
      const std::int64_t i = s.node[k];
      div_v += s.grad(k).dot(ctx.grid.remap[i]);
      grad_p += ctx.grid.pressure[i] * s.grad(k);
      a += s.w[k] * ctx.grid.accel[i];
    }
    const Vec w = -permeability_of(mc, ctx.particles.varying, p) *
                  (grad_p - mc.fluid_density * ctx.model.gravity + mc.darcy_inertia_density * a);
    const double vol = ctx.particles.volume[p];
    for (int k = 0; k < StencilT::N; ++k)
      flux_out[s.node[k]] += vol * (s.grad(k).dot(w) - s.w[k] * div_v);
  }
}

/// The predicted particle velocities v_p + dt sum N a* re-mapped to the
/// nodes (MUSL, as the strain will see them), scattered to nodal remap.
template <int Dim, class Shape>
inline void map_predicted_velocity(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                   std::size_t begin, std::size_t end, double dt) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using Vec = VecD<Dim>;
  StencilT s;
  for (std::size_t p = begin; p < end; ++p) {
    ctx.template stencil_in_step<false, true>(p, s);
    Vec a = Vec::Zero();
    for (int k = 0; k < StencilT::N; ++k) a += s.w[k] * ctx.grid.accel[s.node[k]];
    const Vec mv = ctx.particles.mass[p] * (ctx.particles.v[p] + dt * a);
    for (int k = 0; k < StencilT::N; ++k) at<nodal::remap>(out)[s.node[k]] += s.w[k] * mv;
  }
}

/// The pressure Laplacian of the projection over the particles [begin,
/// end): box[(i - first) Box::size + o] += c_p V_p grad N_i . grad N_j for
/// node j >= i (the lower triangle by columns), with c_p = dt^2/rho_p + dt
/// k/gw (1 - rho_f/rho_p) (rho_p = m_p/V_p; rho_f the Darcy-inertia
/// density, 0 when dropped). Marks every node of a saturated particle's
/// stencil in active[i - first]. `first` is the lowest node the particles'
/// stencils reach (0 for the whole grid; a thread's private box covers its
/// band of nodes only).
template <int Dim, class Shape>
inline void assemble_pressure_laplacian(StepContext<Dim, Shape>& ctx, std::size_t begin,
                                        std::size_t end, double dt, double* box,
                                        std::uint8_t* active, std::int64_t first) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using Vec = VecD<Dim>;
  using Box = CouplingBox<Dim, Shape::K>;
  static_assert(Box::nodes == StencilT::N);
  static constexpr auto offsets = Box::offsets();
  StencilT s;
  for (std::size_t p = begin; p < end; ++p) {
    const MaterialConstants& mc = ctx.model.constants[ctx.particles.material[p]];
    if (!mc.saturated) continue;
    ctx.template stencil_in_step<true, true>(p, s);
    const double vol = ctx.particles.volume[p];
    const double rho = ctx.particles.mass[p] / vol;
    const double c = vol * (dt * dt / rho + dt * permeability_of(mc, ctx.particles.varying, p) *
                                                (1.0 - mc.darcy_inertia_density / rho));
    for (int k = 0; k < StencilT::N; ++k) {
      const std::int64_t i = s.node[k];
      active[i - first] = 1;
      double* const row = box + (i - first) * Box::size;
      const Vec gk = c * s.grad(k);
      const auto& off = offsets[static_cast<std::size_t>(k)];
      for (int l = 0; l < StencilT::N; ++l)
        if (s.node[l] >= i) row[off[static_cast<std::size_t>(l)]] += gk.dot(s.grad(l));
    }
  }
}

/// Corrector force (saturated particles): the pressure force of the
/// increment, V dp_hat grad N_i with dp_hat = sum_j N_j dp_j, scattered to
/// nodal `remap` (used as scratch: the re-map has not started).
template <int Dim, class Shape>
inline void map_pressure_increment_force(StepContext<Dim, Shape>& ctx, const Scatter<Dim>& out,
                                         std::size_t begin, std::size_t end) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using Vec = VecD<Dim>;
  StencilT s;
  Vec* const force_out = at<nodal::remap>(out);
  for (std::size_t p = begin; p < end; ++p) {
    if (!ctx.model.constants[ctx.particles.material[p]].saturated) continue;
    ctx.template stencil_in_step<true, true>(p, s);
    double dp_hat = 0.0;
    for (int k = 0; k < StencilT::N; ++k) dp_hat += s.w[k] * ctx.grid.dp[s.node[k]];
    const double vdp = ctx.particles.volume[p] * dp_hat;
    for (int k = 0; k < StencilT::N; ++k) force_out[s.node[k]] += vdp * s.grad(k);
  }
}

}  // namespace hmpm
