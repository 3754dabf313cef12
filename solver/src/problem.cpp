// problem.cpp — everything about a Problem that is not the time loop:
// particle generation and numbering, the stable time step (the scheme's
// rule, schemes/), and the checks that decide whether a Problem can run at
// all.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "geostatic.hpp"
#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

const char* status_name(RunStatus s) {
  switch (s) {
    case RunStatus::successful:
      return "successful";
    case RunStatus::failed:
      return "failed";
    case RunStatus::cancelled:
      return "dismissed";
  }
  return "failed";
}

// ---------------------------------------------------------------- layout

BodyLayout body_layout(const Problem& problem, const Body& body) {
  BodyLayout layout;
  const int ppc = std::max(body.particles_per_cell, 1);
  for (int a = 0; a < 3; ++a) {
    layout.coords[a].clear();
    if (a >= problem.dimension) {
      layout.coords[a].push_back(0.0);
      continue;
    }
    const double h = (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a];
    const double tol = 1e-9 * h;
    for (int c = 0; c < problem.grid.cells[a]; ++c) {
      const double lo = problem.grid.min[a] + c * h;
      const double hi = lo + h;
      if (lo < body.box.min[a] - tol || hi > body.box.max[a] + tol) continue;
      for (int k = 0; k < ppc; ++k) layout.coords[a].push_back(lo + (k + 0.5) * h / ppc);
    }
  }
  layout.count = static_cast<std::int64_t>(layout.coords[0].size()) *
                 static_cast<std::int64_t>(layout.coords[1].size()) *
                 static_cast<std::int64_t>(layout.coords[2].size());
  return layout;
}

std::int64_t count_particles(const Problem& problem) {
  std::int64_t n = 0;
  for (const Body& b : problem.bodies) n += body_layout(problem, b).count;
  return n;
}

std::vector<Vec3> initial_positions(const Problem& problem) {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(count_particles(problem)));
  for (const Body& b : problem.bodies) {
    const BodyLayout layout = body_layout(problem, b);
    for (double z : layout.coords[2])
      for (double y : layout.coords[1])
        for (double x : layout.coords[0]) out.push_back({x, y, z});
  }
  return out;
}

std::int64_t nearest_particle(const Problem& problem, const Vec3& x) {
  std::int64_t best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::int64_t index = 0;
  for (const Body& b : problem.bodies) {
    const BodyLayout layout = body_layout(problem, b);
    for (double pz : layout.coords[2])
      for (double py : layout.coords[1])
        for (double px : layout.coords[0]) {
          const double d2 =
              (px - x[0]) * (px - x[0]) + (py - x[1]) * (py - x[1]) + (pz - x[2]) * (pz - x[2]);
          if (d2 < best_d2) {
            best_d2 = d2;
            best = index;
          }
          ++index;
        }
  }
  return best;
}

// ---------------------------------------------------------------- time step

double min_cell_size(const Problem& problem) {
  double h = std::numeric_limits<double>::infinity();
  for (int a = 0; a < problem.dimension; ++a)
    h = std::min(h, (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a]);
  return h;
}

StableStep stable_step(const Problem& problem) {
  return scheme_rules(problem).stable_step(problem);
}

// ---------------------------------------------------------------- checks

namespace {

std::string fmt(double v) {
  return format_significant(v, 4);
}

}  // namespace

std::vector<ProblemIssue> problem_warnings(const Problem& problem) {
  std::vector<ProblemIssue> warnings;
  for (const Material& m : problem.materials) {
    const MaterialConstants c = material_constants(m, problem.gravity_constant);
    // From 0.9 of the equations' limit (the scheme's limit is the same):
    // near it, waves hardly decay.
    const double growth = darcy_inertia_growth_ratio(c);
    if (growth <= 0.9) continue;
    const std::string what =
        std::isinf(growth)
            ? "the grains are not denser than the fluid (density " + fmt(m.density) +
                  " kg/m3, fluid " + fmt(c.fluid_density) +
                  "), so the u-p equations with the rho_f a term of Darcy's law have growing "
                  "solutions for any stiffness: oscillations can grow and the run can diverge. "
                  "What to change: check density (the grain density, not the mixture's), or "
                  "set darcy_inertia: false (drops the term)"
            : "constrained modulus x storage (E_oed Q = " + fmt(c.constrained_modulus * c.storage) +
                  ") is " + fmt(growth) +
                  " times (rho - rho_f)/rho_f, above which the u-p equations with the rho_f a "
                  "term of Darcy's law have growing solutions (near it, waves hardly decay): "
                  "oscillations can grow and the run can diverge. What to change: a stiffer "
                  "fluid_bulk_modulus, local_damping for quasi-static runs, or darcy_inertia: "
                  "false (drops the term)";
    warnings.push_back({Location{"materials", m.name, "hydraulic"}, what});
  }
  return warnings;
}

