// problem/check.cpp — whether a Problem can run at all (check_problem):
// the grid, materials, bodies' shapes and layouts, selections, the time
// step of its scheme (schemes/), output requests, the geostatic stage and
// every stage in force. The boundaries' own checks are in boundary/check.cpp;
// the warnings for runnable but doubtful values in problem/warnings.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "boundary/check.hpp"
#include "geometry/polygon.hpp"
#include "geostatic.hpp"
#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/varying.hpp"
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

StableStep stable_step(const Problem& problem) {
  return scheme_rules(problem).stable_step(problem);
}

namespace {

/// Where the job spec gives a material parameter.
Location parameter_location(const Material& m, MaterialParameter k) {
  const Location w{"materials", m.name};
  return k == MaterialParameter::hydraulic_conductivity ? w / "hydraulic" / parameter_name(k)
                                                        : w / parameter_name(k);
}

/// A random field's own numbers.
void check_random_field(const RandomField& f, int dim, const Location& w,
                        std::vector<ProblemIssue>& issues) {
  const Location d = w / "random_field" / "distribution";
  switch (f.distribution) {
    case RandomField::Distribution::lognormal:
      if (!(f.first > 0)) issues.push_back({d / "lognormal" / "mean", "must be > 0"});
      if (!(f.second >= 0 && std::isfinite(f.second)))
        issues.push_back({d / "lognormal" / "cov", "must be >= 0"});
      break;
    case RandomField::Distribution::normal:
      if (!std::isfinite(f.first)) issues.push_back({d / "normal" / "mean", "must be finite"});
      if (!(f.second >= 0 && std::isfinite(f.second)))
        issues.push_back({d / "normal" / "std", "must be >= 0"});
      break;
    case RandomField::Distribution::uniform:
      if (!(std::isfinite(f.first) && std::isfinite(f.second) && f.first <= f.second))
        issues.push_back({d / "uniform", "needs finite min <= max"});
      break;
  }
  for (int a = 0; a < dim; ++a)
    if (!(f.correlation_length[static_cast<std::size_t>(a)] > 0))
      issues.push_back(
          {w / "random_field" / "correlation_length" / static_cast<std::size_t>(a), "must be > 0"});
}

/// Varying material parameters: each once, of a parameter the material
/// has, and every particle's value in the parameter's range (the fields
/// generated here as the run will: a normal field can leave it).
void check_varying(const Problem& problem, std::vector<ProblemIssue>& issues) {
  const std::size_t before = issues.size();
  bool any = false;
  for (const Material& m : problem.materials) {
    std::array<bool, material_parameter_count> seen{};
    for (const VaryingParameter& v : m.varying) {
      any = true;
      const Location w = parameter_location(m, v.parameter);
      if (seen[static_cast<std::size_t>(v.parameter)]) issues.push_back({w, "varies twice"});
      seen[static_cast<std::size_t>(v.parameter)] = true;
      if (!parameter_applies(m, v.parameter))
        issues.push_back({w, "does not apply to this material, so it cannot vary"});
      if (v.random_field) check_random_field(*v.random_field, problem.dimension, w, issues);
    }
  }
  if (!any || issues.size() > before) return;
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  for (std::size_t i = 0; i < problem.materials.size(); ++i) {
    const Material& m = problem.materials[i];
    if (m.varying.empty()) continue;
    const std::vector<std::vector<double>> values = varying_values(problem, i, layouts);
    for (std::size_t k = 0; k < m.varying.size(); ++k) {
      const MaterialParameter parameter = m.varying[k].parameter;
      for (double value : values[k]) {
        const std::string why = parameter_range_issue(parameter, value);
        if (why.empty()) continue;
        issues.push_back(
            {parameter_location(m, parameter),
             "takes the value " + format_significant(value, 4) + " at a particle, which " + why +
                 (m.varying[k].random_field && m.varying[k].random_field->distribution ==
                                                   RandomField::Distribution::normal
                      ? ": a normal distribution is unbounded; use a lognormal one (always "
                        "positive) or a uniform one within the range"
                      : "")});
        break;
      }
    }
  }
}

}  // namespace

