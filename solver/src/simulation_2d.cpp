// simulation_2d.cpp — the 2D solver: Simulation<2, Shape> for the linear,
// GIMP and B-spline shape functions, instantiated here so that every hot loop
// of a 2D run is compiled, and inlined, in this one translation unit.
#include "simulation_impl.hpp"

namespace hmpm {

template class Simulation<2, shape::Linear>;
template class Simulation<2, shape::Gimp>;
template class Simulation<2, shape::BSpline>;

template <>
RunResult run_dimension<2>(const Problem& problem, const RunOptions& options) {
  return run_with_shape<2>(problem, options);
}

}  // namespace hmpm
