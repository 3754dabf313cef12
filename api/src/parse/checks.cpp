// checks.cpp — the checks that need the whole Problem, run once every
// section has been read without error: the particle budget (before anything
// allocates per particle), "near" selections, the solver's check_problem,
// traction selections, formulas finite where they are evaluated, and the
// limits of a shared server from the cost estimate.
#include <algorithm>
#include <cmath>
#include <limits>

#include "cost_model.hpp"
#include "hmpm/format.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

// Work bound for laying out bodies (bodies x cells summed over the axes).
constexpr double max_layout_work = 5e7;
// Work bound for checks that visit every particle per selection.
constexpr double max_near_work = 2e8;
// Work bound for the finiteness checks of formulas, in characters evaluated
// (one evaluation of a formula costs about its length plus a fixed part:
// ~1.2 ns per character with muParser's bytecode on the development
// machine, so the bound is ~60 ms per kind of formula): about a million
// evaluations of short formulas, fewer of long ones. Without the weight a
// spec of long formulas cost ~5 s of CPU to validate.
constexpr double formula_work = 5e7;
constexpr double formula_overhead_characters = 32;

double evaluation_cost(std::size_t length) {
  return static_cast<double>(length) + formula_overhead_characters;
}

// Work bound for filling polygons and prisms: candidate positions x the
// polygon's vertices (each laying out tests every candidate against every
// edge; validation lays the bodies out a few times).
constexpr double max_polygon_work = 2e8;

/// The box a body's particles lie in: its box, or the bounding box of its
/// polygon or prism (points bodies: unused).
Box shape_bounds(const Body& body) {
  Box out = body.box;
  const std::vector<std::array<double, 2>>* vertices = nullptr;
  std::array<int, 2> plane{0, 1};
  if (body.polygon) vertices = &body.polygon->vertices;
  if (body.prism) {
    vertices = &body.prism->polygon.vertices;
    const int axis = body.prism->axis;
    plane = axis == 0 ? std::array<int, 2>{1, 2}
                      : (axis == 1 ? std::array<int, 2>{0, 2} : std::array<int, 2>{0, 1});
    out.min[axis] = body.prism->from;
    out.max[axis] = body.prism->to;
  }
  if (!vertices || vertices->empty()) return out;
  for (int k = 0; k < 2; ++k) {
    out.min[plane[k]] = out.max[plane[k]] = vertices->front()[k];
    for (const auto& v : *vertices) {
      out.min[plane[k]] = std::min(out.min[plane[k]], v[k]);
      out.max[plane[k]] = std::max(out.max[plane[k]], v[k]);
    }
  }
  return out;
}

