// geostatic.hpp — the geostatic initial state of layered ground (internal).
//
// Computes, for every particle, the effective and pore-pressure state of
// Problem::initial_state.geostatic (see Geostatic in problem.hpp for the
// formulas) from the analytic integral of the bodies' densities over the
// particle's column. Bodies fill whole cells with uniform particles, so this
// integral is the particles' own mass above the particle, and the stress is
// linear inside every cell: the particle quadrature of the nodal forces
// integrates it exactly (linear and GIMP shape functions), so the state is
// in discrete equilibrium. Set-up code: allocates, never runs per step.
#pragma once

#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

class SetupInterrupt;

/// Per particle (global numbering), compression negative, Pa.
struct GeostaticState {
  int vertical_axis = 0;
  std::vector<double> vertical;    ///< sigma'_v
  std::vector<double> horizontal;  ///< sigma'_h = K0 sigma'_v
  std::vector<double> pressure;    ///< p (0 for dry materials)
};

/// Everything that keeps the geostatic state from being defined or at
/// rest: gravity not along one axis, initial fields given twice, several
/// pore fluids, `hydraulic` material above the water table or a table above
/// the ground surface. Empty when there is no geostatic block.
std::vector<ProblemIssue> check_geostatic(const Problem& problem);

/// What makes a geostatic state (valid by check_geostatic) start away from
/// rest: a ground surface that is not level (the particles' columns end at
/// heights more than a particle spacing apart). Empty without a geostatic block.
std::vector<ProblemIssue> geostatic_warnings(const Problem& problem);

/// The state at every particle. Requires check_geostatic(problem) to be empty.
/// `interrupt`, when given, is polled once per particle (set-up's stop checks).
GeostaticState geostatic_state(const Problem& problem, const SetupInterrupt* interrupt = nullptr);

/// Sets particle stress (Voigt, `dim` active axes) from a geostatic state:
/// helper shared by the solver's set-up for all dimensions.
inline void geostatic_voigt(const GeostaticState& g, std::size_t p, double* voigt6) {
  for (int c = 0; c < 3; ++c) voigt6[c] = g.horizontal[p];
  voigt6[g.vertical_axis] = g.vertical[p];
  for (int c = 3; c < 6; ++c) voigt6[c] = 0.0;
}

}  // namespace hmpm
