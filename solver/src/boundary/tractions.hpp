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
#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>
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

/// The weights on the nodes of a particle's face (issue 38): those that a
/// uniform stress in the particles below the face balances exactly, so that
/// a load q on the face and the stress -q it leads to are in equilibrium
/// node by node (a mismatch set the whole column ringing: 11 % of q in
/// Terzaghi's column with GIMP or B-splines at 1 particle per cell).
/// centre: the particle's centre; axis, side: the face's outward normal;
/// length: the particle's current length along it. Calls emit(node, w)
/// once per node; the weights sum to 1 (inside the grid).
///  - Linear: the hat functions at the face's centre, the divergence
///    theorem on the cells.
///  - GIMP: the hat functions at the face's centre too. GIMP's gradients are
///    the particles' domain averages of the hat's, so the force of a
///    uniform stress is the hat's flux through the body's boundary, exactly.
///    (The particle-sized box at the face spread a quarter of its half
///    length to the nodes on either side.)
///  - B-spline: the point gradients do not integrate exactly, so the
///    weights are the forces themselves: w_i = sum_j l dN_i/dn (x_j) over
///    the particle and a column of particles of its length below it,
///    4 cells deep (the nodes within 2 cells of the face are then fully
///    reached; deeper ones sum to zero and are dropped), cut at the grid's
///    edge. At 2 particles per cell this is the B-spline at the face
///    (1/8, 3/4, 1/8); at 1 per cell it is (0, 1, 0), where the B-spline at
///    the face put 1/8 on a node the soil does not reach.
template <int Dim, class Shape, class Emit>
inline void face_node_weights(const VecD<Dim>& centre, int axis, int side, double length,
                              const GridState<Dim>& grid, shape::Box box,
                              shape::Stencil<Dim, Shape>& s, Emit&& emit) {
  using StencilT = shape::Stencil<Dim, Shape>;
  VecD<Dim> at = centre;
  at[axis] += side * 0.5 * length;
  if constexpr (!std::is_same_v<Shape, shape::BSpline>) {
    shape::Box point = box;
    if (box.half_length > 0.0)
      point = {shape::Gimp::min_half_length, 0.5 / shape::Gimp::min_half_length};
    s.template compute<false>(at, grid.origin, grid.inv_h, grid.cells, grid.stride, point);
    // GIMP at a face on the grid's edge: a stencil reaches a node beyond
    // the grid, whose share goes to the nodes inside. The others' weights
    // sum to 1 to round-off and are used as they are.
    double sum = 0.0;
    for (int n = 0; n < StencilT::N; ++n) sum += s.w[n];
    const double scale = std::abs(sum - 1.0) > 1e-12 ? 1.0 / sum : 1.0;
    for (int n = 0; n < StencilT::N; ++n) emit(s.node[n], s.w[n] * scale);
  } else {
    const double h = grid.h[axis];
    const double low = grid.origin[axis], high = low + grid.cells[axis] * h;
    const int deep = static_cast<int>(std::ceil(4.0 * h / length - 1e-9));
    constexpr int room = StencilT::N / 3 * 16;  // 3 + 4 cells' node rows, with room
    std::array<std::int64_t, room> node{};
    std::array<double, room> w{};
    int used = 0;
    VecD<Dim> y = centre;
    for (int j = 0; j <= deep; ++j) {
      y[axis] = centre[axis] - side * j * length;
      if (y[axis] <= low || y[axis] >= high) break;
      s.template compute<true>(y, grid.origin, grid.inv_h, grid.cells, grid.stride, box);
      for (int n = 0; n < StencilT::N; ++n) {
        const double d = side * length * s.dw[axis][n];
        int m = 0;
        while (m < used && node[m] != s.node[n]) ++m;
        if (m == used) {
          if (used == room) continue;  // not reached: 7 node rows at most
          node[used] = s.node[n];
          w[used++] = 0.0;
        }
        w[m] += d;
      }
    }
    double sum = 0.0;
    for (int m = 0; m < used; ++m) {
      const double depth = side * (at[axis] - grid.node_position(node[m])[axis]);
      if (depth > 2.0 * h + 1e-9 * h) w[m] = 0.0;
      sum += w[m];
    }
    if (!(std::abs(sum) > 1e-12)) return;
    for (int m = 0; m < used; ++m)
      if (w[m] != 0.0) emit(node[m], w[m] / sum);
  }
}

/// Calls add(node, N area) for the nodes of the loaded face of particle k of
/// `face` (face_node_weights): the face lies half the particle's current
/// length along the normal from its centre; its area follows the
/// particle's volume, V / length0 (a follower load: the explicit schemes),
/// or with DeadLoad keeps its initial area V0 / length0 (the quasi-static
/// scheme).
template <int Dim, class Shape, bool DeadLoad, class Add>
inline void for_face_nodes(const FaceParticles& face, std::size_t k,
                           const ParticleState<Dim>& particles, const GridState<Dim>& grid,
                           shape::Stencil<Dim, Shape>& s, Add&& add) {
  const auto p = static_cast<std::size_t>(face.particles[k]);
  const double stretch = std::pow(particles.volume[p] / face.volume0[k], 1.0 / Dim);
  const double area = (DeadLoad ? face.volume0[k] : particles.volume[p]) / face.length0[k];
  face_node_weights<Dim, Shape>(particles.x[p], face.axis, face.side, face.length0[k] * stretch,
                                grid, shape::box_of(particles, p), s,
                                [&](std::int64_t node, double w) { add(node, w * area); });
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
