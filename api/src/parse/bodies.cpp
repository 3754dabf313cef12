// bodies.cpp — the "bodies" section: shapes of a material (a box, a polygon
// in 2D, a prism in 3D, or explicit points) filled with particles, and
// their initial fields.
#include <algorithm>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view body_allowed[] = {
    "material", "box", "polygon", "prism", "points", "particles_per_cell", "initial"};
constexpr std::string_view body_required[] = {"material"};
constexpr std::string_view shape_keys[] = {"box", "polygon", "prism", "points"};
constexpr std::string_view prism_allowed[] = {"polygon", "axis", "from", "to"};
constexpr std::string_view points_allowed[] = {"positions", "volumes"};
constexpr std::string_view initial_allowed[] = {"velocity", "pore_pressure", "effective_stress"};
constexpr int max_particles_per_cell = 10;

void read_initial(ParseContext& c, Body& body, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, initial_allowed)) return;
  if (j.contains("velocity")) {
    const json& v = j["velocity"];
    const std::string vp = path + "/velocity";
    if (r.per_axis(v, vp, c.dim, "number or formula")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a)
        body.initial.velocity[a] = read_value_of_position(c, v[a], child_pointer(vp, a));
    }
  }
  if (j.contains("pore_pressure")) {
    body.initial.pore_pressure =
        read_value_of_position(c, j["pore_pressure"], path + "/pore_pressure");
    if (body.material >= 0 && !c.p.materials[static_cast<std::size_t>(body.material)].hydraulic)
      r.error(path + "/pore_pressure",
              "is given but material '" +
                  c.p.materials[static_cast<std::size_t>(body.material)].name +
                  "' has no 'hydraulic' properties");
  }
  if (j.contains("effective_stress")) {
    const json& s = j["effective_stress"];
    const std::string sp = path + "/effective_stress";
    if (!s.is_array() || s.size() != 6) {
      r.error(
          sp,
          "expected an array of 6 numbers or formulas (Voigt order xx, yy, zz, xy, yz, zx), got " +
              (s.is_array() ? std::to_string(s.size()) + " entries" : std::string(s.type_name())));
    } else {
      for (std::size_t k = 0; k < 6; ++k)
        body.initial.effective_stress[k] = read_value_of_position(c, s[k], child_pointer(sp, k));
    }
  }
}

/// Every key present (SpecReader::object reports the missing ones).
bool has_all(const json& j, Keys keys) {
  return std::all_of(keys.begin(), keys.end(), [&](std::string_view k) { return j.contains(k); });
}

/// {"polygon": [[u, v], ...], "axis": "z", "from": z0, "to": z1}.
std::optional<Prism> read_prism(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, prism_allowed, prism_allowed) || !has_all(j, prism_allowed))
    return std::nullopt;
  Prism prism;
  const auto axis = r.one_of(j["axis"], path + "/axis", axis_names);
  if (!axis) return std::nullopt;
  prism.axis = (*axis)[0] - 'x';
  const std::array<int, 2> plane = prism.axis == 0   ? std::array<int, 2>{1, 2}
                                   : prism.axis == 1 ? std::array<int, 2>{0, 2}
                                                     : std::array<int, 2>{0, 1};
  auto polygon = read_polygon(c, j["polygon"], path + "/polygon", plane);
  const auto from = r.number(j["from"], path + "/from");
  const auto to = r.number(j["to"], path + "/to");
  if (!polygon || !from || !to) return std::nullopt;
  if (c.grid_ok) {
    const Grid& grid = c.p.grid;
    const int a = prism.axis;
    const double tol = 1e-9 * (grid.max[a] - grid.min[a]);
    for (const auto& [key, value] : {std::pair{"/from", *from}, std::pair{"/to", *to}})
      if (value < grid.min[a] - tol || value > grid.max[a] + tol) {
        r.error(path + key, "is " + format_number(value) + ", outside the grid; the grid spans [" +
                                format_number(grid.min[a]) + ", " + format_number(grid.max[a]) +
                                "] along " + std::string(axis_names[a]));
        return std::nullopt;
      }
  }
  prism.polygon = std::move(*polygon);
  prism.from = *from;
  prism.to = *to;
  return prism;
}