/// A polygon must have 3 or more vertices, no repeated vertex, non-zero
/// area and no crossing or touching edges.
void check_polygon(const Polygon& polygon, const Location& w, std::vector<ProblemIssue>& issues) {
  const std::vector<geometry::Point2>& v = polygon.vertices;
  const std::size_t n = v.size();
  if (n < 3) {
    issues.push_back({w, "has " + std::to_string(n) +
                             " vertices; a polygon needs at least 3, [[x, y], ...] in order "
                             "along its boundary (it closes itself)"});
    return;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = (k + 1) % n;
    if (v[k] == v[next]) {
      const std::size_t later = std::max(k, next), earlier = std::min(k, next);
      issues.push_back({w / later, "repeats vertex " + std::to_string(earlier) +
                                       "; list each corner once (the polygon closes itself: do "
                                       "not repeat the first vertex at the end)"});
      return;
    }
  }
  const auto [lo, hi] = geometry::bounds(v);
  const double extent = std::max(hi[0] - lo[0], hi[1] - lo[1]);
  if (std::abs(geometry::signed_area(v)) <= 1e-12 * extent * extent) {
    issues.push_back({w,
                      "has zero area: its vertices lie on one line; give the corners of a "
                      "region"});
    return;
  }
  if (const auto crossing = geometry::self_intersection(v)) {
    const auto [i, j] = *crossing;
    auto edge = [&](std::size_t e) {
      return "edge " + std::to_string(e) + " (vertex " + std::to_string(e) + " to " +
             std::to_string((e + 1) % n) + ")";
    };
    issues.push_back({w, "is not a simple polygon: " + edge(i) + " and " + edge(j) +
                             " cross or touch; list the vertices in order along the boundary "
                             "so that no two edges meet except at their shared vertex"});
  }
}

