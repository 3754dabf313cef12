// boundary/tractions.hpp — surface loads on particle faces (internal).
//
// A Traction of the Problem loads one face of the particles whose initial
// position lies in its box or polygon. Compiled once at set-up (compile_tractions);
// each step the load is mapped to the nodes at the loaded face of each
// particle, with the face area following the particle's volume change
// (apply_tractions). A Flux (water across a face) is selected and mapped
// the same way, into the nodal flux of the mass balance (apply_fluxes).
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

/// The particles loaded on one face (a traction's or a flux's), at their
/// initial volumes.
struct FaceParticles {
  int axis = 0;
  int side = 1;
  std::vector<std::int64_t> particles;
  std::vector<double> length0;  ///< initial length along the face normal
  std::vector<double> volume0;
};

struct TractionLoad : FaceParticles {
  const Traction* source = nullptr;
  /// The selected particles' initial positions when a component varies
  /// along the face (Traction::traction_field); empty otherwise.
  std::vector<Vec3> x0;
};

/// Water across a face (Flux): the selected particles and, when the rate
/// depends on position, their initial positions.
struct FluxLoad : FaceParticles {
  const Flux* source = nullptr;
  std::vector<Vec3> x0;  ///< empty unless source->rate_varies_in_space
};

/// A particle's initial position as a Vec3 (trailing components zero).
template <int Dim>
inline Vec3 initial_position(const ParticleState<Dim>& particles, std::size_t p) {
  Vec3 x{0.0, 0.0, 0.0};
  for (int a = 0; a < Dim; ++a) x[a] = particles.x0[p][a];
  return x;
}

/// The particles in the run whose initial position `source` selects, on
/// its face. volume0: each particle's initial volume. Initial length along
/// the normal: the cell size over the body's particles per axis, recovered
/// from the initial volume (particles of a body are not cubes when cells
/// are not).
template <int Dim, class Source>
FaceParticles select_face_particles(const Problem& problem, const Source& source,
                                    const ParticleState<Dim>& particles,
                                    const std::vector<double>& volume0,
                                    const GridState<Dim>& grid) {
  FaceParticles face;
  face.axis = source.axis;
  face.side = source.side;
  double cell_volume = 1.0;
  for (int a = 0; a < Dim; ++a) cell_volume *= grid.h[a];
  for (std::size_t p = 0; p < particles.size(); ++p) {
    if (!particle_selected(problem, source, initial_position(particles, p))) continue;
    face.particles.push_back(static_cast<std::int64_t>(p));
    const double n_per_axis = std::round(std::pow(cell_volume / volume0[p], 1.0 / Dim));
    face.length0.push_back(grid.h[face.axis] / std::max(n_per_axis, 1.0));
    face.volume0.push_back(volume0[p]);
  }
  return face;
}

/// The loads of `problem` on the particles (volume0: their initial volumes).
template <int Dim>
std::vector<TractionLoad> compile_tractions(const Problem& problem,
                                            const ParticleState<Dim>& particles,
                                            const std::vector<double>& volume0,
                                            const GridState<Dim>& grid) {
  std::vector<TractionLoad> tractions;
  for (const Traction& t : problem.tractions) {
    TractionLoad load;
    static_cast<FaceParticles&>(load) = select_face_particles(problem, t, particles, volume0, grid);
    load.source = &t;
    if (std::any_of(t.traction_field.begin(), t.traction_field.end(),
                    [](const FieldOfSpaceTime& f) { return static_cast<bool>(f); }))
      for (std::int64_t p : load.particles)
        load.x0.push_back(initial_position(particles, static_cast<std::size_t>(p)));
    tractions.push_back(std::move(load));
  }
  return tractions;
}

/// The fluxes of `problem` (saturated runs).
template <int Dim>
std::vector<FluxLoad> compile_fluxes(const Problem& problem, const ParticleState<Dim>& particles,
                                     const std::vector<double>& volume0,
                                     const GridState<Dim>& grid) {
  std::vector<FluxLoad> fluxes;
  for (const Flux& f : problem.fluxes) {
    FluxLoad load;
    static_cast<FaceParticles&>(load) = select_face_particles(problem, f, particles, volume0, grid);
    load.source = &f;
    if (f.rate_varies_in_space)
      for (std::int64_t p : load.particles)
        load.x0.push_back(initial_position(particles, static_cast<std::size_t>(p)));
    fluxes.push_back(std::move(load));
  }
  return fluxes;
}

/// Calls add(node, N area) for the nodes of the loaded face of particle k of
/// `face`: the face lies half the particle's current length along the
/// normal from its centre; its area follows the particle's volume, V /
/// length0 (a follower load: the explicit schemes), or with DeadLoad keeps
/// its initial area V0 / length0 (the quasi-static scheme).
template <int Dim, class Shape, bool DeadLoad, class Add>
inline void for_face_nodes(const FaceParticles& face, std::size_t k,
                           const ParticleState<Dim>& particles, const GridState<Dim>& grid,
                           shape::Stencil<Dim, Shape>& s, Add&& add) {
  using StencilT = shape::Stencil<Dim, Shape>;
  const auto p = static_cast<std::size_t>(face.particles[k]);
  const double stretch = std::pow(particles.volume[p] / face.volume0[k], 1.0 / Dim);
  const double area = (DeadLoad ? face.volume0[k] : particles.volume[p]) / face.length0[k];
  VecD<Dim> at = particles.x[p];
  at[face.axis] += face.side * 0.5 * face.length0[k] * stretch;
  s.template compute<false>(at, grid.origin, grid.inv_h, grid.cells, grid.stride,
                            shape::box_of(particles, p));
  // GIMP at a face on the grid's edge: the particle-sized stencil there
  // reaches a node beyond the grid, whose share (half_length / 4 of the load:
  // 6 % with 2 particles per cell) goes to the nodes inside. The other
  // shape functions' weights sum to 1 to round-off and are used as they are.
  double sum = 0.0;
  for (int n = 0; n < StencilT::N; ++n) sum += s.w[n];
  const double whole = std::abs(sum - 1.0) > 1e-12 ? area / sum : area;
  for (int n = 0; n < StencilT::N; ++n) add(s.node[n], s.w[n] * whole);
}

