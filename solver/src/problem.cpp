// problem.cpp — everything about a Problem that is not the time loop:
// particle generation and numbering, the stable time step (the scheme's
// rule, schemes/), and the checks that decide whether a Problem can run at
// all.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "geometry/polygon.hpp"
#include "geostatic.hpp"
#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"
#include "plausibility.hpp"
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

namespace {

using geometry::Point2;

/// Cell size along axis a.
double cell_size(const Problem& problem, int a) {
  return (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a];
}

/// Volume of one cell (area in 2D, length in 1D).
double cell_volume(const Problem& problem) {
  double v = 1.0;
  for (int a = 0; a < problem.dimension; ++a) v *= cell_size(problem, a);
  return v;
}

/// Tolerance of "on the boundary" for filling: far below any sub-cell spacing.
double fill_tolerance(const Problem& problem) {
  return 1e-9 * min_cell_size(problem);
}

/// The plane axes of a prism's polygon: the other two axes in order.
std::array<int, 2> plane_axes(int axis) {
  if (axis == 0) return {1, 2};
  if (axis == 1) return {0, 2};
  return {0, 1};
}

/// Whether x lies in a polygon or prism body's shape (or on its boundary).
bool in_polygon_shape(const Body& body, const Vec3& x, double tol) {
  if (body.polygon) return geometry::inside_or_on(body.polygon->vertices, {x[0], x[1]}, tol);
  const Prism& prism = *body.prism;
  if (x[prism.axis] < prism.from - tol || x[prism.axis] > prism.to + tol) return false;
  const auto [u, v] = plane_axes(prism.axis);
  return geometry::inside_or_on(prism.polygon.vertices, {x[u], x[v]}, tol);
}

/// The bounding box of a polygon or prism body's shape (a box body: its box).
Box shape_box(const Body& body) {
  Box out = body.box;
  if (!body.polygon && !body.prism) return out;
  const std::vector<Point2>& poly =
      body.polygon ? body.polygon->vertices : body.prism->polygon.vertices;
  if (poly.empty()) return out;
  const auto [lo, hi] = geometry::bounds(poly);
  const std::array<int, 2> uv =
      body.polygon ? std::array<int, 2>{0, 1} : plane_axes(body.prism->axis);
  for (int k = 0; k < 2; ++k) {
    out.min[uv[k]] = lo[k];
    out.max[uv[k]] = hi[k];
  }
  if (body.prism) {
    out.min[body.prism->axis] = body.prism->from;
    out.max[body.prism->axis] = body.prism->to;
  }
  return out;
}

bool in_box(const Box& box, const Vec3& x, int dim, double tol) {
  for (int a = 0; a < dim; ++a)
    if (x[a] < box.min[a] - tol || x[a] > box.max[a] + tol) return false;
  return true;
}

/// Per axis, the sub-cell centres a lattice body may fill: of the whole
/// cells inside a box, or of every cell meeting a polygon's or prism's
/// bounding box.
std::array<std::vector<double>, 3> lattice_coords(const Problem& problem, const Body& body) {
  const int ppc = std::max(body.particles_per_cell, 1);
  const Box range = shape_box(body);
  const bool whole_cells = !body.polygon && !body.prism;
  std::array<std::vector<double>, 3> coords;
  for (int a = 0; a < 3; ++a) {
    if (a >= problem.dimension) {
      coords[a].push_back(0.0);
      continue;
    }
    const double h = cell_size(problem, a);
    const double tol = 1e-9 * h;
    for (int c = 0; c < problem.grid.cells[a]; ++c) {
      const double lo = problem.grid.min[a] + c * h;
      const double hi = lo + h;
      if (whole_cells && (lo < range.min[a] - tol || hi > range.max[a] + tol)) continue;
      if (!whole_cells && (hi < range.min[a] - tol || lo > range.max[a] + tol)) continue;
      for (int k = 0; k < ppc; ++k) {
        const double x = lo + (k + 0.5) * h / ppc;
        if (whole_cells || (x >= range.min[a] - tol && x <= range.max[a] + tol))
          coords[a].push_back(x);
      }
    }
  }
  return coords;
}

/// Whether an earlier box, polygon or prism body (its layout `earlier`,
/// its shape's bounding box `bounds`) owns position x: a box owns the whole
/// cells it fills, a polygon or prism its shape.
bool claims(const Problem& problem, const Body& body, const BodyLayout& earlier, const Box& bounds,
            const Vec3& x, double tol) {
  if (earlier.count == 0) return false;
  if (body.polygon || body.prism)
    return in_box(bounds, x, problem.dimension, tol) && in_polygon_shape(body, x, tol);
  const Box filled{earlier.lo, earlier.hi};
  return in_box(filled, x, problem.dimension, tol);
}

/// Whether two positions coincide (within tol per axis).
bool same_place(const Vec3& a, const Vec3& b, double tol) {
  return std::abs(a[0] - b[0]) <= tol && std::abs(a[1] - b[1]) <= tol &&
         std::abs(a[2] - b[2]) <= tol;
}

}  // namespace

