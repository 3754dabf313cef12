// phases/stress_and_flux.hpp — the strain-rate phase: stress update through
// the materials' models, volume and porosity, and the fluid flux of the mass
// balance (internal).
#pragma once

#include <cstdint>

#include "materials/material.hpp"
#include "objective_rate.hpp"
#include "simulation.hpp"

namespace hmpm {

/// Phase 4: strain increment from the re-mapped nodal velocities, stress
/// update, volume and porosity; the fluid flux of the mass balance,
/// -N V div v + V grad N . w, is scattered to the nodes (Fluid: runs with
/// a saturated material). In dry runs (!Fluid) the particles also move
/// with the Lagrangian nodal velocity; in saturated runs the last phase
/// moves them. Plastic: some material has a return mapping
/// (return_to_yield_surface, materials/material.hpp). !ScatterFlux (the
/// semi-implicit scheme, whose pressure increment is already solved): no
/// flux is scattered, and the reported Darcy flux is that of p^n + dp.
template <bool Fluid, bool Plastic, bool ScatterFlux = true, int Dim, class Shape>
inline void update_particle_stress_and_fluid_flux(StepContext<Dim, Shape>& ctx,
                                                  const Scatter<Dim>& out, std::size_t begin,
                                                  std::size_t end, double dt) {
  using StencilT = shape::Stencil<Dim, Shape>;
  using AxesAhead = typename StepContext<Dim, Shape>::AxesAhead;
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  StencilT s;
  AxesAhead ahead;
  // A local copy (Eigen's stores may alias the pointer for the compiler).
  double* const flux_out = Fluid && ScatterFlux ? at<nodal::flux>(out) : nullptr;
  // Per-particle constants where parameters vary (null: every particle
  // takes its material's; materials/varying.hpp).
  const VaryingConstants& varying = ctx.particles.varying;
  const constitutive::Elastic* const own_elastic =
      varying.elastic.empty() ? nullptr : varying.elastic.data();
  const double* const own_permeability =
      varying.permeability_over_gamma.empty() ? nullptr : varying.permeability_over_gamma.data();
  for (std::size_t p = begin; p < end; ++p) {
    const auto& f = ctx.template axes_ahead<true>(p, begin, end, ahead);
    Mat grad_v = Mat::Zero();
    // Dry runs move the particle in this phase: its velocity is gathered
    // from the same nodes in the same loop (the same sums, in the same order,
    // as update_particle_pressure_and_position's).
    Vec v_move = Vec::Zero();
    if constexpr (StencilT::factorised) {
      // Row by row (StencilT::Axes): sums along axis 0 with the axis-0
      // factors, scaled by the row's factors.
      Vec column[Dim];  // of grad_v
      for (int c = 0; c < Dim; ++c) column[c] = Vec::Zero();
      f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto& dr) {
        const Vec* const r = &ctx.grid.remap[row];
        f.add_scaled(column[0], wr, f.row_sum(f.dw[0], r));
        const Vec sw = f.row_sum(f.w[0], r);
        for (int c = 1; c < Dim; ++c) f.add_scaled(column[c], dr[c], sw);
        if constexpr (!Fluid) f.add_scaled(v_move, wr, f.row_sum(f.w[0], &ctx.grid.velocity[row]));
      });
      for (int c = 0; c < Dim; ++c)
        for (int a = 0; a < Dim; ++a) grad_v(a, c) = column[c][a];
    } else {
      ctx.template stencil_in_step<true, true>(p, s);
      for (int k = 0; k < StencilT::N; ++k) {
        grad_v.noalias() += ctx.grid.remap[s.node[k]] * s.grad(k).transpose();
        if constexpr (!Fluid) v_move += s.w[k] * ctx.grid.velocity[s.node[k]];
      }
    }
    const double vol = ctx.particles.volume[p];
    const std::uint16_t mat = ctx.particles.material[p];
    const MaterialConstants& mc = ctx.model.constants[mat];
    if (Fluid && mc.saturated) {
      const double div_v = grad_v.trace();
      Vec grad_p = Vec::Zero(), a = Vec::Zero();
      // The pressure of the Darcy flux: p^n, or (semi-implicit, whose
      // increment is known) p^{n+1}.
      auto pressure_at = [&](std::int64_t i) {
        if constexpr (ScatterFlux)
          return ctx.grid.pressure[i];
        else
          return ctx.grid.pressure[i] + ctx.grid.dp[i];
      };
      if constexpr (StencilT::factorised) {
        f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto& dr) {
          const double pr[3] = {pressure_at(row), pressure_at(row + 1), pressure_at(row + 2)};
          grad_p[0] += wr * f.row_sum(f.dw[0], pr);
          const double pw = f.row_sum(f.w[0], pr);
          for (int c = 1; c < Dim; ++c) grad_p[c] += dr[c] * pw;
          f.add_scaled(a, wr, f.row_sum(f.w[0], &ctx.grid.accel[row]));
        });
      } else {
        for (int k = 0; k < StencilT::N; ++k) {
          grad_p += pressure_at(s.node[k]) * s.grad(k);
          a += s.w[k] * ctx.grid.accel[s.node[k]];
        }
      }
      // Component by component (an expression template here was left out of line).
      const double k = own_permeability ? own_permeability[p] : mc.permeability_over_gamma;
      Vec w;
      for (int c = 0; c < Dim; ++c)
        w[c] = -k * (grad_p[c] - mc.fluid_density * ctx.model.gravity[c] +
                     mc.darcy_inertia_density * a[c]);
      ctx.particles.darcy[p] = w;
      if constexpr (ScatterFlux) {
        if constexpr (StencilT::factorised) {
          // vol (grad N . w - N div v) = dw_i (vol wr w_0) + w_i vol (sum dr_c w_c - wr div v)
          const double wx0 = f.w[0][0], wx1 = f.w[0][1], wx2 = f.w[0][2];
          const double dx0 = f.dw[0][0], dx1 = f.dw[0][1], dx2 = f.dw[0][2];
          f.for_rows(ctx.grid.stride, [&](std::int64_t row, double wr, const auto& dr) {
            const double c0 = vol * wr * w[0];
            double along = -wr * div_v;
            for (int c = 1; c < Dim; ++c) along += dr[c] * w[c];
            const double c1 = vol * along;
            double* const to = flux_out + row;
            to[0] += dx0 * c0 + wx0 * c1;
            to[1] += dx1 * c0 + wx1 * c1;
            to[2] += dx2 * c0 + wx2 * c1;
          });
        } else {
          for (int k = 0; k < StencilT::N; ++k)
            flux_out[s.node[k]] += vol * (s.grad(k).dot(w) - s.w[k] * div_v);
        }
      }
    }
    Voigt de = Voigt::Zero();
    for (int a = 0; a < Dim; ++a) de[a] = grad_v(a, a) * dt;
    if constexpr (Dim >= 2) de[3] = 0.5 * (grad_v(0, 1) + grad_v(1, 0)) * dt;
    if constexpr (Dim == 3) {
      de[4] = 0.5 * (grad_v(1, 2) + grad_v(2, 1)) * dt;
      de[5] = 0.5 * (grad_v(2, 0) + grad_v(0, 2)) * dt;
    }
    const double tr = de[0] + de[1] + de[2];
    Voigt& sig = ctx.particles.stress[p];
    if constexpr (Dim >= 2) rotate_jaumann<Dim>(sig, grad_v, dt);
    // Constants copied first: the stores to sig could alias mc for the compiler.
    const constitutive::Elastic& el = own_elastic ? own_elastic[p] : mc.elastic;
    const double lambda_tr = el.lambda * tr, two_g = 2.0 * el.shear;
    // Below 3D the shear increments yz and zx (in 1D also xy) are zero:
    // the loops end before them (components 0..changed_end-1 can change).
    constexpr int changed_end = Dim == 1 ? 3 : (Dim == 2 ? 4 : 6);
    // The elastic trial, unless the model makes its own (Cam-Clay).
    if (!Plastic || elastic_trial_outside(mc.model)) {
      for (int c = 0; c < 3; ++c) sig[c] += lambda_tr + two_g * de[c];
      for (int c = 3; c < changed_end; ++c) sig[c] += two_g * de[c];
    }
    if constexpr (Plastic) {
      const double plastic =
          return_to_yield_surface(sig, de, mc, el, varying, p, {ctx.particles.internal.data(), p});
      if (plastic > 0.0) ctx.particles.plastic_strain[p] += equivalent_plastic_strain(plastic);
    }
    for (int c = 0; c < changed_end; ++c) ctx.particles.strain[p][c] += de[c];
    // F = I + dt grad v, a plain matrix (its determinant inlines), filled
    // element by element.
    Mat def;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b) def(a, b) = (a == b ? 1.0 : 0.0) + dt * grad_v(a, b);
    const double j = def.determinant();
    if (!(j > 0.0)) ctx.failures.volume(p, j);
    ctx.particles.volume[p] = vol * j;
    if (Fluid && mc.saturated)
      ctx.particles.porosity[p] = 1.0 - (1.0 - ctx.particles.porosity[p]) / j;
    if constexpr (!Fluid) displace_particle(ctx, p, v_move, dt);
  }
}

}  // namespace hmpm
