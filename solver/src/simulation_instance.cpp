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

namespace {

/// Sets up and runs; a set-up stopped by cancellation or the wall-time
/// limit (interrupt.hpp) ends the run as cancelled or failed.
template <class Shape>
RunResult run_checked(const Problem& problem, const RunOptions& options) {
  try {
    const Problem regularised = regularise_softening(problem);  // lives as long as the run
    Simulation<HMPM_DIM, Shape> simulation(regularised, options);
    return simulation.run(options);
  } catch (const SetupInterrupted& stop) {
    RunResult result;
    result.status = stop.status;
    result.message = stop.message;
    result.scheme = scheme_name(problem.time.scheme);
    result.reports_iterations = scheme_row(problem.time.scheme).reports_iterations;
    return result;
  }
}

}  // namespace

template <>
RunResult run_simulation<HMPM_DIM, shape::Linear>(const Problem& problem,
                                                  const RunOptions& options) {
  return run_checked<shape::Linear>(problem, options);
}
template <>
RunResult run_simulation<HMPM_DIM, shape::Gimp>(const Problem& problem, const RunOptions& options) {
  return run_checked<shape::Gimp>(problem, options);
}
template <>
RunResult run_simulation<HMPM_DIM, shape::BSpline>(const Problem& problem,
                                                   const RunOptions& options) {
  return run_checked<shape::BSpline>(problem, options);
}

}  // namespace hmpm