bool check_particle_budget(ParseContext& c) {
  // Count particles from the layout rule without generating them, so a huge
  // body is refused before anything allocates per particle.
  // Laying out a body walks every cell along each axis; many bodies on a
  // fine grid would make validation itself slow.
  const Problem& p = c.p;
  double axis_cells = 0;
  for (int a = 0; a < c.dim; ++a) axis_cells += p.grid.cells[a];
  const double layout_work = axis_cells * static_cast<double>(p.bodies.size());
  if (layout_work > max_layout_work) {
    c.r.error("/bodies", std::to_string(p.bodies.size()) + " bodies on a grid of " +
                             format_count(axis_cells) +
                             " cells summed over the axes is too much work to lay out (" +
                             format_count(layout_work) + " > " + format_count(max_layout_work) +
                             "); merge bodies");
    return false;
  }
  double total = 0;
  for (std::size_t b = 0; b < p.bodies.size(); ++b) {
    const Body& body = p.bodies[b];
    if (body.points) {
      total += static_cast<double>(body.points->positions.size());
      continue;
    }
    const Box range = shape_bounds(body);
    const bool shaped = body.polygon || body.prism;
    double n = 1;
    for (int a = 0; a < c.dim; ++a) {
      // A polygon or prism fills at most the sub-cells of the cells meeting
      // its bounding box.
      const double cells =
          shaped ? static_cast<double>(nodes_inside(p.grid, a, range.min[a], range.max[a]) + 1)
                 : static_cast<double>(cells_inside(p.grid, a, range.min[a], range.max[a]));
      const double along = cells * body.particles_per_cell;
      if (along > static_cast<double>(c.limits.max_particles)) {
        c.r.error(child_pointer("/bodies", b) + "/particles_per_cell",
                  "body would have " + format_count(along) + " particles along " +
                      std::string(axis_names[a]) + "; the limit is " +
                      std::to_string(c.limits.max_particles) + " particles in all");
        return false;
      }
      n *= along;
    }
    if (shaped) {
      const std::size_t vertices =
          body.polygon ? body.polygon->vertices.size() : body.prism->polygon.vertices.size();
      if (n * static_cast<double>(vertices) > max_polygon_work) {
        c.r.error(child_pointer("/bodies", b) + (body.polygon ? "/polygon" : "/prism/polygon"),
                  "filling it tests " + format_count(n) + " sub-cell centres against " +
                      std::to_string(vertices) + " edges, too much work (" +
                      format_count(n * static_cast<double>(vertices)) + " > " +
                      format_count(max_polygon_work) +
                      "); use fewer vertices, fewer particles per cell or a coarser grid");
        return false;
      }
    }
    total += n;
  }
  if (total > static_cast<double>(c.limits.max_particles)) {
    c.r.error("/bodies", "the bodies would create " + format_count(total) +
                             " particles; the limit is " + std::to_string(c.limits.max_particles));
    return false;
  }
  return true;
}

void resolve_near(ParseContext& c) {
  if (c.near.empty()) return;
  const std::int64_t n = count_particles(c.p);
  if (static_cast<double>(c.near.size()) * static_cast<double>(n) > max_near_work) {
    c.r.error("/output/series/particles",
              std::to_string(c.near.size()) + " 'near' selections over " + std::to_string(n) +
                  " particles is too much work to resolve; name particles by index instead");
    return;
  }
  for (const PendingNear& s : c.near) {
    const std::int64_t i = nearest_particle(c.p, s.at);
    if (i < 0)
      c.r.error(s.path, "no particle exists");
    else
      c.p.output.series_particles[s.slot] = i;
  }
}

/// The particle nearest to each point of each output.profiles line (by
/// initial position). A point farther than a cell diagonal from every
/// particle lies outside the bodies: an error naming it, so that a profile
/// never reports a particle from somewhere else.
void resolve_profiles(ParseContext& c) {
  if (c.profiles.empty()) return;
  std::size_t points = 0;
  for (const ProfileGeometry& g : c.profiles) points += g.points.size();
  const std::vector<Vec3> x0 = initial_positions(c.p);
  if (static_cast<double>(points) * static_cast<double>(x0.size()) > max_near_work) {
    c.r.error("/output/profiles/lines", std::to_string(points) + " profile points over " +
                                            std::to_string(x0.size()) +
                                            " particles is too much work; use fewer points");
    return;
  }
  double diagonal2 = 0;
  for (int a = 0; a < c.dim; ++a) {
    const double h = (c.p.grid.max[a] - c.p.grid.min[a]) / c.p.grid.cells[a];
    diagonal2 += h * h;
  }
  for (std::size_t l = 0; l < c.profiles.size(); ++l) {
    std::vector<std::int64_t>& parts = c.p.output.profiles[l].particles;
    parts.clear();
    for (std::size_t k = 0; k < c.profiles[l].points.size(); ++k) {
      const Vec3& at = c.profiles[l].points[k];
      double best = std::numeric_limits<double>::infinity();
      std::int64_t nearest = -1;
      for (std::size_t p = 0; p < x0.size(); ++p) {
        double d2 = 0;
        for (int a = 0; a < c.dim; ++a) d2 += (x0[p][a] - at[a]) * (x0[p][a] - at[a]);
        if (d2 < best) {
          best = d2;
          nearest = static_cast<std::int64_t>(p);
        }
      }
      if (nearest < 0 || best > diagonal2) {
        std::string where;
        for (int a = 0; a < c.dim; ++a) {
          if (a) where += ", ";
          where += format_significant(at[a], 6);
        }
        c.r.error(child_pointer("/output/profiles/lines", l),
                  "point " + std::to_string(k) + " at (" + where +
                      ") is more than a cell from every particle: keep the line inside the "
                      "bodies");
        break;
      }
      parts.push_back(nearest);
    }
  }
}

