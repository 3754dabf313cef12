// values.cpp — values several sections share: boxes, polygons, node and
// particle selections, and numbers-or-formulas of position and of time.
#include <algorithm>

#include "expression.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view box_allowed[] = {"min", "max"};
constexpr std::string_view selection_allowed[] = {"box", "polygon"};
// The simplicity check of a polygon compares every pair of edges.
constexpr std::size_t max_polygon_vertices = 2000;
constexpr const char* selection_expected =
    "expected \"all\", {\"box\": {\"min\": [...], \"max\": [...]}} or {\"polygon\": [[x, y], "
    "...]}";

// Counts a formula against the spec's formula budget (Limits::max_formulas,
// max_formula_characters); false, with an error at `path`, when over it.
bool admit_formula(ParseContext& c, const std::string& text, const std::string& path) {
  ++c.formulas;
  c.formula_characters += static_cast<std::int64_t>(text.size());
  if (c.formulas == static_cast<std::size_t>(c.limits.max_formulas) + 1) {
    c.r.error(path, "is formula number " + std::to_string(c.formulas) +
                        "; a spec may hold at most " + std::to_string(c.limits.max_formulas) +
                        " formulas (limit max_formulas); use numbers where the value is constant");
    return false;
  }
  if (c.formulas > static_cast<std::size_t>(c.limits.max_formulas)) return false;
  const std::int64_t before = c.formula_characters - static_cast<std::int64_t>(text.size());
  if (c.formula_characters > c.limits.max_formula_characters) {
    if (before <= c.limits.max_formula_characters)
      c.r.error(path, "brings the formulas of the spec to " + std::to_string(c.formula_characters) +
                          " characters; at most " +
                          std::to_string(c.limits.max_formula_characters) +
                          " in all (limit max_formula_characters)");
    return false;
  }
  return true;
}

}  // namespace

Keys box_key_names() {
  return box_allowed;
}

Keys selection_key_names() {
  return selection_allowed;
}

