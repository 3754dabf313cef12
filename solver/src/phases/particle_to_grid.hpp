// phases/particle_to_grid.hpp — clearing the grid and the first particle
// phase of the step: particles to nodes (internal).
#pragma once

#include <algorithm>
#include <cstdint>

#include "simulation.hpp"

namespace hmpm {

/// Zeroes every nodal sum (the one list of state/grid.hpp).
template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::clear_grid() {
  for_nodes([&](std::int64_t b, std::int64_t e) { grid_.clear(b, e); });
}

/// Total stress divergence term of one particle: f_i -= V sigma grad N_i,
/// with sigma the (3D) effective stress restricted to the active axes.
template <int Dim, class Shape>
inline typename Simulation<Dim, Shape>::Mat Simulation<Dim, Shape>::active_stress(const Voigt& s) {
  Mat m;
  if constexpr (Dim == 1) {
    m(0, 0) = s[0];
  } else if constexpr (Dim == 2) {
    m << s[0], s[3], s[3], s[1];
  } else {
    m << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
  }
  return m;
}

/// Phase 1: mass, momentum and effective-stress forces, and the fluid
/// storage and storage-weighted pressure, from particles to nodes. (The
/// body force sum_p N_ip m_p g is m_i g: update_nodal_momentum adds it.)
/// Locates each particle's stencil for the later phases of the step.
template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::map_particles_to_grid(const Out& out, std::size_t begin,
                                                          std::size_t end) {
  StencilT s;
  NodeRange touched{grid_.count, -1};
  // Local copies: Eigen's vector stores may alias anything for the
  // compiler, which otherwise reloads these pointers at every node.
  double* const mass_out = at<nodal::mass>(out);
  Vec* const momentum_out = at<nodal::momentum>(out);
  Vec* const force_out = at<nodal::force>(out);
  for (std::size_t p = begin; p < end; ++p) {
    stencil_in_step<true, false>(p, s);
    touched.lo = std::min(touched.lo, s.node[0]);  // stencil nodes are in increasing order
    touched.hi = std::max(touched.hi, s.node[StencilT::N - 1]);
    const double m = particles_.mass[p];
    const double vol = particles_.volume[p];
    const Vec mv = m * particles_.v[p];
    const Mat vol_sig = vol * active_stress(particles_.stress[p]);
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
    if (fluid_) {
      const std::uint16_t mat = particles_.material[p];
      if (!constants_[mat].saturated) continue;
      const double n = particles_.porosity[p];
      const double qv = ((1.0 - n) * inv_ks_[mat] + n * inv_kf_[mat]) * vol;
      const double qvp = qv * particles_.pressure[p];
      for (int k = 0; k < StencilT::N; ++k) {
        at<nodal::storage>(out)[s.node[k]] += s.w[k] * qv;
        at<nodal::pressure>(out)[s.node[k]] += s.w[k] * qvp;
      }
    }
  }
  *out.touched = touched;
}

/// Surface loads at time t (boundary/tractions.hpp) added to the nodal force.
template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::apply_surface_loads(double t) {
  apply_tractions<Dim, Shape>(tractions_, particles_, grid_, t);
}

template <int Dim, class Shape>
inline void Simulation<Dim, Shape>::apply_boundary_fluxes(double t) {
  // The nodes with storage: those the saturated particles reach.
  apply_fluxes<Dim, Shape>(fluxes_, particles_, grid_, t,
                           [this](std::int64_t i) { return grid_.storage[i] > 0.0; });
}

}  // namespace hmpm