/// Replaces each {"polygon": ...} entry of output.series.particles by the
/// particles inside or on the polygon (as a traction selects them).
void resolve_series_polygons(ParseContext& c) {
  if (c.series_polygons.empty()) return;
  for (const PendingPolygon& pp : c.series_polygons) {
    std::vector<ProblemIssue> issues;
    check_polygon(pp.polygon, Location{}, issues);
    for (const ProblemIssue& issue : issues)
      c.r.error(pp.path + "/polygon" + pointer_of_solver_location(issue.where), issue.message);
  }
  if (c.r.error_count() > 0) return;
  std::vector<std::int64_t>& parts = c.p.output.series_particles;
  const std::vector<Vec3> positions = initial_positions(c.p);
  if (static_cast<double>(c.series_polygons.size()) * static_cast<double>(positions.size()) >
      max_near_work) {
    c.r.error("/output/series/particles", "too many 'polygon' selections over " +
                                              std::to_string(positions.size()) +
                                              " particles to resolve; name particles by index");
    return;
  }
  std::vector<std::int64_t> out;
  std::size_t next = 0;
  for (std::size_t slot = 0; slot < parts.size(); ++slot) {
    if (next < c.series_polygons.size() && c.series_polygons[next].slot == slot) {
      const PendingPolygon& pp = c.series_polygons[next++];
      Traction as_selection;
      as_selection.polygon = pp.polygon;
      const std::size_t before = out.size();
      for (std::size_t i = 0; i < positions.size(); ++i)
        if (particle_selected(c.p, as_selection, positions[i]))
          out.push_back(static_cast<std::int64_t>(i));
      if (out.size() == before) c.r.error(pp.path + "/polygon", "selects no particle");
      continue;
    }
    out.push_back(parts[slot]);
  }
  if (out.size() > static_cast<std::size_t>(c.limits.max_series_particles)) {
    c.r.error("/output/series/particles", "selects " + std::to_string(out.size()) +
                                              " particles; the limit is " +
                                              std::to_string(c.limits.max_series_particles));
    return;
  }
  parts = std::move(out);
}

// Every traction or flux selects at least one particle. A convenience
// check, skipped when it would cost more than a moment.
template <class Load>
void check_face_selections(ParseContext& c, const std::vector<Load>& loads,
                           const std::vector<std::string>& paths) {
  const Problem& p = c.p;
  if (loads.empty() ||
      static_cast<double>(loads.size()) * static_cast<double>(count_particles(p)) > max_near_work)
    return;
  const std::vector<Vec3> positions = initial_positions(p);
  for (std::size_t k = 0; k < loads.size(); ++k) {
    const bool any = std::any_of(positions.begin(), positions.end(), [&](const Vec3& x) {
      return particle_selected(p, loads[k], x);  // as the solver selects
    });
    if (!any)
      c.r.error(paths[k],
                "selects no particle; particles sit at sub-cell centres, e.g. the "
                "top row of a body is half a particle spacing below its top face");
  }
}

void check_traction_selections(ParseContext& c) {
  check_face_selections(c, c.p.tractions, c.traction_paths);
  check_face_selections(c, c.p.fluxes, c.flux_paths);
  check_face_selections(c, c.p.surface_pressures, c.surface_pressure_paths);
}