namespace {

/// Whether a 2D point lies in the grid (within 1e-9 of its extent).
bool in_grid(const Problem& problem, const Vec3& x) {
  for (int a = 0; a < problem.dimension; ++a) {
    const double tol = 1e-9 * (problem.grid.max[a] - problem.grid.min[a]);
    if (!(x[a] >= problem.grid.min[a] - tol && x[a] <= problem.grid.max[a] + tol)) return false;
  }
  return true;
}

std::string grid_range(const Problem& problem) {
  std::string out;
  const char* names[] = {"x", "y", "z"};
  for (int a = 0; a < problem.dimension; ++a)
    out += std::string(a ? ", " : "") + names[a] + " in [" + format4(problem.grid.min[a]) + ", " +
           format4(problem.grid.max[a]) + "]";
  return out;
}

void check_selection_polygon(const Problem& problem, const Polygon& polygon, const Location& w,
                             std::vector<ProblemIssue>& issues) {
  if (problem.dimension != 2) {
    issues.push_back({w,
                      "selects by a polygon in the (x, y) plane, which needs a 2D problem; "
                      "this one is " +
                          std::to_string(problem.dimension) + "D: select by 'box'"});
    return;
  }
  check_polygon(polygon, w, issues);
}

void check_body_shape(const Problem& problem, const Body& body, const Location& w,
                      std::vector<ProblemIssue>& issues) {
  const int shapes = (body.polygon ? 1 : 0) + (body.prism ? 1 : 0) + (body.points ? 1 : 0);
  if (shapes > 1) {
    issues.push_back({w,
                      "gives more than one shape; give exactly one of 'box', 'polygon', "
                      "'prism' and 'points'"});
    return;
  }
  const int dim = problem.dimension;
  if (body.polygon) {
    if (dim != 2)
      issues.push_back(
          {w / "polygon", "is a 2D shape but this problem is " + std::to_string(dim) + "D; use " +
                              (dim == 3 ? "'prism' (a polygon extruded along an axis)" : "'box'") +
                              " or 'points'"});
    else
      check_polygon(*body.polygon, w / "polygon", issues);
  }
  if (body.prism) {
    const Prism& pr = *body.prism;
    if (dim != 3) {
      issues.push_back({w / "prism", "is a 3D shape but this problem is " + std::to_string(dim) +
                                         "D; use " + (dim == 2 ? "'polygon'" : "'box'") +
                                         " or 'points'"});
      return;
    }
    if (pr.axis < 0 || pr.axis > 2) issues.push_back({w / "prism" / "axis", "must be x, y or z"});
    if (!(pr.to > pr.from))
      issues.push_back(
          {w / "prism" / "to",
           "is " + format4(pr.to) + "; must be greater than from (" + format4(pr.from) + ")"});
    check_polygon(pr.polygon, w / "prism" / "polygon", issues);
  }
  if (body.points) {
    const ParticleList& pl = *body.points;
    const Location wp = w / "points";
    if (pl.positions.empty())
      issues.push_back({wp / "positions",
                        "is empty; give at least one "
                        "particle"});
    if (pl.volumes.size() != pl.positions.size())
      issues.push_back({wp / "volumes", "has " + std::to_string(pl.volumes.size()) +
                                            " entries but positions has " +
                                            std::to_string(pl.positions.size()) +
                                            "; give one volume per position"});
    int reported = 0;  // the first few of a long list say enough
    for (std::size_t k = 0; k < pl.volumes.size() && reported < 10; ++k)
      if (!(pl.volumes[k] > 0 && std::isfinite(pl.volumes[k]))) {
        issues.push_back({wp / "volumes" / k, "is " + format4(pl.volumes[k]) +
                                                  "; a particle volume must be > 0 (m^3 in 3D, "
                                                  "m^2 per metre in 2D, m in 1D)"});
        ++reported;
      }
    reported = 0;
    for (std::size_t k = 0; k < pl.positions.size() && reported < 10; ++k)
      if (!in_grid(problem, pl.positions[k])) {
        issues.push_back({wp / "positions" / k, "lies outside the grid (" + grid_range(problem) +
                                                    "); particles must start inside it"});
        ++reported;
      }
    // GIMP's stencil holds 3 nodes per axis: a particle box wider than a
    // cell (half-length above half a cell) reaches a fourth node, whose
    // share of the particle's mass and forces would be lost.
    if (problem.shape_function == ShapeFunction::gimp) {
      const double cell_v = cell_volume(problem);
      reported = 0;
      for (std::size_t k = 0; k < pl.volumes.size() && reported < 10; ++k)
        if (pl.volumes[k] > cell_v * (1.0 + 1e-9)) {
          std::string message = "is " + format4(pl.volumes[k]);
          message += ", more than one cell (";
          message += format4(cell_v);
          message +=
              "): with shape_function gimp a particle's box must fit in a cell, or part of "
              "its mass reaches nodes beyond the stencil and is lost; split it into smaller "
              "particles, use larger cells, or use shape_function bspline";
          issues.push_back({wp / "volumes" / k, std::move(message)});
          ++reported;
        }
    }
  }
}

}  // namespace