std::vector<BodyLayout> body_layouts(const Problem& problem, LayoutDetail detail) {
  const bool store_all = detail == LayoutDetail::positions;
  std::vector<BodyLayout> layouts(problem.bodies.size());
  const double tol = fill_tolerance(problem);
  const int dim = problem.dimension;
  // Every points body's positions sorted by x, to find coincident ones.
  std::vector<std::vector<Vec3>> sorted_points(problem.bodies.size());
  std::vector<Box> bounds;
  for (const Body& body : problem.bodies) bounds.push_back(shape_box(body));
  const double cell_v = cell_volume(problem);
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    BodyLayout& layout = layouts[b];
    // A points body's positions are always kept: later bodies test against them.
    const bool store = store_all || body.points;
    for (int a = 0; a < dim; ++a) {
      layout.lo[a] = std::numeric_limits<double>::infinity();
      layout.hi[a] = -std::numeric_limits<double>::infinity();
    }
    // The space filled: each particle's own cell (sub-cell, or the cube of
    // its volume for a points body).
    Vec3 half{0, 0, 0};
    for (int a = 0; a < dim; ++a)
      half[a] = 0.5 * cell_size(problem, a) / std::max(body.particles_per_cell, 1);
    std::vector<std::int64_t> lost(b, 0);
    auto keep = [&](const Vec3& x, double volume) {
      for (std::size_t e = 0; e < b; ++e) {
        bool owned = false;
        if (problem.bodies[e].points) {
          const std::vector<Vec3>& pts = sorted_points[e];
          auto it = std::lower_bound(pts.begin(), pts.end(), x[0] - tol,
                                     [](const Vec3& p, double v) { return p[0] < v; });
          for (; it != pts.end() && (*it)[0] <= x[0] + tol && !owned; ++it)
            owned = same_place(*it, x, tol);
        } else {
          owned = claims(problem, problem.bodies[e], layouts[e], bounds[e], x, tol);
        }
        if (owned) {
          ++lost[e];
          return;
        }
      }
      ++layout.count;
      if (body.points) half.fill(0.5 * std::pow(std::max(volume, 0.0), 1.0 / dim));
      for (int a = 0; a < dim; ++a) {
        layout.lo[a] = std::min(layout.lo[a], x[a] - half[a]);
        layout.hi[a] = std::max(layout.hi[a], x[a] + half[a]);
      }
      if (!store) return;
      layout.positions.push_back(x);
      layout.volumes.push_back(volume);
    };
    if (body.points) {
      const ParticleList& pl = *body.points;
      layout.positions.reserve(pl.positions.size());
      layout.volumes.reserve(pl.positions.size());
      for (std::size_t k = 0; k < pl.positions.size(); ++k)
        keep(pl.positions[k], k < pl.volumes.size() ? pl.volumes[k] : 0.0);
    } else {
      const std::array<std::vector<double>, 3> coords = lattice_coords(problem, body);
      const bool shaped = body.polygon || body.prism;
      const double v0 = cell_v / std::pow(std::max(body.particles_per_cell, 1), dim);
      if (store) {
        const std::size_t most = coords[0].size() * coords[1].size() * coords[2].size();
        layout.positions.reserve(most);
        layout.volumes.reserve(most);
      }
      for (double z : coords[2])
        for (double y : coords[1])
          for (double x : coords[0]) {
            const Vec3 x3{x, y, z};
            if (!shaped || in_polygon_shape(body, x3, tol)) keep(x3, v0);
          }
    }
    for (std::size_t e = 0; e < b; ++e)
      if (lost[e] > 0) layout.lost.emplace_back(e, lost[e]);
    if (body.points) {
      sorted_points[b] = layout.positions;
      std::sort(sorted_points[b].begin(), sorted_points[b].end(),
                [](const Vec3& p, const Vec3& q) { return p[0] < q[0]; });
      if (!store_all) {
        layout.positions = {};
        layout.volumes = {};
      }
    }
  }
  return layouts;
}