std::optional<Box> read_box(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, box_allowed, box_allowed)) return std::nullopt;
  std::optional<Vec3> lo, hi;
  if (j.contains("min")) lo = r.vector(j["min"], path + "/min", c.dim);
  if (j.contains("max")) hi = r.vector(j["max"], path + "/max", c.dim);
  if (!lo || !hi) return std::nullopt;
  const Grid& grid = c.p.grid;
  bool ok = true;
  for (int a = 0; a < c.dim; ++a) {
    if ((*hi)[a] < (*lo)[a]) {
      r.error(child_pointer(path + "/max", a),
              "is " + format_number((*hi)[a]) + "; must be >= min " + format_number((*lo)[a]));
      ok = false;
      continue;
    }
    if (!c.grid_ok) continue;
    const double tol = 1e-9 * (grid.max[a] - grid.min[a]);
    const std::string range = "; the grid spans [" + format_number(grid.min[a]) + ", " +
                              format_number(grid.max[a]) + "] along " + std::string(axis_names[a]);
    if ((*lo)[a] < grid.min[a] - tol || (*lo)[a] > grid.max[a] + tol) {
      r.error(child_pointer(path + "/min", a),
              "is " + format_number((*lo)[a]) + ", outside the grid" + range);
      ok = false;
    }
    if ((*hi)[a] > grid.max[a] + tol || (*hi)[a] < grid.min[a] - tol) {
      r.error(child_pointer(path + "/max", a),
              "is " + format_number((*hi)[a]) + ", outside the grid" + range);
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return Box{*lo, *hi};
}

std::optional<Polygon> read_polygon(ParseContext& c, const json& j, const std::string& path,
                                    std::array<int, 2> plane) {
  SpecReader& r = c.r;
  if (!j.is_array()) {
    r.error(path, std::string("expected an array of vertices [[") +
                      std::string(axis_names[plane[0]]) + ", " + std::string(axis_names[plane[1]]) +
                      "], ...], got " + j.type_name());
    return std::nullopt;
  }
  if (j.size() < 3) {
    r.error(path, "has " + std::to_string(j.size()) +
                      " vertices; a polygon needs at least 3, in order along its boundary (it "
                      "closes itself)");
    return std::nullopt;
  }
  if (j.size() > max_polygon_vertices) {
    r.error(path, "has " + std::to_string(j.size()) + " vertices; the limit is " +
                      std::to_string(max_polygon_vertices));
    return std::nullopt;
  }
  Polygon polygon;
  bool ok = true;
  for (std::size_t k = 0; k < j.size(); ++k) {
    const std::string vp = child_pointer(path, k);
    const json& v = j[k];
    if (!v.is_array() || v.size() != 2) {
      r.error(vp, std::string("expected a vertex [") + std::string(axis_names[plane[0]]) + ", " +
                      std::string(axis_names[plane[1]]) +
                      "] (two numbers: polygons are plane), got " +
                      (v.is_array() ? std::to_string(v.size()) + " entries" : v.type_name()));
      ok = false;
      continue;
    }
    std::array<double, 2> xy{0.0, 0.0};
    for (std::size_t q = 0; q < 2; ++q) {
      const auto x = r.number(v[q], child_pointer(vp, q));
      if (!x) {
        ok = false;
        continue;
      }
      xy[q] = *x;
      const int a = plane[q];
      const Grid& grid = c.p.grid;
      if (!c.grid_ok || a >= c.dim) continue;
      const double tol = 1e-9 * (grid.max[a] - grid.min[a]);
      if (*x < grid.min[a] - tol || *x > grid.max[a] + tol) {
        r.error(child_pointer(vp, q),
                "is " + format_number(*x) + ", outside the grid; the grid spans [" +
                    format_number(grid.min[a]) + ", " + format_number(grid.max[a]) + "] along " +
                    std::string(axis_names[a]));
        ok = false;
      }
    }
    polygon.vertices.push_back(xy);
  }
  if (!ok) return std::nullopt;
  return polygon;
}

std::optional<Box> read_selection(ParseContext& c, const json& j, const std::string& path,
                                  bool& all, std::optional<Polygon>* polygon) {
  all = false;
  if (j.is_string()) {
    if (j.get_ref<const std::string&>() == "all") {
      all = true;
      return Box{c.p.grid.min, c.p.grid.max};
    }
    c.r.error(path, std::string(selection_expected) + ", got the string '" +
                        j.get_ref<const std::string&>().substr(0, 64) + "'");
    return std::nullopt;
  }
  if (!j.is_object()) {
    c.r.error(path, std::string(selection_expected) + ", got " + j.type_name());
    return std::nullopt;
  }
  if (!c.r.object(j, path, selection_allowed)) return std::nullopt;
  if (j.contains("box") == j.contains("polygon")) {
    c.r.error(path, j.contains("box") ? "gives both 'box' and 'polygon'; give one"
                                      : "needs 'box' or 'polygon'");
    return std::nullopt;
  }
  if (j.contains("box")) return read_box(c, j["box"], path + "/box");
  if (c.dim != 2) {
    c.r.error(path + "/polygon",
              "selects in the (x, y) plane, which needs a 2D problem; this one "
              "is " +
                  std::to_string(c.dim) + "D: select by 'box'");
    return std::nullopt;
  }
  auto poly = read_polygon(c, j["polygon"], path + "/polygon", {0, 1});
  if (!poly) return std::nullopt;
  Box bounds{c.p.grid.min, c.p.grid.min};
  for (int a = 0; a < 2; ++a) {
    bounds.min[a] = poly->vertices.front()[a];
    bounds.max[a] = poly->vertices.front()[a];
    for (const auto& v : poly->vertices) {
      bounds.min[a] = std::min(bounds.min[a], v[a]);
      bounds.max[a] = std::max(bounds.max[a], v[a]);
    }
  }
  if (polygon) *polygon = std::move(poly);
  return bounds;
}

FieldOfPosition read_value_of_position(ParseContext& c, const json& j, const std::string& path) {
  if (j.is_string()) {
    if (!admit_formula(c, j.get_ref<const std::string&>(), path)) return {};
    std::string error;
    if (auto f = compile_field_of_position(j.get_ref<const std::string&>(), error)) {
      c.position_formulas.push_back(
          {c.p.bodies.size(), path, *f, j.get_ref<const std::string&>().size()});
      return *f;
    }
    c.r.error(path, error);
    return {};
  }
  if (!j.is_number()) {
    c.r.error(path, std::string("expected a number or a formula string in x, y, z, got ") +
                        j.type_name());
    return {};
  }
  if (auto v = c.r.number(j, path)) return constant_field_of_position(*v);
  return {};
}

std::optional<FieldOfTime> read_value_of_time(ParseContext& c, const json& j,
                                              const std::string& path) {
  if (j.is_string()) {
    if (!admit_formula(c, j.get_ref<const std::string&>(), path)) return std::nullopt;
    std::string error;
    if (auto f = compile_field_of_time(j.get_ref<const std::string&>(), error)) {
      c.time_formulas.push_back({path, *f, j.get_ref<const std::string&>().size()});
      return f;
    }
    c.r.error(path, error);
    return std::nullopt;
  }
  if (j.is_object()) return read_table_of_time(c, j, path);
  if (!j.is_number()) {
    c.r.error(path, std::string("expected a number, a formula string in t or {\"table\": [[t, "
                                "value], ...]}, got ") +
                        j.type_name());
    return std::nullopt;
  }
  if (auto v = c.r.number(j, path)) return constant_field_of_time(*v);
  return std::nullopt;
}

std::optional<FieldOfSpaceTime> read_value_of_space_time(ParseContext& c, const json& j,
                                                         const std::string& path,
                                                         bool& varies_in_space) {
  varies_in_space = false;
  if (j.is_string()) {
    const std::string& text = j.get_ref<const std::string&>();
    if (!admit_formula(c, text, path)) return std::nullopt;
    std::string error;
    if (auto f = compile_field_of_space_time(text, error, varies_in_space)) {
      // The finiteness check of the formulas of time, at the grid's centre.
      const Problem& p = c.p;
      c.time_formulas.push_back({path,
                                 [&p, f = *f](double t) {
                                   Vec3 mid{};
                                   for (int a = 0; a < 3; ++a)
                                     mid[a] = 0.5 * (p.grid.min[a] + p.grid.max[a]);
                                   return f(mid, t);
                                 },
                                 text.size()});
      return f;
    }
    c.r.error(path, error);
    return std::nullopt;
  }
  if (!j.is_number()) {
    c.r.error(path, std::string("expected a number or a formula string in x, y, z, t, got ") +
                        j.type_name());
    return std::nullopt;
  }
  if (auto v = c.r.number(j, path)) return constant_field_of_space_time(*v);
  return std::nullopt;
}

std::string quoted_list(const std::vector<std::string>& words) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i) out += ", ";
    out += '\'';
    out += words[i];
    out += '\'';
  }
  return out;
}

}  // namespace hmpm::api::parse