std::vector<ProblemIssue> check_problem(const Problem& problem) {
  std::vector<ProblemIssue> issues;
  auto add = [&](Location where, std::string msg) {
    issues.push_back({std::move(where), std::move(msg)});
  };
  const int dim = problem.dimension;
  if (dim < 1 || dim > 3) {
    add({"dimension"}, "must be 1, 2 or 3");
    return issues;
  }
  for (int a = 0; a < dim; ++a) {
    if (problem.grid.cells[a] < 1)
      add(Location{"grid", "cells"} / static_cast<std::size_t>(a), "must be >= 1");
    if (!(problem.grid.max[a] > problem.grid.min[a]))
      add(Location{"grid", "max"} / static_cast<std::size_t>(a), "must be greater than grid.min");
  }
  if (!issues.empty()) return issues;

  for (std::size_t i = 0; i < problem.materials.size(); ++i) {
    const Material& m = problem.materials[i];
    const Location w{"materials", m.name};
    if (!(m.density > 0)) add(w / "density", "must be > 0");
    if (!(m.youngs_modulus > 0)) add(w / "youngs_modulus", "must be > 0");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      add(w / "poisson_ratio", "must be in (-1, 0.5)");
    if (m.hydraulic) {
      const Hydraulic& hy = *m.hydraulic;
      if (!(hy.porosity > 0 && hy.porosity < 1))
        add(w / "hydraulic" / "porosity", "must be in (0, 1)");
      if (!(hy.hydraulic_conductivity >= 0))
        add(w / "hydraulic" / "hydraulic_conductivity", "must be >= 0");
      if (!(hy.fluid_bulk_modulus > 0)) add(w / "hydraulic" / "fluid_bulk_modulus", "must be > 0");
      if (!(hy.fluid_density > 0)) add(w / "hydraulic" / "fluid_density", "must be > 0");
      if (!(hy.solid_bulk_modulus > 0)) add(w / "hydraulic" / "solid_bulk_modulus", "must be > 0");
    }
  }
  if (problem.bodies.empty()) add({"bodies"}, "at least one body is needed");
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    const Location w = Location{"bodies"} / b;
    if (body.material < 0 || body.material >= static_cast<int>(problem.materials.size()))
      add(w / "material", "names no material");
    if (body.particles_per_cell < 1)
      add(w / "particles_per_cell", "must be >= 1");
    else if (body_layout(problem, body).count == 0)
      add(w / "box",
          "contains no whole grid cell, so no particles; a body fills the cells "
          "that lie entirely inside its box");
  }
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& bc = problem.boundaries[i];
    if (!bc.friction) continue;
    const Location w = Location{"boundaries"} / i / "friction";
    int prescribed = 0;
    for (int a = 0; a < dim; ++a) prescribed += bc.velocity[a] ? 1 : 0;
    if (dim == 1)
      add(w, "needs a 2D or 3D problem: in 1D there is no tangential direction");
    else if (prescribed != 1)
      add(w,
          "needs exactly one prescribed velocity component (the wall normal) and the others "
          "null (free); this boundary prescribes " +
              std::to_string(prescribed));
    if (!(*bc.friction >= 0)) add(w, "must be >= 0");
  }
  if (!(problem.time.end > 0)) add({"time", "end"}, "must be > 0");
  if (!(problem.time.courant > 0 && problem.time.courant <= 1))
    add({"time", "courant"}, "must be in (0, 1]");
  if (problem.time.dt && !(*problem.time.dt > 0)) add({"time", "dt"}, "must be > 0");
  if (!issues.empty()) return issues;

  const SchemeRules& scheme = scheme_rules(problem);
  scheme.check(problem, scheme.stable_step(problem), issues);
  const std::int64_t n = count_particles(problem);
  for (std::size_t i = 0; i < problem.output.series_particles.size(); ++i) {
    const std::int64_t p = problem.output.series_particles[i];
    if (p < 0 || p >= n)
      add(Location{"output", "series", "particles"} / i,
          "particle " + std::to_string(p) + " does not exist; there are " + std::to_string(n) +
              " particles (0.." + std::to_string(n - 1) + ")");
  }
  for (ProblemIssue& issue : check_geostatic(problem)) issues.push_back(std::move(issue));
  return issues;
}

}  // namespace hmpm
