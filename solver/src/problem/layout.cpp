// problem/layout.cpp — where the particles go: every body's layout and the
// contract's numbering (particle_layout.hpp), the selections of nodes and
// particles, and the cell sizes.
#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/polygon.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "particle_layout.hpp"

namespace hmpm {

double cell_size(const Problem& problem, int a) {
  return (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a];
}

double cell_volume(const Problem& problem) {
  double v = 1.0;
  for (int a = 0; a < problem.dimension; ++a) v *= cell_size(problem, a);
  return v;
}

double min_cell_size(const Problem& problem) {
  double h = std::numeric_limits<double>::infinity();
  for (int a = 0; a < problem.dimension; ++a)
    h = std::min(h, (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a]);
  return h;
}

namespace {

using geometry::Point2;

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

bool particle_selected(const Problem& problem, const SurfacePressure& s, const Vec3& x) {
  return in_selection(problem, s.particles, s.polygon, x);
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

}  // namespace hmpm
