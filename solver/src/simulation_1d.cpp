// simulation_1d.cpp — the 1D solver: Simulation<1, Shape> for the linear,
// GIMP and B-spline shape functions, instantiated here so that every hot loop
// of a 1D run is compiled, and inlined, in this one translation unit.
#include "simulation_impl.hpp"

namespace hmpm {

template class Simulation<1, shape::Linear>;
template class Simulation<1, shape::Gimp>;
template class Simulation<1, shape::BSpline>;

template <>
RunResult run_dimension<1>(const Problem& problem, const RunOptions& options) {
  return run_with_shape<1>(problem, options);
}

}  // namespace hmpm
