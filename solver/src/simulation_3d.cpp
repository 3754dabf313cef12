// simulation_3d.cpp — the 3D solver: Simulation<3, Shape> for the linear,
// GIMP and B-spline shape functions, instantiated here so that every hot loop
// of a 3D run is compiled, and inlined, in this one translation unit.
#include "simulation_impl.hpp"

namespace hmpm {

template class Simulation<3, shape::Linear>;
template class Simulation<3, shape::Gimp>;
template class Simulation<3, shape::BSpline>;

template <>
RunResult run_dimension<3>(const Problem& problem, const RunOptions& options) {
  return run_with_shape<3>(problem, options);
}

}  // namespace hmpm
