// initial_state.cpp — the "initial_state" section: procedures that set the
// initial state of all bodies together (today the geostatic state).
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view initial_state_allowed[] = {"geostatic"};
constexpr std::string_view geostatic_allowed[] = {"water_table", "k0"};

}  // namespace

void initial_state_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/initial_state", initial_state_allowed));
  out.push_back(keys_entry("/initial_state/geostatic", geostatic_allowed));
}

void read_initial_state(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, initial_state_allowed)) return;
  if (!j.contains("geostatic")) return;
  const json& g = j["geostatic"];
  const std::string gp = path + "/geostatic";
  if (!r.object(g, gp, geostatic_allowed)) return;
  Geostatic geo;
  r.number_at(g, gp, "water_table", Range::any(), geo.water_table);
  if (g.contains("k0")) {
    const json& k = g["k0"];
    const std::string kp = gp + "/k0";
    if (k.is_object()) {
      geo.material_k0.resize(c.p.materials.size());
      for (const auto& [name, value] : k.items()) {
        const std::string mp = child_pointer(kp, name);
        const auto it = c.material_index.find(name);
        if (it == c.material_index.end()) {
          r.error(mp, "names no material");
          continue;
        }
        if (auto v = r.number(value, mp, Range::non_negative()))
          geo.material_k0[static_cast<std::size_t>(it->second)] = *v;
      }
    } else if (k.is_number()) {
      if (auto v = r.number(k, kp, Range::non_negative())) geo.k0 = *v;
    } else {
      r.error(kp, std::string("expected a number >= 0 or an object of material name -> number, "
                              "got ") +
                      k.type_name());
    }
  }
  c.p.initial_state.geostatic = std::move(geo);
}

}  // namespace hmpm::api::parse
