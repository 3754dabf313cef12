// boundary/tractions.hpp — surface loads on particle faces (internal).
//
// A Traction of the Problem loads one face of the particles whose initial
// position lies in its box or polygon. Compiled once at set-up (compile_tractions);
// each step the load is mapped to the nodes at the loaded face of each
// particle, with the face area following the particle's volume change
// (apply_tractions).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "shape.hpp"
#include "state/grid.hpp"
#include "state/particles.hpp"

namespace hmpm {

struct TractionLoad {
  const Traction* source = nullptr;
  int axis = 0;
  int side = 1;
  std::vector<std::int64_t> particles;
  std::vector<double> length0;
  std::vector<double> volume0;
};

/// The loads of `problem` on the particles at their initial volumes.
template <int Dim>
std::vector<TractionLoad> compile_tractions(const Problem& problem,
                                            const ParticleState<Dim>& particles,
                                            const GridState<Dim>& grid) {
  std::vector<TractionLoad> tractions;
  const std::vector<Vec3> x0 = initial_positions(problem);
  for (const Traction& t : problem.tractions) {
    TractionLoad load;
    load.source = &t;
    load.axis = t.axis;
    load.side = t.side;
    for (std::size_t p = 0; p < x0.size(); ++p) {
      if (!particle_selected(problem, t, x0[p])) continue;
      load.particles.push_back(static_cast<std::int64_t>(p));
      // Initial length along the face normal: the cell size over the body's
      // particles per cell, recovered from the initial volume per axis.
      load.length0.push_back(std::pow(particles.volume[p], 1.0 / Dim));
      load.volume0.push_back(particles.volume[p]);
    }
    tractions.push_back(std::move(load));
  }
  // Particles of a body are not cubes when cells are not; use the cell size
  // along the normal over particles per cell when available.
  for (TractionLoad& load : tractions)
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      const auto p = static_cast<std::size_t>(load.particles[k]);
      double ppc_volume = 1.0;
      for (int a = 0; a < Dim; ++a) ppc_volume *= grid.h[a];
      const double n_per_axis = std::round(std::pow(ppc_volume / particles.volume[p], 1.0 / Dim));
      load.length0[k] = grid.h[load.axis] / std::max(n_per_axis, 1.0);
    }
  return tractions;
}

/// Surface loads at time t, mapped at the loaded face of each selected
/// particle and added to the nodal force. The face's area follows the
/// particle's volume, V / length0 (a follower load: the explicit schemes);
/// DeadLoad keeps its initial area V0 / length0 (a load fixed in size: the
/// quasi-static scheme, whose Terzaghi and Mandel loads are fixed forces).
template <int Dim, class Shape, bool DeadLoad = false>
inline void apply_tractions(const std::vector<TractionLoad>& tractions,
                            const ParticleState<Dim>& particles, GridState<Dim>& grid, double t) {
  using Vec = VecD<Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;
  StencilT s;
  for (const TractionLoad& load : tractions) {
    Vec traction;
    for (int a = 0; a < Dim; ++a)
      traction[a] = load.source->traction[a] ? load.source->traction[a](t) : 0.0;
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      const auto p = static_cast<std::size_t>(load.particles[k]);
      const double stretch = std::pow(particles.volume[p] / load.volume0[k], 1.0 / Dim);
      const double area = (DeadLoad ? load.volume0[k] : particles.volume[p]) / load.length0[k];
      Vec face = particles.x[p];
      face[load.axis] += load.side * 0.5 * load.length0[k] * stretch;
      s.compute(face, grid.origin, grid.inv_h, grid.cells, grid.stride,
                particles.half_length.empty() ? 0.0 : particles.half_length[p]);
      for (int n = 0; n < StencilT::N; ++n) grid.force[s.node[n]] += s.w[n] * area * traction;
    }
  }
}

}  // namespace hmpm
