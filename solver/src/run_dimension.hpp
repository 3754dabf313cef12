// run_dimension.hpp — the solver's compiled entry points (internal).
// run.cpp checks the Problem and calls the run_simulation of its dimension
// and shape function; they are defined, with the Simulation explicitly
// instantiated, in simulation_instance.cpp, compiled once per dimension
// (solver/CMakeLists.txt).
#pragma once

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

namespace shape {
struct Linear;
struct Gimp;
struct BSpline;
}  // namespace shape

/// Runs a checked Problem of dimension Dim (1, 2 or 3) with shape function Shape.
template <int Dim, class Shape>
RunResult run_simulation(const Problem& problem, const RunOptions& options);

}  // namespace hmpm
