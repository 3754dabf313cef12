// problems.hpp — builders of the reference problems as typed hmpm::Problem,
// parameterised so tests can vary them (moduli, lengths, orientation, dimension).
#pragma once

#include <cmath>
#include <limits>

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

/// A dry linear elastic material.
inline hmpm::Material elastic(double rho, double e, double nu) {
  hmpm::Material m;
  m.name = "soil";
  m.density = rho;
  m.youngs_modulus = e;
  m.poisson_ratio = nu;
  return m;
}

/// A dry, normally consolidated Modified Cam-Clay "clay" (OCR 1), with
/// `e` its reference Young's modulus (the stable-step rules' stiffness).
inline hmpm::Material cam_clay(double rho, double e, double nu, double lambda, double kappa,
                               double m_ratio, double e0) {
  hmpm::Material m = elastic(rho, e, nu);
  m.name = "clay";
  hmpm::ModifiedCamClay cc;
  cc.lambda = lambda;
  cc.kappa = kappa;
  cc.critical_state_ratio = m_ratio;
  cc.initial_void_ratio = e0;
  cc.overconsolidation_ratio = 1.0;
  m.plasticity = cc;
  return m;
}

/// A linear elastic saturated material (incompressible grains, water of
/// density 1000 kg/m^3 and bulk modulus kw).
inline hmpm::Material saturated_elastic(double rho_s, double e, double nu, double porosity,
                                        double k, double kw) {
  hmpm::Material m;
  m.name = "clay";
  m.density = rho_s;
  m.youngs_modulus = e;
  m.poisson_ratio = nu;
  m.hydraulic = hmpm::Hydraulic{porosity, k, kw, 1000.0, std::numeric_limits<double>::infinity()};
  return m;
}

/// Terzaghi's consolidation on a column() of height h along `axis` with
/// `cells` x `ppc` particles along it: the base (x_axis = 0) fixed, p = 0 on
/// the node plane x_axis = drained_at (h: the loaded top; 0: the base), the
/// load q on the top row of particles, carried by the water at t = 0 (zero
/// effective stress, p = q).
inline void load_consolidation(hmpm::Problem& p, int axis, double h, int cells, int ppc, double q,
                               double drained_at) {
  p.bodies[0].initial.pore_pressure = [q](const hmpm::Vec3&) { return q; };
  p.boundaries.push_back(fixed_velocity(plane(p, axis, 0.0), axis));
  p.boundaries.push_back(fixed_pressure(plane(p, axis, drained_at), 0.0));
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  t.particles.min[axis] = h - h / (cells * ppc);  // the top row of particles
  t.axis = axis;
  t.side = +1;
  t.traction[axis] = constant(-q);
  p.tractions.push_back(t);
}

}  // namespace problems
