// run.cpp — entry point: checks a Problem and dispatches to the Simulation
// instantiated for its dimension and shape function (1D/2D/3D x linear,
// GIMP, B-spline), so every hot loop is compiled for fixed sizes.
#include <stdexcept>

#include "hmpm/run.hpp"
#include "simulation.hpp"

namespace hmpm {

namespace {

template <int Dim>
RunResult run_dim(const Problem& problem, const RunOptions& options) {
  switch (problem.shape_function) {
    case ShapeFunction::gimp: return Simulation<Dim, shape::Gimp>(problem).run(options);
    case ShapeFunction::bspline: return Simulation<Dim, shape::BSpline>(problem).run(options);
    case ShapeFunction::linear: break;
  }
  return Simulation<Dim, shape::Linear>(problem).run(options);
}

}  // namespace

RunResult run(const Problem& problem, const RunOptions& options) {
  const std::vector<ProblemIssue> issues = check_problem(problem);
  if (!issues.empty()) {
    std::string msg = "invalid problem:";
    for (const ProblemIssue& i : issues) msg += " " + i.where + ": " + i.message + ";";
    throw std::invalid_argument(msg);
  }
  switch (problem.dimension) {
    case 1: return run_dim<1>(problem, options);
    case 2: return run_dim<2>(problem, options);
    default: return run_dim<3>(problem, options);
  }
}

}  // namespace hmpm
