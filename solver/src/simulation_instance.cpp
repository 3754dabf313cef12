// simulation_instance.cpp — Simulation<HMPM_DIM, Shape> for the linear, GIMP
// and B-spline shape functions, explicitly instantiated here so that every
// hot loop of a run of that dimension is compiled, and inlined, in this one
// translation unit. solver/CMakeLists.txt compiles this file three times,
// with HMPM_DIM = 1, 2 and 3, as separate object libraries.
#include "run_dimension.hpp"
#include "simulation_impl.hpp"

#ifndef HMPM_DIM
#error "simulation_instance.cpp needs HMPM_DIM (see solver/CMakeLists.txt)"
#endif

namespace hmpm {

template class Simulation<HMPM_DIM, shape::Linear>;
template class Simulation<HMPM_DIM, shape::Gimp>;
template class Simulation<HMPM_DIM, shape::BSpline>;

template <>
RunResult run_simulation<HMPM_DIM, shape::Linear>(const Problem& problem,
                                                  const RunOptions& options) {
  return Simulation<HMPM_DIM, shape::Linear>(problem).run(options);
}
template <>
RunResult run_simulation<HMPM_DIM, shape::Gimp>(const Problem& problem, const RunOptions& options) {
  return Simulation<HMPM_DIM, shape::Gimp>(problem).run(options);
}
template <>
RunResult run_simulation<HMPM_DIM, shape::BSpline>(const Problem& problem,
                                                   const RunOptions& options) {
  return Simulation<HMPM_DIM, shape::BSpline>(problem).run(options);
}

}  // namespace hmpm
