// boundary/check.cpp — see boundary/check.hpp.
#include "boundary/check.hpp"

#include <algorithm>
#include <string>

namespace hmpm {
namespace {

// A friction wall: one prescribed velocity component (its normal), in 2D or 3D.
void check_friction_boundaries(const Problem& problem, std::vector<ProblemIssue>& issues) {
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& bc = problem.boundaries[i];
    if (!bc.friction) continue;
    const Location w = Location{"boundaries"} / i / "friction";
    int prescribed = 0;
    for (int a = 0; a < problem.dimension; ++a) prescribed += bc.velocity[a] ? 1 : 0;
    if (problem.dimension == 1)
      issues.push_back({w, "needs a 2D or 3D problem: in 1D there is no tangential direction"});
    else if (prescribed != 1)
      issues.push_back({w,
                        "needs exactly one prescribed velocity component (the wall normal) and "
                        "the others null (free); this boundary prescribes " +
                            std::to_string(prescribed)});
    if (!(*bc.friction >= 0)) issues.push_back({w, "must be >= 0"});
  }
}

// Fluxes, surface pressures and seepage faces: they act on the pore water, so they need a
// saturated material (every scheme has both).
void check_hydraulic_boundaries(const Problem& problem, std::vector<ProblemIssue>& issues) {
  const bool saturated = std::any_of(problem.materials.begin(), problem.materials.end(),
                                     [](const Material& m) { return m.hydraulic.has_value(); });
  for (std::size_t i = 0; i < problem.fluxes.size(); ++i) {
    const Flux& f = problem.fluxes[i];
    const Location w = Location{"fluxes"} / i;
    if (!saturated)
      issues.push_back({w,
                        "moves pore water, but no material has `hydraulic` (a dry run has "
                        "none): give the soil's material a hydraulic section or remove the flux"});
    if (f.axis < 0 || f.axis >= problem.dimension)
      issues.push_back({w / "face", "names an axis this " + std::to_string(problem.dimension) +
                                        "D problem does not have"});
  }
  for (std::size_t i = 0; i < problem.surface_pressures.size(); ++i) {
    const SurfacePressure& s = problem.surface_pressures[i];
    const Location w = Location{"surface_pressures"} / i;
    if (!saturated)
      issues.push_back({w,
                        "acts on pore water, but no material has `hydraulic` (a dry run has "
                        "none): give the soil's material a hydraulic section or remove it"});
    if (s.axis < 0 || s.axis >= problem.dimension)
      issues.push_back({w / "face", "names an axis this " + std::to_string(problem.dimension) +
                                        "D problem does not have"});
    if (s.seepage == static_cast<bool>(s.pore_pressure))
      issues.push_back({w, "needs exactly one of pore_pressure (a value) and seepage: true"});
  }
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& b = problem.boundaries[i];
    if (!b.seepage) continue;
    const Location w = Location{"boundaries"} / i / "seepage";
    if (!saturated) issues.push_back({w, "needs pore water, but no material has `hydraulic`"});
    if (b.pore_pressure)
      issues.push_back({w,
                        "cannot share an entry with pore_pressure: a seepage face decides its "
                        "own pressure (p = 0 while water leaves); give the prescribed "
                        "pressure its own boundary entry (it wins where both meet)"});
  }
}

void check_absorbing_boundaries(const Problem& problem, std::vector<ProblemIssue>& issues) {
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& b = problem.boundaries[i];
    if (!b.absorbing) continue;
    const Location w = Location{"boundaries"} / i / "absorbing";
    if (problem.time.scheme != Scheme::explicit_scheme)
      issues.push_back({w, std::string("needs time.scheme 'explicit' (this ") +
                               (problem.stages.empty() ? "job" : "stage") + " runs '" +
                               scheme_name(problem.time.scheme) +
                               "'): dashpots act on inertia, which the quasi-static scheme "
                               "has none of, and the semi-implicit pressure system does not "
                               "carry them yet"});
    if (b.absorbing->normal < 0 || b.absorbing->normal >= problem.dimension)
      issues.push_back({w / "normal", "names an axis this " + std::to_string(problem.dimension) +
                                          "D problem does not have"});
    if (b.absorbing->material >= problem.materials.size())
      issues.push_back(
          {w / "material", "is " + std::to_string(b.absorbing->material) + " but the job has " +
                               std::to_string(problem.materials.size()) + " materials"});
    if (b.rigid[0] || b.rigid[1] || b.rigid[2] || b.friction)
      issues.push_back({w,
                        "cannot share an entry with 'rigid' or 'friction': give the tie or "
                        "wall its own boundary entry"});
  }
}

}  // namespace

void check_boundaries(const Problem& problem, std::vector<ProblemIssue>& issues) {
  check_friction_boundaries(problem, issues);
  check_absorbing_boundaries(problem, issues);
  check_hydraulic_boundaries(problem, issues);
}

}  // namespace hmpm