std::int64_t count_particles(const Problem& problem) {
  std::int64_t n = 0;
  for (const BodyLayout& l : body_layouts(problem, LayoutDetail::counts)) n += l.count;
  return n;
}

bool node_selected(const Problem& problem, const NodeSelection& nodes, const Vec3& x) {
  if (nodes.all) return true;
  if (nodes.polygon)
    return geometry::inside_or_on(nodes.polygon->vertices, {x[0], x[1]},
                                  1e-6 * min_cell_size(problem));
  for (int a = 0; a < problem.dimension; ++a) {
    const double tol = 1e-9 * cell_size(problem, a);
    if (x[a] < nodes.box.min[a] - tol || x[a] > nodes.box.max[a] + tol) return false;
  }
  return true;
}

namespace {
// A particle selection: a closed box of initial positions, or a polygon.
bool in_selection(const Problem& problem, const Box& box, const std::optional<Polygon>& polygon,
                  const Vec3& x) {
  if (polygon)
    return geometry::inside_or_on(polygon->vertices, {x[0], x[1]}, 1e-6 * min_cell_size(problem));
  for (int a = 0; a < problem.dimension; ++a)
    if (x[a] < box.min[a] - 1e-12 || x[a] > box.max[a] + 1e-12) return false;
  return true;
}
}  // namespace

bool particle_selected(const Problem& problem, const Traction& traction, const Vec3& x) {
  return in_selection(problem, traction.particles, traction.polygon, x);
}

bool particle_selected(const Problem& problem, const Flux& flux, const Vec3& x) {
  return in_selection(problem, flux.particles, flux.polygon, x);
}

bool particle_selected(const Problem& problem, const ConsolidationRequest& c, const Vec3& x) {
  return c.all || in_selection(problem, c.particles, c.polygon, x);
}

std::vector<Vec3> initial_positions(const Problem& problem) {
  std::vector<Vec3> out;
  for (const BodyLayout& l : body_layouts(problem))
    out.insert(out.end(), l.positions.begin(), l.positions.end());
  return out;
}

std::int64_t nearest_particle(const Problem& problem, const Vec3& x) {
  std::int64_t best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::int64_t index = 0;
  for (const Vec3& p : initial_positions(problem)) {
    const double d2 = (p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]) +
                      (p[2] - x[2]) * (p[2] - x[2]);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = index;
    }
    ++index;
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

Problem stage_problem(const Problem& problem, std::size_t k) {
  Problem out = problem;
  out.stages.clear();
  for (std::size_t i = 1; i <= k && i <= problem.stages.size(); ++i) {
    const Stage& s = problem.stages[i - 1];
    const double previous_end = out.time.end;
    if (s.boundaries) out.boundaries = *s.boundaries;
    if (s.tractions) out.tractions = *s.tractions;
    if (s.fluxes) out.fluxes = *s.fluxes;
    if (s.gravity) out.gravity = *s.gravity;
    if (s.time) out.time = *s.time;
    if (s.local_damping) out.local_damping = *s.local_damping;
    out.time.start = previous_end;
    out.time.end = s.end;
  }
  return out;
}

std::vector<bool> stage_bodies(const Problem& problem, std::size_t k) {
  std::vector<bool> in(problem.bodies.size(), true);
  auto set = [&](const std::vector<int>& bodies, bool value) {
    for (int b : bodies)
      if (b >= 0 && static_cast<std::size_t>(b) < in.size())
        in[static_cast<std::size_t>(b)] = value;
  };
  for (const Stage& s : problem.stages) set(s.add_bodies, false);
  for (std::size_t i = 1; i <= k && i <= problem.stages.size(); ++i) {
    set(problem.stages[i - 1].add_bodies, true);
    set(problem.stages[i - 1].remove_bodies, false);
  }
  return in;
}

