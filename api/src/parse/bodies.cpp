// bodies.cpp — the "bodies" section: boxes of a material filled with
// particles, and their initial fields.
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view body_allowed[] = {"material", "box", "particles_per_cell", "initial"};
constexpr std::string_view body_required[] = {"material", "box"};
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

void read_body(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  Body body;
  body.material = -1;
  if (!r.object(j, path, body_allowed, body_required)) return;
  if (j.contains("material")) {
    if (auto name = r.string(j["material"], path + "/material", 100)) {
      if (auto it = c.material_index.find(*name); it != c.material_index.end()) {
        body.material = it->second;
      } else {
        std::vector<std::string> names;
        for (const auto& [n, i] : c.material_index) names.push_back(n);
        r.error(path + "/material", "unknown material '" + *name + "'; defined materials: " +
                                        (names.empty() ? std::string("none") : quoted_list(names)));
      }
    }
  }
  if (j.contains("box"))
    if (auto b = read_box(c, j["box"], path + "/box")) body.box = *b;
  if (j.contains("particles_per_cell"))
    if (auto n = r.integer(j["particles_per_cell"], path + "/particles_per_cell", 1,
                           max_particles_per_cell))
      body.particles_per_cell = static_cast<int>(*n);
  if (j.contains("initial")) read_initial(c, body, j["initial"], path + "/initial");
  c.p.bodies.push_back(std::move(body));
}

}  // namespace

void body_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/bodies/*", body_allowed));
  out.push_back(keys_entry("/bodies/*/box", box_key_names()));
  out.push_back(keys_entry("/bodies/*/initial", initial_allowed));
}

void read_bodies(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  if (j.empty()) c.r.error(path, "is empty; at least one body is needed");
  for (std::size_t i = 0; i < j.size(); ++i) read_body(c, j[i], child_pointer(path, i));
}

}  // namespace hmpm::api::parse