/// The resultant of the surface loads at time t, N (per metre in 2D), on
/// the faces' current areas (the explicit schemes' follower loads): the
/// load level a collapse report gives (collapse_watch.hpp).
template <int Dim>
inline Vec3 traction_resultant(const std::vector<TractionLoad>& tractions,
                               const ParticleState<Dim>& particles, double t) {
  Vec3 sum{0.0, 0.0, 0.0};
  for (const TractionLoad& load : tractions)
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      const auto p = static_cast<std::size_t>(load.particles[k]);
      const double area = particles.volume[p] / load.length0[k];
      for (int a = 0; a < Dim; ++a) {
        double v = load.source->traction[a] ? load.source->traction[a](t) : 0.0;
        if (!load.x0.empty() && load.source->traction_field[a])
          v = load.source->traction_field[a](load.x0[k], t);
        sum[static_cast<std::size_t>(a)] += v * area;
      }
    }
  return sum;
}

/// Surface loads at time t, mapped at the loaded face of each selected
/// particle and added to the nodal force (for_face_nodes; DeadLoad: the
/// quasi-static scheme, whose Terzaghi and Mandel loads are fixed forces).
/// Only nodes that carry the soil take load (`takes(node)`: nodes with
/// mass): a face inside the grid, whose GIMP or B-spline stencil reaches a
/// node above the soil, gives that node's share to the others (before, it
/// was lost: half_length / 4 of the load with GIMP, 12.5 % at one particle
/// per cell, issue 38). Where every node takes load the weights are used
/// as they are.
template <int Dim, class Shape, bool DeadLoad = false, class Takes>
inline void apply_tractions(const std::vector<TractionLoad>& tractions,
                            const ParticleState<Dim>& particles, GridState<Dim>& grid, double t,
                            Takes&& takes) {
  using Vec = VecD<Dim>;
  shape::Stencil<Dim, Shape> s;
  for (const TractionLoad& load : tractions) {
    Vec traction;
    for (int a = 0; a < Dim; ++a)
      traction[a] = load.source->traction[a] ? load.source->traction[a](t) : 0.0;
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      // A load that varies along the face: its formula at the particle's
      // initial position (once per loaded particle per step).
      if (!load.x0.empty())
        for (int a = 0; a < Dim; ++a)
          if (load.source->traction_field[a])
            traction[a] = load.source->traction_field[a](load.x0[k], t);
      double all = 0.0, kept = 0.0;
      for_face_nodes<Dim, Shape, DeadLoad>(load, k, particles, grid, s,
                                           [&](std::int64_t node, double wa) {
                                             all += wa;
                                             if (takes(node)) kept += wa;
                                           });
      if (!(kept > 0.0)) continue;
      if (kept == all) {
        for_face_nodes<Dim, Shape, DeadLoad>(
            load, k, particles, grid, s,
            [&](std::int64_t node, double wa) { grid.force[node] += wa * traction; });
        continue;
      }
      const double scale = all / kept;
      for_face_nodes<Dim, Shape, DeadLoad>(load, k, particles, grid, s,
                                           [&](std::int64_t node, double wa) {
                                             if (takes(node))
                                               grid.force[node] += (wa * scale) * traction;
                                           });
    }
  }
}

/// Water across the faces at time t into the nodal flux (the right-hand
/// side of s_i dp_i/dt): N area rate, positive into the soil. Only nodes
/// the scheme solves the mass balance at take water (`takes(node)`: the
/// nodes the saturated particles reach); a face that has moved into a cell
/// the soil does not reach (a swelling top, above its last node row) gives
/// those nodes' shares to the others of its stencil, so that all the water
/// enters. Where every node takes water the weights are used as they are.
template <int Dim, class Shape, bool DeadLoad = false, class Takes>
inline void apply_fluxes(const std::vector<FluxLoad>& fluxes, const ParticleState<Dim>& particles,
                         GridState<Dim>& grid, double t, Takes&& takes) {
  shape::Stencil<Dim, Shape> s;
  for (const FluxLoad& load : fluxes) {
    const FieldOfSpaceTime& rate = load.source->rate;
    if (!rate) continue;
    const double uniform = load.x0.empty() ? rate(Vec3{0.0, 0.0, 0.0}, t) : 0.0;
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      const double r = load.x0.empty() ? uniform : rate(load.x0[k], t);
      double all = 0.0, kept = 0.0;
      for_face_nodes<Dim, Shape, DeadLoad>(load, k, particles, grid, s,
                                           [&](std::int64_t node, double wa) {
                                             all += wa;
                                             if (takes(node)) kept += wa;
                                           });
      if (!(kept > 0.0)) continue;      // no node of the face's stencil holds water
      const double scale = all / kept;  // exactly 1 when every node takes water
      for_face_nodes<Dim, Shape, DeadLoad>(
          load, k, particles, grid, s, [&](std::int64_t node, double wa) {
            if (takes(node)) grid.flux[static_cast<std::size_t>(node)] += wa * scale * r;
          });
    }
  }
}

}  // namespace hmpm