Problem initial_ground(const Problem& problem) {
  const std::vector<bool> in = stage_bodies(problem, 0);
  Problem out = problem;
  out.bodies.clear();
  for (std::size_t b = 0; b < problem.bodies.size(); ++b)
    if (in[b]) out.bodies.push_back(problem.bodies[b]);
  return out;
}

StableStep stable_step(const Problem& problem) {
  return scheme_rules(problem).stable_step(problem);
}

// ---------------------------------------------------------------- checks

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

// Fluxes and seepage faces: they act on the pore water, so they need a
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

/// The ways out of the Darcy-inertia growth regime that exist for this
/// material (E_oed Q rho_f/(rho - rho_f) <= 0.9): a stiffer fluid only when
/// one no stiffer than water gets there, else a softer skeleton.
std::string darcy_growth_advice(const Material& m, const MaterialConstants& c) {
  constexpr double water_bulk_modulus = 2.2e9;  // Pa, at 20 degrees C
  const Hydraulic& h = *m.hydraulic;
  const double buoyant = c.mixture_density - c.fluid_density;
  // The storage Q at which the ratio is 0.9, and the fluid modulus giving it.
  const double q_target = 0.9 * buoyant / (c.fluid_density * c.constrained_modulus);
  const double solid_term =
      std::isinf(h.solid_bulk_modulus) ? 0.0 : (1 - h.porosity) / h.solid_bulk_modulus;
  std::string out;
  if (q_target > solid_term) {
    const double kf = h.porosity / (q_target - solid_term);
    if (kf <= water_bulk_modulus)
      out = "a stiffer fluid_bulk_modulus (at least " + format_lower_bound(kf) +
            " Pa; water's is 2.2e9), ";
  }
  // The Young's modulus at which E_oed Q gives 0.9 with the fluid as given.
  const double nu = m.poisson_ratio;
  const double e_target =
      0.9 * buoyant / (c.fluid_density * c.storage) * (1 + nu) * (1 - 2 * nu) / (1 - nu);
  if (out.empty())
    out =
        "no fluid_bulk_modulus up to water's 2.2e9 Pa removes it (the skeleton is stiffer "
        "than the fluid's storage allows); a softer skeleton (youngs_modulus at most " +
        format_upper_bound(e_target) + " Pa, if " + format4(m.youngs_modulus) +
        " Pa is a unit slip), ";
  return out + "local_damping for quasi-static runs, or darcy_inertia: false (drops the term)";
}

}  // namespace

