// boundary/surface_pressures.hpp — pore pressures prescribed on the faces of
// particles (Problem::surface_pressures; internal).
//
// A node condition fixes the pressure where the grid's nodes are; the
// soil's surface is where its particles are: inside a cell, between node
// rows, moving as the soil settles. A SurfacePressure acts through the
// particles it selects (the selection and the face of a traction or a flux,
// boundary/tractions.hpp): each exchanges water with its face through the
// half-particle between its centre and the face, a Robin condition
//
//   q = C (p_face - p_bar),   C = (k/gamma_w) A / (l/2) = 2 (k/gamma_w) V / l^2,
//
// q the volume rate into the soil (m^3/s), p_bar = sum N_i p_i the pressure
// interpolated at the particle, l the particle's current length along the
// face normal (its initial length times the Dim-th root of its volume
// ratio, as the traction's face position) and A = V / l the face's area. A
// seepage face has p_face = 0 and q <= 0 (water leaves, never enters).
// The water crosses the face: it is taken to the particle's nodes with the
// shape functions at the face's centre (face_weights), the pressure read
// at the particle with its own weights N: the term C w N^T, which holds the
// linear steady profile exactly. Explicit scheme: the flux with p_bar at
// the start of the step (phases/particle_to_grid.hpp), its stable step
// shortened for it (explicit_rules.cpp); semi-implicit: that flux, with
// the symmetric C N N^T dt in the pressure system (zero at steady state:
// it acts on the increment only) to keep it stable at long steps;
// quasi-static: in the mass-balance residual and its (unsymmetric)
// Jacobian.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "boundary/tractions.hpp"
#include "hmpm/problem.hpp"
#include "materials/material.hpp"
#include "shape.hpp"
#include "state/grid.hpp"
#include "state/particles.hpp"

namespace hmpm {

/// The particles a SurfacePressure selects on its face.
struct SurfacePressureLoad : FaceParticles {
  const SurfacePressure* source = nullptr;
};

/// The surface pressures of `problem` (saturated runs; volume0: the
/// particles' initial volumes).
template <int Dim>
std::vector<SurfacePressureLoad> compile_surface_pressures(const Problem& problem,
                                                           const ParticleState<Dim>& particles,
                                                           const std::vector<double>& volume0,
                                                           const GridState<Dim>& grid) {
  std::vector<SurfacePressureLoad> loads;
  for (const SurfacePressure& s : problem.surface_pressures) {
    SurfacePressureLoad load;
    static_cast<FaceParticles&>(load) = select_face_particles(problem, s, particles, volume0, grid);
    load.source = &s;
    loads.push_back(std::move(load));
  }
  return loads;
}

/// Calls f(p, C, p_face, seepage) for every saturated particle a surface
/// pressure selects, at time t: C the conductance of its half-particle
/// (m^3/(Pa s)), p_face the prescribed pressure at its face's current
/// centre (0 on a seepage face).
template <int Dim, class F>
inline void for_surface_particles(const std::vector<SurfacePressureLoad>& loads,
                                  const ParticleState<Dim>& particles,
                                  const std::vector<MaterialConstants>& constants, double t,
                                  F&& f) {
  for (const SurfacePressureLoad& load : loads) {
    const SurfacePressure& source = *load.source;
    for (std::size_t k = 0; k < load.particles.size(); ++k) {
      const auto p = static_cast<std::size_t>(load.particles[k]);
      const MaterialConstants& mc = constants[particles.material[p]];
      if (!mc.saturated) continue;
      const double volume = particles.volume[p];
      const double length = load.length0[k] * std::pow(volume / load.volume0[k], 1.0 / Dim);
      const double c = 2.0 * mc.permeability_over_gamma * volume / (length * length);
      VecD<Dim> face = particles.x[p];
      face[load.axis] += load.side * 0.5 * length;
      double p_face = 0.0;
      if (!source.seepage) {
        Vec3 at{0.0, 0.0, 0.0};
        for (int a = 0; a < Dim; ++a) at[a] = face[a];
        p_face = source.pore_pressure(at, t);
      }
      f(p, c, p_face, source.seepage, face);
    }
  }
}

/// The weights w that take a particle's exchange to the nodes of its own
/// stencil `sp` (particle p, its face's centre `face`): the face's weights
/// (face_node_weights, those of a traction: the water crosses the face
/// there; with the particle's own weights the linear steady profile was
/// not a steady state, 2-11 % of q off in Terzaghi's column), on the nodes
/// of the particle's stencil only (the nodes the particle gives storage; a
/// face node outside it gives its share to the others), each at most 4
/// times the particle's own weight there (a node the particle barely
/// reaches gets little storage from it: the cap bounds the explicit
/// scheme's stiffness), then scaled to sum to 1.
template <int Dim, class Shape>
inline void face_weights(const shape::Stencil<Dim, Shape>& sp, const VecD<Dim>& face,
                         const GridState<Dim>& grid, const ParticleState<Dim>& particles,
                         std::size_t p, double* w) {
  using StencilT = shape::Stencil<Dim, Shape>;
  for (int k = 0; k < StencilT::N; ++k) w[k] = 0.0;
  int axis = 0;
  for (int a = 1; a < Dim; ++a)
    if (std::abs(face[a] - particles.x[p][a]) > std::abs(face[axis] - particles.x[p][axis]))
      axis = a;
  const double offset = face[axis] - particles.x[p][axis];
  StencilT sf;
  face_node_weights<Dim, Shape>(particles.x[p], axis, offset < 0.0 ? -1 : 1, 2.0 * std::abs(offset),
                                grid, shape::box_of(particles, p), sf,
                                [&](std::int64_t node, double wn) {
                                  for (int k = 0; k < StencilT::N; ++k)
                                    if (node == sp.node[k]) w[k] += wn;
                                });
  double sum = 0.0;
  for (int k = 0; k < StencilT::N; ++k) {
    w[k] = std::clamp(w[k], 0.0, 4.0 * sp.w[k]);
    sum += w[k];
  }
  if (!(sum > 0.0)) {  // no face node in the particle's stencil: its own weights
    for (int k = 0; k < StencilT::N; ++k) w[k] = sp.w[k];
    return;
  }
  for (int k = 0; k < StencilT::N; ++k) w[k] /= sum;
}

/// The volume rate into the soil of a particle with conductance c, face
/// pressure p_face and interpolated pressure p_bar (seepage: outflow only).
inline double surface_inflow(double c, double p_face, double p_bar, bool seepage) {
  const double q = c * (p_face - p_bar);
  return seepage && q > 0.0 ? 0.0 : q;
}

}  // namespace hmpm
