// boundary/check.hpp — the checks of the boundary conditions themselves:
// what a friction wall, an absorbing boundary, a seepage face or a flux
// needs of the problem (its dimension, scheme and materials) and which of
// them cannot share an entry. Beside the boundaries so that a boundary type
// brings its checks with it; check_problem (problem/check.cpp) calls them.
#pragma once

#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// Appends to `issues` what keeps the problem's boundaries (friction,
/// absorbing, seepage) and fluxes from running, each at its JSON path.
void check_boundaries(const Problem& problem, std::vector<ProblemIssue>& issues);

}  // namespace hmpm