namespace {

/// A boundary on a face of the grid whose velocity (prescribed, or the
/// input motion of an absorbing base) carries the soil towards the grid's
/// edge further than the room there: a shaken base moves the whole layer
/// along the shaking, and particles that leave the grid stop the run. The
/// displacement is the velocity's integral over the job's time (2000
/// trapezoids); the room is the gap between the bodies' particles and the
/// grid's edges along that axis. Sideways: the smaller gap of the two
/// sides; along the face normal: the gap behind the face, when the motion
/// moves away from the soil.
void check_room_for_motion(const Problem& problem, const std::vector<BodyLayout>& layouts,
                           std::vector<ProblemIssue>& warnings) {
  const int dim = problem.dimension;
  const double end = job_end_time(problem);
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& b = problem.boundaries[i];
    if (b.nodes.all || b.nodes.polygon) continue;
    // The grid face the nodes lie on: its normal axis and side (-1: min).
    int normal = -1, side = 0;
    for (int a = 0; a < dim; ++a) {
      if (b.nodes.box.min[a] != b.nodes.box.max[a]) continue;
      if (b.nodes.box.min[a] <= problem.grid.min[a] || b.nodes.box.max[a] >= problem.grid.max[a]) {
        normal = a;
        side = b.nodes.box.min[a] <= problem.grid.min[a] ? -1 : 1;
      }
    }
    if (normal < 0) continue;
    for (int a = 0; a < dim; ++a) {
      if (!b.velocity[a]) continue;
      constexpr int samples = 2000;
      double u = 0.0, lowest = 0.0, highest = 0.0, v_prev = (*b.velocity[a])(0.0);
      for (int k = 1; k <= samples; ++k) {
        const double v = (*b.velocity[a])(end * k / samples);
        u += 0.5 * (v + v_prev) * end / samples;
        v_prev = v;
        lowest = std::min(lowest, u);
        highest = std::max(highest, u);
      }
      if (!std::isfinite(lowest) || !std::isfinite(highest)) continue;
      // Room along a: between the particles (half a spacing inside the
      // filled extent) and the grid's edges.
      double below = std::numeric_limits<double>::infinity(), above = below;
      const double h = cell_size(problem, a);
      for (std::size_t k = 0; k < layouts.size(); ++k) {
        if (layouts[k].count == 0) continue;
        const double half = 0.5 * h / problem.bodies[k].particles_per_cell;
        below = std::min(below, layouts[k].lo[a] + half - problem.grid.min[a]);
        above = std::min(above, problem.grid.max[a] - layouts[k].hi[a] + half);
      }
      double reach = 0.0, room = 0.0;
      std::string where;
      if (a != normal) {
        reach = std::max(-lowest, highest);
        room = std::min(below, above);
        where = "sideways";
      } else {
        reach = side < 0 ? -lowest : highest;
        room = side < 0 ? below : above;
        where = "out of the grid across its face";
      }
      if (!(reach > room)) continue;
      const std::string axis(1, static_cast<char>('x' + a));
      warnings.push_back(
          {Location{"boundaries"} / i / (b.from_acceleration[a] ? "acceleration" : "velocity") /
               static_cast<std::size_t>(a),
           "moves its nodes, and the soil with them, up to " + format4(reach) + " m along " + axis +
               " " + where + " over the run (the integral of the velocity), more than the " +
               format4(room) +
               " m between the outermost particles and the grid's edge: "
               "particles will leave the grid and the run will stop there. What to change: "
               "extend the grid along " +
               axis + " by at least " + format4(reach - room) +
               " m beyond the soil (the added cells stay empty), or check the motion's "
               "baseline (a velocity that does not return to zero drifts)"});
    }
  }
}