namespace {

/// The stages of a staged job: ends in order, body indices that exist and
/// are in the run when removed (absent when added), and every stage's own
/// Problem runnable: its issues, where the top level does not have them
/// already, at the stage (a list it sets at its own path; one in force
/// from before at the stage, naming it).
// Stage i's new materials of bodies: a body and a material that exist, the
// body given one material, and a material whose density and pore water are
// those of the one in force (the particles keep their mass, porosity and
// pore pressure).
void check_body_materials(const Problem& problem, std::size_t i,
                          std::vector<ProblemIssue>& issues) {
  const std::vector<Stage::BodyMaterial>& list = problem.stages[i].body_materials;
  const Problem before = stage_problem(problem, i);
  const std::size_t materials = problem.materials.size();
  for (std::size_t k = 0; k < list.size(); ++k) {
    const Location at = Location{"stages"} / i / "body_materials" / k;
    const Stage::BodyMaterial& bm = list[k];
    if (bm.body < 0 || static_cast<std::size_t>(bm.body) >= problem.bodies.size()) {
      issues.push_back({at / "body", "body " + std::to_string(bm.body) +
                                         " does not exist; there are " +
                                         std::to_string(problem.bodies.size()) + " bodies"});
      continue;
    }
    for (std::size_t e = 0; e < k; ++e)
      if (list[e].body == bm.body)
        issues.push_back({at / "body", "body " + std::to_string(bm.body) +
                                           " is given a material twice in this stage"});
    if (bm.material < 0 || static_cast<std::size_t>(bm.material) >= materials) {
      issues.push_back({at / "material", "material " + std::to_string(bm.material) +
                                             " does not exist; there are " +
                                             std::to_string(materials) + " materials"});
      continue;
    }
    const Material& from = problem.materials[static_cast<std::size_t>(
        before.bodies[static_cast<std::size_t>(bm.body)].material)];
    const Material& to = problem.materials[static_cast<std::size_t>(bm.material)];
    std::string differs;
    if (to.density != from.density) differs = "density";
    if (to.hydraulic.has_value() != from.hydraulic.has_value())
      differs = to.hydraulic ? "pore water (hydraulic)" : "pore water (no hydraulic)";
    else if (to.hydraulic && (to.hydraulic->porosity != from.hydraulic->porosity ||
                              to.hydraulic->fluid_density != from.hydraulic->fluid_density))
      differs = "porosity or fluid density";
    if (!differs.empty())
      issues.push_back(
          {at / "material",
           "'" + to.name + "' differs from '" + from.name + "', the body's material in force, in " +
               differs +
               ": the particles keep their mass and pore water, so the new material must have "
               "the same density, porosity and fluid density (change the model and its "
               "strength and stiffness parameters only)"});
    // A random field's values are drawn at set-up for the particles of the
    // bodies of its material then (materials/varying.hpp): a body that
    // changes material later would keep the values of the one it left.
    if (!to.varying.empty() || !from.varying.empty())
      issues.push_back(
          {at / "material",
           "'" + (to.varying.empty() ? from.name : to.name) + "' has a parameter that varies (" +
               parameter_name((to.varying.empty() ? from : to).varying.front().parameter) +
               "), and a stage cannot switch a body to or from such a material: its values are "
               "drawn at set-up for the bodies of the material then. Give the body that "
               "material from the start, or make the parameter a number"});
  }
}

void check_stages(const Problem& problem, std::vector<ProblemIssue>& issues) {
  if (problem.stages.empty()) return;
  std::vector<std::string> top;
  top.reserve(issues.size());
  for (const ProblemIssue& i : issues) top.push_back(i.where.text() + ": " + i.message);
  double previous = problem.time.end;
  for (std::size_t i = 0; i < problem.stages.size(); ++i) {
    const Stage& st = problem.stages[i];
    const Location at = Location{"stages"} / i;
    if (!(st.end > previous))
      issues.push_back({at / "end", "must be after the end of the stage before (" +
                                        format_significant(previous, 6) + " s)"});
    previous = std::max(previous, st.end);
    const std::vector<bool> before = stage_bodies(problem, i);
    auto bodies = [&](const std::vector<int>& list, const char* key, bool adding) {
      for (std::size_t k = 0; k < list.size(); ++k) {
        const int b = list[k];
        if (b < 0 || static_cast<std::size_t>(b) >= problem.bodies.size()) {
          issues.push_back({at / key / k, "body " + std::to_string(b) +
                                              " does not exist; there are " +
                                              std::to_string(problem.bodies.size()) + " bodies"});
          continue;
        }
        const bool in = before[static_cast<std::size_t>(b)];
        if (adding && in)
          issues.push_back({at / key / k, "body " + std::to_string(b) +
                                              " is in the run already (added by an earlier "
                                              "stage); a body can be added once"});
        if (!adding && !in)
          issues.push_back({at / key / k, "body " + std::to_string(b) +
                                              " is not in the run at this stage (removed "
                                              "before, or not added yet)"});
      }
    };
    bodies(st.add_bodies, "add_bodies", true);
    bodies(st.remove_bodies, "remove_bodies", false);
    check_body_materials(problem, i, issues);
    const std::vector<bool> after = stage_bodies(problem, i + 1);
    if (std::none_of(after.begin(), after.end(), [](bool b) { return b; }))
      issues.push_back({at / "remove_bodies", "leaves no body in the run"});
  }
  if (!issues.empty()) return;
  for (std::size_t i = 0; i < problem.stages.size(); ++i) {
    const Stage& st = problem.stages[i];
    const Location at = Location{"stages"} / i;
    auto sets = [&](const std::string& key) {
      return (key == "boundaries" && st.boundaries) || (key == "tractions" && st.tractions) ||
             (key == "fluxes" && st.fluxes) || (key == "time" && st.time) ||
             (key == "gravity" && st.gravity) || (key == "local_damping" && st.local_damping);
    };
    Problem in_force = stage_problem(problem, i + 1);
    // output.consolidation is the job's (its `from` may lie in a later
    // stage): checked once, with the whole job.
    in_force.output.consolidation = ConsolidationRequest{};
    // So are output.profiles' times (any may lie in a later stage).
    if (!in_force.output.profile_times.empty()) in_force.output.profile_times = {0.0};
    for (const ProblemIssue& issue : check_problem(in_force)) {
      const std::string text = issue.where.text() + ": " + issue.message;
      if (std::find(top.begin(), top.end(), text) != top.end()) continue;
      const std::string& key = issue.where.parts.empty() ? std::string() : issue.where.parts[0];
      if (key == "time" && issue.where.parts.size() > 1 && issue.where.parts[1] == "end") {
        issues.push_back({at / "end", issue.message});
      } else if (sets(key)) {
        Location where = at;
        for (const std::string& part : issue.where.parts) where = where / part;
        issues.push_back({where, issue.message});
      } else {
        issues.push_back({at, "with " + issue.where.text() +
                                  " in force from the stage before: " + issue.message});
      }
    }
  }
}

}  // namespace