/// {"positions": [[x, ...], ...], "volumes": [v, ...]}.
std::optional<ParticleList> read_points(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, points_allowed, points_allowed) || !has_all(j, points_allowed))
    return std::nullopt;
  const json& pos = j["positions"];
  const json& vol = j["volumes"];
  if (!r.array(pos, path + "/positions", 1) || !r.array(vol, path + "/volumes", 1))
    return std::nullopt;
  if (pos.size() > static_cast<std::size_t>(c.limits.max_particles)) {
    r.error(path + "/positions", "has " + std::to_string(pos.size()) + " particles; the limit is " +
                                     std::to_string(c.limits.max_particles) + " particles in all");
    return std::nullopt;
  }
  if (vol.size() != pos.size()) {
    r.error(path + "/volumes", "has " + std::to_string(vol.size()) + " entries but positions has " +
                                   std::to_string(pos.size()) + "; give one volume per position");
    return std::nullopt;
  }
  ParticleList list;
  bool ok = true;
  for (std::size_t k = 0; k < pos.size(); ++k) {
    auto x = r.vector(pos[k], child_pointer(path + "/positions", k), c.dim);
    auto v = r.number(vol[k], child_pointer(path + "/volumes", k), Range::positive());
    if (!x || !v) {
      ok = false;
      continue;
    }
    list.positions.push_back(*x);
    list.volumes.push_back(*v);
  }
  if (!ok) return std::nullopt;
  return list;
}

void read_body(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  Body body;
  body.material = -1;
  if (!r.object(j, path, body_allowed, body_required)) return;
  if (j.contains("material"))
    if (auto m = read_material_name(c, j["material"], path + "/material")) body.material = *m;
  std::vector<std::string> shapes;
  for (std::string_view key : shape_keys)
    if (j.contains(key)) shapes.emplace_back(key);
  if (shapes.empty())
    r.error(path, "needs a shape: 'box', 'polygon' (2D), 'prism' (3D) or 'points'");
  else if (shapes.size() > 1)
    r.error(path, "gives " + quoted_list(shapes) + "; give exactly one shape");
  else if (j.contains("box")) {
    if (auto b = read_box(c, j["box"], path + "/box")) body.box = *b;
  } else if (j.contains("polygon")) {
    if (c.dim > 0 && c.dim != 2)
      r.error(path + "/polygon",
              "is a 2D shape but this problem is " + std::to_string(c.dim) + "D; use " +
                  (c.dim == 3 ? "'prism' (a polygon extruded along an axis)" : "'box'") +
                  " or 'points'");
    else
      body.polygon = read_polygon(c, j["polygon"], path + "/polygon", {0, 1});
  } else if (j.contains("prism")) {
    if (c.dim > 0 && c.dim != 3)
      r.error(path + "/prism", "is a 3D shape but this problem is " + std::to_string(c.dim) +
                                   "D; use " + (c.dim == 2 ? "'polygon'" : "'box'") +
                                   " or 'points'");
    else
      body.prism = read_prism(c, j["prism"], path + "/prism");
  } else {
    body.points = read_points(c, j["points"], path + "/points");
  }
  if (j.contains("particles_per_cell"))
    if (auto n = r.integer(j["particles_per_cell"], path + "/particles_per_cell", 1,
                           max_particles_per_cell))
      body.particles_per_cell = static_cast<int>(*n);
  if (j.contains("initial")) read_initial(c, body, j["initial"], path + "/initial");
  c.p.bodies.push_back(std::move(body));
}

}  // namespace

std::optional<int> read_material_name(ParseContext& c, const json& j, const std::string& path) {
  const auto name = c.r.string(j, path, 100);
  if (!name) return std::nullopt;
  if (auto it = c.material_index.find(*name); it != c.material_index.end()) return it->second;
  std::vector<std::string> names;
  for (const auto& [n, i] : c.material_index) names.push_back(n);
  c.r.error(path, "unknown material '" + *name + "'; defined materials: " +
                      (names.empty() ? std::string("none") : quoted_list(names)));
  return std::nullopt;
}

void body_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/bodies/*", body_allowed));
  out.push_back(keys_entry("/bodies/*/box", box_key_names()));
  out.push_back(keys_entry("/bodies/*/prism", prism_allowed));
  out.push_back(keys_entry("/bodies/*/points", points_allowed));
  out.push_back(keys_entry("/bodies/*/initial", initial_allowed));
}

void read_bodies(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  if (j.empty()) c.r.error(path, "is empty; at least one body is needed");
  for (std::size_t i = 0; i < j.size(); ++i) read_body(c, j[i], child_pointer(path, i));
}

}  // namespace hmpm::api::parse
