// problems.hpp — builders of the reference problems as typed hmpm::Problem,
// parameterised so tests can vary them (moduli, lengths, orientation, dimension).
#pragma once

#include <cmath>

#include "hmpm/problem.hpp"

namespace problems {

inline hmpm::FieldOfTime constant(double v) {
  return [v](double) { return v; };
}

/// A column along `axis` of a grid in `dim` dimensions, one cell wide
/// across, with roller walls (normal velocity zero) on the other axes.
inline hmpm::Problem column(int dim, int axis, double length, int cells, int ppc) {
  hmpm::Problem p;
  p.dimension = dim;
  for (int a = 0; a < dim; ++a) {
    p.grid.min[a] = 0.0;
    p.grid.max[a] = a == axis ? length : length / cells;
    p.grid.cells[a] = a == axis ? cells : 1;
  }
  hmpm::Body b;
  b.box.min = p.grid.min;
  b.box.max = p.grid.max;
  b.particles_per_cell = ppc;
  p.bodies.push_back(b);
  for (int a = 0; a < dim; ++a) {
    if (a == axis) continue;
    hmpm::Boundary roller;
    roller.nodes.all = true;
    roller.has_velocity = true;
    roller.velocity[a] = constant(0.0);
    p.boundaries.push_back(roller);
  }
  return p;
}

/// Nodes on the plane x_axis = value.
inline hmpm::NodeSelection plane(const hmpm::Problem& p, int axis, double value) {
  hmpm::NodeSelection s;
  s.box.min = p.grid.min;
  s.box.max = p.grid.max;
  s.box.min[axis] = s.box.max[axis] = value;
  return s;
}

inline hmpm::Boundary fixed_velocity(const hmpm::NodeSelection& nodes, int axis) {
  hmpm::Boundary b;
  b.nodes = nodes;
  b.has_velocity = true;
  b.velocity[axis] = constant(0.0);
  return b;
}

inline hmpm::Boundary fixed_pressure(const hmpm::NodeSelection& nodes, double value) {
  hmpm::Boundary b;
  b.nodes = nodes;
  b.pore_pressure = constant(value);
  return b;
}

}  // namespace problems