void check_time_formulas(ParseContext& c) {
  // At up to 1001 instants over [0, end], within the formula work bound.
  double per_instant = 0;
  for (const TimeFormula& tf : c.time_formulas) per_instant += evaluation_cost(tf.length);
  const int intervals =
      static_cast<int>(std::clamp(formula_work / std::max(per_instant, 1.0), 1.0, 1000.0));
  for (const TimeFormula& tf : c.time_formulas) {
    for (int k = 0; k <= intervals; ++k) {
      const double t = c.p.time.end * k / intervals;
      const double v = tf.f(t);
      if (!std::isfinite(v)) {
        c.r.error(tf.path,
                  "the formula gives " + format_number(v) + " at t = " + format_number(t) + " s");
        break;
      }
      if (c.damping_formula && tf.path == "/local_damping" && !(v >= 0.0 && v < 1.0)) {
        c.r.error(tf.path, "the formula gives " + format_number(v) + " at t = " + format_number(t) +
                               " s; local damping must lie in [0, 1)");
        break;
      }
    }
  }
}

void check_position_formulas(ParseContext& c) {
  // At every particle of the body, or a regular sample within the formula
  // work bound when the bodies are large or the formulas long.
  if (c.position_formulas.empty()) return;
  const Problem& p = c.p;
  std::vector<std::vector<Vec3>> positions(p.bodies.size());
  double work = 0;
  for (const PositionFormula& pf : c.position_formulas) {
    if (pf.body >= p.bodies.size()) continue;
    if (positions[pf.body].empty()) {
      Problem one;
      one.dimension = p.dimension;
      one.grid = p.grid;
      Body b = p.bodies[pf.body];
      b.initial = InitialFields{};
      one.bodies.push_back(std::move(b));
      positions[pf.body] = initial_positions(one);
    }
    work += static_cast<double>(positions[pf.body].size()) * evaluation_cost(pf.length);
  }
  const std::size_t stride =
      static_cast<std::size_t>(std::max(1.0, std::ceil(work / formula_work)));
  for (const PositionFormula& pf : c.position_formulas) {
    if (pf.body >= p.bodies.size()) continue;
    const std::vector<Vec3>& xs = positions[pf.body];
    for (std::size_t i = 0; i < xs.size(); i += stride) {
      const double v = pf.f(xs[i]);
      if (!std::isfinite(v)) {
        std::string at = "x = " + format_number(xs[i][0]);
        if (c.dim > 1) at += ", y = " + format_number(xs[i][1]);
        if (c.dim > 2) at += ", z = " + format_number(xs[i][2]);
        c.r.error(pf.path, "the formula gives " + format_number(v) + " at a particle of body " +
                               std::to_string(pf.body) + " (" + at + ")");
        break;
      }
    }
  }
}

void check_limits(ParseContext& c) {
  const Problem& p = c.p;
  const Limits& limits = c.limits;
  c.cost = estimate_cost(p, c.calibration);
  const CostEstimate& cost = *c.cost;
  const StableStep s = stable_step(p);
  const double steps = static_cast<double>(s.steps);
  if (steps > static_cast<double>(limits.max_steps)) {
    std::string why = "end " + format_number(p.time.end) + " s / ";
    why += p.time.dt ? "dt " : (s.fixed ? "automatic dt " : "first dt ");
    why += format_number(s.chosen) + " s with scheme '" + scheme_name(p.time.scheme) + "'";
    std::string message = "the run needs " + format_count(steps) + " time steps (" + why +
                          "); the limit is " + std::to_string(limits.max_steps);
    const std::string advice = cost::scheme_advice(p, limits.max_steps, cost.calibration);
    if (advice.empty())
      message += "; shorten time.end or use a coarser grid";
    else
      message += "; " + advice;
    c.r.error(p.time.dt || p.time.growth ? "/time/dt" : "/time/end", message);
  }
  if (cost.series_rows > limits.max_series_rows)
    c.r.error("/output/series/interval",
              "the series would have " + std::to_string(cost.series_rows) + " rows; the limit is " +
                  std::to_string(limits.max_series_rows) + "; use a larger interval");
  if (cost.reaction_rows > limits.max_series_rows)
    c.r.error("/output/reactions/interval",
              "the reactions would have " + std::to_string(cost.reaction_rows) +
                  " rows; the limit (that of the series) is " +
                  std::to_string(limits.max_series_rows) + "; use a larger interval");
  if (cost.snapshots > limits.max_snapshots)
    c.r.error("/output/snapshots/interval",
              "the run would write " + std::to_string(cost.snapshots) +
                  " snapshots; the limit is " + std::to_string(limits.max_snapshots) +
                  "; use a larger interval");
  if (cost.output_bytes > limits.max_output_bytes)
    c.r.error("/output", "the result files would take about " + std::to_string(cost.output_bytes) +
                             " bytes; the limit is " + std::to_string(limits.max_output_bytes));
}

}  // namespace

