// run_dimension.hpp — the per-dimension entry points of the solver
// (internal). run.cpp checks the Problem and calls the one of its
// dimension; each is defined, with the Simulation explicitly instantiated
// for its three shape functions, in simulation_{1,2,3}d.cpp.
#pragma once

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// Runs a checked Problem of dimension Dim (1, 2 or 3).
template <int Dim>
RunResult run_dimension(const Problem& problem, const RunOptions& options);

}  // namespace hmpm
