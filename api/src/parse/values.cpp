// values.cpp — values several sections share: boxes, node and particle
// selections, and numbers-or-formulas of position and of time.
#include "expression.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view box_allowed[] = {"min", "max"};
constexpr std::string_view selection_allowed[] = {"box"};

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

std::optional<Box> read_selection(ParseContext& c, const json& j, const std::string& path,
                                  bool& all) {
  all = false;
  if (j.is_string()) {
    if (j.get_ref<const std::string&>() == "all") {
      all = true;
      return Box{c.p.grid.min, c.p.grid.max};
    }
    c.r.error(path,
              "expected \"all\" or {\"box\": {\"min\": [...], \"max\": [...]}}, got the string '" +
                  j.get_ref<const std::string&>().substr(0, 64) + "'");
    return std::nullopt;
  }
  if (!j.is_object()) {
    c.r.error(path,
              std::string("expected \"all\" or {\"box\": {\"min\": [...], \"max\": [...]}}, got ") +
                  j.type_name());
    return std::nullopt;
  }
  if (!c.r.object(j, path, selection_allowed, selection_allowed) || !j.contains("box"))
    return std::nullopt;
  return read_box(c, j["box"], path + "/box");
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
  if (!j.is_number()) {
    c.r.error(path,
              std::string("expected a number or a formula string in t, got ") + j.type_name());
    return std::nullopt;
  }
  if (auto v = c.r.number(j, path)) return constant_field_of_time(*v);
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