// The steady pore pressure of output.consolidation and of the output field
// excess_pore_pressure, when the spec gives none: the hydrostatic pressure
// under the geostatic water table when the job has one, else 0 (with a
// warning when gravity acts on the pore water and either is asked for by
// name; snapshots of every field take the default silently).
void resolve_consolidation(ParseContext& c) {
  ConsolidationRequest& out = c.p.output.consolidation;
  const bool consolidation = out.interval > 0;
  if (consolidation && !c.consolidation_hydrostatic) return;  // given
  const std::string path = consolidation ? "/output/consolidation" : c.excess_field_path;
  int axis = -1;
  for (int a = 0; a < 3; ++a)
    if (c.p.gravity[a] != 0) axis = a;
  std::optional<double> rho_f;
  bool mixed = false;
  for (const Material& m : c.p.materials)
    if (m.hydraulic) {
      if (rho_f && *rho_f != m.hydraulic->fluid_density) mixed = true;
      if (!rho_f) rho_f = m.hydraulic->fluid_density;
    }
  if (axis < 0 || !rho_f) return;  // no weight of water, or no water: the excess is p itself
  const auto& geo = c.p.initial_state.geostatic;
  if (!geo || !geo->water_table) {
    if (path.empty()) return;
    const std::string ax(axis_names[axis]);
    std::string advice =
        std::string(consolidation ? "has no steady_pore_pressure" : "has no reference") +
        ", so the excess pore pressure is measured from 0, but gravity acts on the pore water: "
        "the hydrostatic pressure would count as excess. Give " +
        (consolidation ? "" : "initial_state.geostatic.water_table, or output.consolidation.") +
        "steady_pore_pressure the pressure the ground drains to, e.g. \"";
    advice.append(format_number(*rho_f * std::abs(c.p.gravity[axis])))
        .append("*(WT - ")
        .append(ax)
        .append(")\" with WT the water table's ")
        .append(ax);
    c.warnings.push_back({path, advice});
    return;
  }
  if (mixed) {
    if (path.empty()) return;  // snapshots of every field: the excess measured from 0
    c.r.error(path,
              "needs steady_pore_pressure: its default, the hydrostatic pressure under "
              "the water table, is ambiguous when the materials' fluid densities differ");
    return;
  }
  const double gamma = *rho_f * std::abs(c.p.gravity[axis]);
  const double up = c.p.gravity[axis] < 0 ? 1.0 : -1.0;  // "above" is against gravity
  const double table = *geo->water_table;
  out.steady_pore_pressure = [gamma, up, table, axis](const Vec3& x) {
    return gamma * up * (table - x[static_cast<std::size_t>(axis)]);
  };
}

void check_whole_problem(ParseContext& c) {
  integrate_accelerations(c);
  if (!check_particle_budget(c)) return;
  resolve_near(c);
  resolve_series_polygons(c);
  resolve_profiles(c);
  resolve_consolidation(c);
  for (const ProblemIssue& issue : check_problem(c.p))
    c.r.error(pointer_of_solver_location(issue.where), issue.message);
  if (c.r.error_count() > 0) return;
  check_traction_selections(c);
  check_time_formulas(c);
  check_position_formulas(c);
  if (c.r.error_count() > 0) return;
  check_limits(c);
}

}  // namespace hmpm::api::parse
