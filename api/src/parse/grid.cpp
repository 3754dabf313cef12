// grid.cpp — the "grid" section (the background grid) and "shape_function".
#include <algorithm>
#include <cmath>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view grid_allowed[] = {"min", "max", "cells"};
constexpr std::string_view shape_names[] = {"linear", "gimp", "bspline"};

}  // namespace

void grid_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/grid", grid_allowed));
}

void read_grid(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, grid_allowed, grid_allowed)) return;
  const std::size_t before = r.error_count();
  std::optional<Vec3> lo, hi;
  if (j.contains("min")) lo = r.vector(j["min"], path + "/min", c.dim);
  if (j.contains("max")) hi = r.vector(j["max"], path + "/max", c.dim);
  if (j.contains("cells")) {
    const json& cells = j["cells"];
    const std::string cp = path + "/cells";
    if (r.per_axis(cells, cp, c.dim, "integer number of cells")) {
      double total = 1.0;
      for (std::size_t a = 0; a < cells.size() && a < 3; ++a) {
        if (auto n = r.integer(cells[a], child_pointer(cp, a), 1, c.limits.max_cells)) {
          c.p.grid.cells[a] = static_cast<int>(*n);
          total *= static_cast<double>(*n);
        }
      }
      if (total > static_cast<double>(c.limits.max_cells))
        r.error(cp, "grid has " + format_count(total) + " cells; the limit is " +
                        std::to_string(c.limits.max_cells));
    }
  }
  if (lo && hi) {
    c.p.grid.min = *lo;
    c.p.grid.max = *hi;
    for (int a = 0; a < c.dim; ++a)
      if (!(hi->at(a) > lo->at(a)))
        r.error(child_pointer(path + "/max", a), "is " + format_number(hi->at(a)) +
                                                     "; must be greater than grid min " +
                                                     format_number(lo->at(a)));
  }
  c.grid_ok = c.dim > 0 && r.error_count() == before;
}

Keys shape_function_names() {
  return shape_names;
}

void read_shape_function(ParseContext& c, const json& j, const std::string& path) {
  if (auto s = c.r.one_of(j, path, shape_names))
    c.p.shape_function = *s == "gimp"      ? ShapeFunction::gimp
                         : *s == "bspline" ? ShapeFunction::bspline
                                           : ShapeFunction::linear;
}

std::int64_t cells_inside(const Grid& grid, int axis, double lo, double hi) {
  const double h = (grid.max[axis] - grid.min[axis]) / grid.cells[axis];
  const double tol = 1e-9 * h;
  const double first = std::ceil((lo - tol - grid.min[axis]) / h);
  const double last =
      std::floor((hi + tol - grid.min[axis]) / h);  // exclusive upper cell edge index
  const double a = std::max(first, 0.0);
  const double b = std::min(last, static_cast<double>(grid.cells[axis]));
  return b > a ? static_cast<std::int64_t>(b - a) : 0;
}

std::int64_t nodes_inside(const Grid& grid, int axis, double lo, double hi) {
  const double h = (grid.max[axis] - grid.min[axis]) / grid.cells[axis];
  const double tol = 1e-9 * h;
  const double first = std::ceil((lo - tol - grid.min[axis]) / h);
  const double last = std::floor((hi + tol - grid.min[axis]) / h);
  const double a = std::max(first, 0.0);
  const double b = std::min(last, static_cast<double>(grid.cells[axis]));
  return b >= a ? static_cast<std::int64_t>(b - a) + 1 : 0;
}

}  // namespace hmpm::api::parse
