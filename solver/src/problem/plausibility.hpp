// problem/plausibility.hpp — warnings for values a runnable Problem holds that are
// far outside soil and rock ranges, and for loads and slopes a simple
// estimate says will fail (internal; docs/job-spec.md "Plausibility
// warnings" has the table of ranges and the rules). Called by
// problem_warnings, so they reach validate, the 201, the status document and
// summary.json like every other warning. Set-up code: allocates, never runs
// per step.
#pragma once

#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// Material parameters outside the usual range of soils and rocks (each
/// message: the value, the range, the likely mistake, what to change).
std::vector<ProblemIssue> material_plausibility(const Problem& problem);

/// A traction on part of the top of a Mohr-Coulomb or Drucker-Prager box
/// layer above the strip bearing capacity (Prandtl/Terzaghi, 2D only); a
/// free face of a cohesionless Mohr-Coulomb or Drucker-Prager body steeper
/// than its friction angle under gravity (2D only).
std::vector<ProblemIssue> stability_plausibility(const Problem& problem);

/// The strip bearing capacity of a surface footing (no surcharge) of width
/// b (m) on a half space of cohesion c (Pa), friction angle phi (degrees)
/// and unit weight gamma (N/m^3): c Nc + gamma b N_gamma / 2,
/// Nq = e^(pi tan phi) tan^2(45 + phi/2), Nc = (Nq - 1) cot phi (pi + 2 at
/// phi = 0), N_gamma = 2 (Nq + 1) tan phi (Vesic). Pa.
double strip_bearing_capacity(double c, double phi_deg, double gamma, double b);

}  // namespace hmpm
