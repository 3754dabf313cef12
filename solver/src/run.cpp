// run.cpp — entry point: checks a Problem and dispatches to the solver of
// its dimension (simulation_instance.cpp, compiled per dimension for the linear,
// GIMP and B-spline shape functions, so every hot loop is compiled for fixed
// sizes).
#include <stdexcept>
#include <string>
#include <vector>

#include "hmpm/run.hpp"
#include "run_dimension.hpp"

namespace hmpm {

namespace {

/// The compiled Simulation of the problem's dimension and shape function.
template <int Dim>
RunResult run_with_shape(const Problem& problem, const RunOptions& options) {
  switch (problem.shape_function) {
    case ShapeFunction::gimp:
      return run_simulation<Dim, shape::Gimp>(problem, options);
    case ShapeFunction::bspline:
      return run_simulation<Dim, shape::BSpline>(problem, options);
    case ShapeFunction::linear:
      break;
  }
  return run_simulation<Dim, shape::Linear>(problem, options);
}

}  // namespace

RunResult run(const Problem& problem, const RunOptions& options) {
  const std::vector<ProblemIssue> issues = check_problem(problem);
  if (!issues.empty()) {
    std::string msg = "invalid problem:";
    for (const ProblemIssue& i : issues) {
      msg.append(" ").append(i.where.text()).append(": ").append(i.message).append(";");
    }
    throw std::invalid_argument(msg);
  }
  switch (problem.dimension) {
    case 1:
      return run_with_shape<1>(problem, options);
    case 2:
      return run_with_shape<2>(problem, options);
    default:
      return run_with_shape<3>(problem, options);
  }
}

}  // namespace hmpm