// output.consolidation: pore water to drain, a reference instant inside
// the run, and a selection that holds some of it.
void check_consolidation(const Problem& problem, std::vector<ProblemIssue>& issues) {
  const ConsolidationRequest& c = problem.output.consolidation;
  if (!(c.interval > 0)) return;
  const Location w{"output", "consolidation"};
  std::vector<bool> wet(problem.materials.size());
  for (std::size_t m = 0; m < wet.size(); ++m) wet[m] = problem.materials[m].hydraulic.has_value();
  if (std::find(wet.begin(), wet.end(), true) == wet.end()) {
    issues.push_back({w,
                      "needs pore water, but no material has `hydraulic` (a dry run has no "
                      "pore pressure to dissipate): give the soil's material a hydraulic "
                      "section or remove output.consolidation"});
    return;
  }
  const double end = job_end_time(problem);
  if (!(c.from >= 0 && c.from < end))
    issues.push_back(
        {w / "from", "is " + format4(c.from) + " s; it must be in [0, " + format4(end) +
                         ") s, inside the run (the job ends at t = " + format4(end) + " s)"});
  if (c.all) return;
  std::int64_t held = 0;
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  for (std::size_t b = 0; b < layouts.size() && b < problem.bodies.size(); ++b) {
    const auto m = static_cast<std::size_t>(problem.bodies[b].material);
    if (m >= wet.size() || !wet[m]) continue;
    for (const Vec3& x : layouts[b].positions)
      if (particle_selected(problem, c, x)) ++held;
  }
  if (held == 0)
    issues.push_back({w / "particles",
                      "selects no particle with pore water: widen the box or polygon to hold "
                      "the consolidating ground, or leave 'particles' out to count every one"});
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
    else if (problem.grid.cells[a] < 2 && problem.shape_function != ShapeFunction::linear)
      // A 3-node stencil spans three node columns: one cell has two (the
      // stencil's first node fell outside the grid).
      add(Location{"grid", "cells"} / static_cast<std::size_t>(a),
          "must be >= 2 with shape_function gimp or bspline (their stencil spans 3 nodes)");
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
    if (const auto* cc = std::get_if<ModifiedCamClay>(&m.plasticity)) {
      if (!(cc->kappa > 0)) add(w / "kappa", "must be > 0");
      if (!(cc->lambda > cc->kappa))
        add(w / "lambda",
            "must be greater than kappa (the NCL is steeper than the unloading line)");
      if (!(cc->critical_state_ratio > 0)) add(w / "critical_state_ratio", "must be > 0");
      if (!(cc->initial_void_ratio > 0)) add(w / "initial_void_ratio", "must be > 0");
      if (!cc->preconsolidation_pressure && !(cc->overconsolidation_ratio >= 1))
        add(w / "overconsolidation_ratio", "must be >= 1");
    }
    if (const auto* mc = std::get_if<MohrCoulomb>(&m.plasticity); mc && mc->softening) {
      const MohrCoulomb::Softening& sf = *mc->softening;
      if (!(sf.shape_factor > 0)) add(w / "softening" / "shape_factor", "must be > 0");
      if (!(sf.residual_cohesion >= 0)) add(w / "softening" / "residual_cohesion", "must be >= 0");
      if (!(sf.residual_friction_angle_deg >= 0 && sf.residual_friction_angle_deg < 90))
        add(w / "softening" / "residual_friction_angle", "must be in [0, 90)");
      if (!(sf.reference_cell_size >= 0))
        add(w / "softening" / "reference_cell_size", "must be > 0 (0: not regularised)");
    }
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
  const std::size_t before_shapes = issues.size();
  for (std::size_t b = 0; b < problem.bodies.size(); ++b)
    check_body_shape(problem, problem.bodies[b], Location{"bodies"} / b, issues);
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i)
    if (problem.boundaries[i].nodes.polygon && !problem.boundaries[i].nodes.all)
      check_selection_polygon(problem, *problem.boundaries[i].nodes.polygon,
                              Location{"boundaries"} / i / "nodes" / "polygon", issues);
  for (std::size_t i = 0; i < problem.tractions.size(); ++i)
    if (problem.tractions[i].polygon)
      check_selection_polygon(problem, *problem.tractions[i].polygon,
                              Location{"tractions"} / i / "particles" / "polygon", issues);
  for (std::size_t i = 0; i < problem.fluxes.size(); ++i)
    if (problem.fluxes[i].polygon)
      check_selection_polygon(problem, *problem.fluxes[i].polygon,
                              Location{"fluxes"} / i / "particles" / "polygon", issues);
  for (std::size_t i = 0; i < problem.surface_pressures.size(); ++i)
    if (problem.surface_pressures[i].polygon)
      check_selection_polygon(problem, *problem.surface_pressures[i].polygon,
                              Location{"surface_pressures"} / i / "particles" / "polygon", issues);
  if (issues.size() > before_shapes) return issues;
  check_varying(problem, issues);
  const std::vector<BodyLayout> layouts = body_layouts(problem, LayoutDetail::counts);
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    const Location w = Location{"bodies"} / b;
    if (body.material < 0 || body.material >= static_cast<int>(problem.materials.size()))
      add(w / "material", "names no material");
    if (body.particles_per_cell < 1) {
      add(w / "particles_per_cell", "must be >= 1");
    } else if (layouts[b].count == 0 && !layouts[b].lost.empty()) {
      add(w,
          "has no particles: every particle position of it lies inside an earlier body, "
          "which owns it (a place inside several bodies gets one particle, of the first); "
          "remove the body or list it first");
    } else if (layouts[b].count == 0 && body.points) {
      add(w / "points" / "positions", "is empty; give at least one particle");
    } else if (layouts[b].count == 0 && (body.polygon || body.prism)) {
      add(w / (body.polygon ? "polygon" : "prism"),
          "contains no sub-cell centre, so no particles (particles lie at sub-cell centres, "
          "cell size / particles_per_cell apart); enlarge the shape or refine the grid");
    } else if (layouts[b].count == 0) {
      add(w / "box",
          "contains no whole grid cell, so no particles; a body fills the cells "
          "that lie entirely inside its box");
    }
  }
  check_boundaries(problem, issues);
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
  const OutputRequest& out = problem.output;
  for (std::size_t l = 0; l < out.profiles.size(); ++l) {
    const Location where = Location{"output", "profiles", "lines"} / l;
    for (const std::int64_t p : out.profiles[l].particles)
      if (p < 0 || p >= n) {
        add(where, "particle " + std::to_string(p) + " does not exist; there are " +
                       std::to_string(n) + " particles");
        break;
      }
    if (out.profiles[l].particles.empty() || out.profiles[l].fields.empty())
      add(where, "needs particles and fields");
  }
  if (!out.profiles.empty() && !(out.profile_interval > 0) && out.profile_times.empty())
    add({"output", "profiles", "interval"}, "must be > 0 (or give the profiles' times)");
  const double job_end = job_end_time(problem);
  for (std::size_t k = 0; k < out.profile_times.size(); ++k) {
    const double tk = out.profile_times[k];
    const Location where = Location{"output", "profiles", "times"} / k;
    if (!(tk >= 0 && tk <= job_end))
      add(where, "is " + format4(tk) + " s; it must be in [0, " + format4(job_end) +
                     "] s, inside the run (the job ends at t = " + format4(job_end) + " s)");
    else if (k > 0 && !(tk > out.profile_times[k - 1]))
      add(where, "is " + format4(tk) + " s, not after the time before it (" +
                     format4(out.profile_times[k - 1]) + " s): list the times in increasing order");
  }
  check_consolidation(problem, issues);
  const bool adds = std::any_of(problem.stages.begin(), problem.stages.end(),
                                [](const Stage& st) { return !st.add_bodies.empty(); });
  for (ProblemIssue& issue : check_geostatic(adds ? initial_ground(problem) : problem))
    issues.push_back(std::move(issue));
  check_stages(problem, issues);
  if (const auto& sr = problem.strength_reduction) {
    const Problem last = stage_problem(problem, stage_count(problem) - 1);
    if (last.time.scheme != Scheme::quasi_static)
      add({"strength_reduction"},
          std::string("needs the quasi-static scheme in the last stage (its Newton iterations "
                      "find the equilibrium at each reduced strength); the last stage runs '") +
              scheme_name(last.time.scheme) +
              "': set its time.scheme to 'quasi_static' (a gravity stage in any scheme may "
              "come before it)");
    if (!std::any_of(last.materials.begin(), last.materials.end(), [](const Material& m) {
          return std::holds_alternative<MohrCoulomb>(m.plasticity) ||
                 std::holds_alternative<DruckerPrager>(m.plasticity);
        }))
      add({"strength_reduction"},
          "needs a material with a strength (mohr_coulomb or drucker_prager): elastic soil "
          "never fails");
    if (!(sr->increment > 0)) add({"strength_reduction", "increment"}, "must be > 0");
    if (!(sr->resolution > 0)) add({"strength_reduction", "resolution"}, "must be > 0");
    if (!(sr->max_factor > 1)) add({"strength_reduction", "max_factor"}, "must be > 1");
  }
  return issues;
}

}  // namespace hmpm