/// Linear shape functions in a dynamic run whose loads move the loaded face
/// by more than a quarter cell: particles then cross cell boundaries, where
/// linear gradients jump, and the stresses ring (measured on the column-wave
/// problem of verification §5 at its 2 kPa load, particles moving 1-2
/// cells: 18-24 % RMS of the load with linear, 3.5-4 % with GIMP or
/// B-spline). The estimate: the largest traction over the run times the
/// bodies' extent along its normal over the smallest constrained modulus
/// (the static compression of the loaded soil).
void check_cell_crossing(const Problem& problem, const std::vector<BodyLayout>& layouts,
                         std::vector<ProblemIssue>& warnings) {
  if (problem.shape_function != ShapeFunction::linear ||
      problem.time.scheme == Scheme::quasi_static)
    return;
  double modulus = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < layouts.size(); ++b) {
    const int m = problem.bodies[b].material;
    if (layouts[b].count == 0 || m < 0 || static_cast<std::size_t>(m) >= problem.materials.size())
      continue;
    modulus = std::min(modulus, material_constants(problem.materials[static_cast<std::size_t>(m)],
                                                   problem.gravity_constant)
                                    .constrained_modulus);
  }
  if (!std::isfinite(modulus)) return;
  for (std::size_t i = 0; i < problem.tractions.size(); ++i) {
    const Traction& tr = problem.tractions[i];
    const int a = tr.axis;
    if (a < 0 || a >= problem.dimension) continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const BodyLayout& l : layouts)
      if (l.count > 0) {
        lo = std::min(lo, l.lo[a]);
        hi = std::max(hi, l.hi[a]);
      }
    double peak = 0.0;
    constexpr int samples = 200;
    const double end = job_end_time(problem);
    for (int k = 0; k <= samples; ++k) {
      const double t = end * k / samples;
      for (int c = 0; c < problem.dimension; ++c)
        if (tr.traction[c]) peak = std::max(peak, std::abs(tr.traction[c](t)));
    }
    const double move = peak * (hi - lo) / modulus;
    const double h = cell_size(problem, a);
    if (!(move > 0.25 * h)) continue;
    warnings.push_back(
        {Location{"tractions"} / i,
         "moves the loaded soil by about " + format4(move) + " m (the load " + format4(peak) +
             " Pa times the soil's extent " + format4(hi - lo) +
             " m over its constrained modulus " + format4(modulus) +
             " Pa), more than a quarter of the cell size " + format4(h) +
             " m: particles will cross cell boundaries, where linear shape functions' gradients "
             "jump, and the stresses ring (18-24 % of the load in the column-wave test, 3.5-4 % "
             "with the others). What to change: \"shape_function\": \"gimp\" or \"bspline\" "
             "(a finer grid makes the crossings more frequent, not fewer)"});
  }
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
            ? "the grains are not denser than the fluid (density " + format4(m.density) +
                  " kg/m3, fluid " + format4(c.fluid_density) +
                  "), so the u-p equations with the rho_f a term of Darcy's law have growing "
                  "solutions for any stiffness: oscillations can grow and the run can diverge. "
                  "What to change: check density (the grain density, not the mixture's), or "
                  "set darcy_inertia: false (drops the term)"
            : "constrained modulus x storage (E_oed Q = " +
                  format4(c.constrained_modulus * c.storage) + ") is " + format4(growth) +
                  " times (rho - rho_f)/rho_f, above which the u-p equations with the rho_f a "
                  "term of Darcy's law have growing solutions (near it, waves hardly decay): "
                  "oscillations can grow and the run can diverge. What to change: " +
                  darcy_growth_advice(m, c);
    warnings.push_back({Location{"materials", m.name, "hydraulic"}, what});
  }
  const std::vector<BodyLayout> layouts = body_layouts(problem, LayoutDetail::counts);
  for (std::size_t b = 0; b < layouts.size(); ++b)
    for (const auto& [earlier, n] : layouts[b].lost)
      warnings.push_back(
          {Location{"bodies"} / b,
           "overlaps body " + std::to_string(earlier) + ": " + std::to_string(n) +
               " of its particle positions lie inside body " + std::to_string(earlier) +
               ", which is listed first, so they belong to body " + std::to_string(earlier) +
               " (a place inside several bodies gets one particle, of the first). What to "
               "change: nothing if intended; else shrink body " +
               std::to_string(b) + " (or body " + std::to_string(earlier) +
               ") so that they do not overlap, or list body " + std::to_string(b) +
               " first if the shared place should be its (body " + std::to_string(earlier) +
               " then loses it)"});
  check_room_for_motion(problem, layouts, warnings);
  check_cell_crossing(problem, layouts, warnings);
  for (ProblemIssue& w : material_plausibility(problem)) warnings.push_back(std::move(w));
  for (ProblemIssue& w : stability_plausibility(problem)) warnings.push_back(std::move(w));
  for (ProblemIssue& w : geostatic_warnings(problem)) warnings.push_back(std::move(w));
  return warnings;
}

namespace {

/// The stages of a staged job: ends in order, body indices that exist and
/// are in the run when removed (absent when added), and every stage's own
/// Problem runnable: its issues, where the top level does not have them
/// already, at the stage (a list it sets at its own path; one in force
/// from before at the stage, naming it).
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
  if (issues.size() > before_shapes) return issues;
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
  check_absorbing_boundaries(problem, issues);
  check_hydraulic_boundaries(problem, issues);
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
  if (!out.profiles.empty() && !(out.profile_interval > 0))
    add({"output", "profiles", "interval"}, "must be > 0");
  check_consolidation(problem, issues);
  const bool adds = std::any_of(problem.stages.begin(), problem.stages.end(),
                                [](const Stage& st) { return !st.add_bodies.empty(); });
  for (ProblemIssue& issue : check_geostatic(adds ? initial_ground(problem) : problem))
    issues.push_back(std::move(issue));
  check_stages(problem, issues);
  return issues;
}

}  // namespace hmpm
