// simulation_impl.hpp — every definition of Simulation, for the explicit
// instantiations in simulation_{1,2,3}d.cpp (internal; include nowhere else).
#pragma once

#include "failures.hpp"
#include "output.hpp"
#include "phases/grid.hpp"
#include "phases/grid_to_particle.hpp"
#include "phases/particle_to_grid.hpp"
#include "phases/pore_pressure.hpp"
#include "phases/pressure_projection.hpp"
#include "phases/stress_and_flux.hpp"
#include "run_dimension.hpp"
#include "schemes/explicit_scheme.hpp"
#include "schemes/semi_implicit_scheme.hpp"
#include "setup.hpp"
#include "simulation.hpp"
#include "time_loop.hpp"

namespace hmpm {

/// The body of run_dimension<Dim>: the Simulation of the problem's shape function.
template <int Dim>
RunResult run_with_shape(const Problem& problem, const RunOptions& options) {
  switch (problem.shape_function) {
    case ShapeFunction::gimp:
      return Simulation<Dim, shape::Gimp>(problem).run(options);
    case ShapeFunction::bspline:
      return Simulation<Dim, shape::BSpline>(problem).run(options);
    case ShapeFunction::linear:
      break;
  }
  return Simulation<Dim, shape::Linear>(problem).run(options);
}

}  // namespace hmpm
