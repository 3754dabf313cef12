// material_models.cpp — see material_models.hpp: the table of models.
#include "material_models.hpp"

#include <algorithm>

namespace hmpm::api::parse {
namespace {

// ------------------------------------------------- Mohr-Coulomb parameter set
// Shared by the Mohr-Coulomb and the Drucker-Prager (fitted to it) models.
enum MohrCoulombParameter : std::size_t { friction, dilatancy, cohesion, tension };

std::string dilatancy_within_friction(double psi, std::span<const double> earlier) {
  const double phi = earlier[friction];
  if (psi > phi)
    return "is " + format_number(psi) + " degrees; must not exceed friction_angle " +
           format_number(phi);
  return {};
}

std::string cohesion_gives_strength(double c, std::span<const double> earlier) {
  if (c == 0 && earlier[friction] == 0)
    return "is 0 with friction_angle 0: the material would have no strength";
  return {};
}

constexpr Range angle_range{0.0, 90.0, false, true};
const ModelParameter mohr_coulomb_parameters[] = {
    {"friction_angle", angle_range, 30.0, true},
    {"dilatancy_angle", angle_range, 0.0, true, dilatancy_within_friction},
    {"cohesion", Range::non_negative(), 0.0, true, cohesion_gives_strength},
    {"tensile_strength", Range::non_negative(), 0.0, false},
};

// ------------------------------------------------------------------ the table
const MaterialModel model_table[] = {
    {"linear_elastic", {}, [](std::span<const double>) -> Plasticity { return LinearElastic{}; }},
    {"mohr_coulomb", mohr_coulomb_parameters,
     [](std::span<const double> v) -> Plasticity {
       return MohrCoulomb{v[friction], v[dilatancy], v[cohesion], v[tension]};
     }},
    {"drucker_prager", mohr_coulomb_parameters,
     [](std::span<const double> v) -> Plasticity {
       return DruckerPrager{v[friction], v[dilatancy], v[cohesion], v[tension]};
     }},
};

}  // namespace

std::span<const MaterialModel> material_models() {
  return model_table;
}

const MaterialModel* find_material_model(std::string_view name) {
  for (const MaterialModel& m : model_table)
    if (m.name == name) return &m;
  return nullptr;
}

std::span<const std::string_view> material_model_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> out;
    for (const MaterialModel& m : model_table) out.push_back(m.name);
    return out;
  }();
  return names;
}

std::span<const std::string_view> model_parameter_keys() {
  static const std::vector<std::string_view> keys = [] {
    std::vector<std::string_view> out;
    for (const MaterialModel& m : model_table)
      for (const ModelParameter& p : m.parameters)
        if (std::find(out.begin(), out.end(), p.key) == out.end()) out.push_back(p.key);
    return out;
  }();
  return keys;
}

std::string models_reading(std::string_view key) {
  std::vector<std::string> names;
  for (const MaterialModel& m : model_table)
    if (std::any_of(m.parameters.begin(), m.parameters.end(),
                    [&](const ModelParameter& p) { return p.key == key; }))
      names.emplace_back(m.name);
  std::string out = names.size() == 1 ? "model " : "models ";
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) out += i + 1 == names.size() ? " and " : ", ";
    out += "'" + names[i] + "'";
  }
  return out;
}

}  // namespace hmpm::api::parse
