// material_models.cpp — see material_models.hpp: the table of models.
#include "material_models.hpp"

#include <algorithm>
#include <limits>

#include "expression.hpp"

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

// ------------------------------------------------- Modified Cam-Clay parameters
enum CamClayParameter : std::size_t {
  ncl_slope,
  url_slope,
  critical_ratio,
  void_ratio,
  preconsolidation,
  overconsolidation
};

std::string kappa_below_lambda(double kappa, std::span<const double> earlier) {
  const double lambda = earlier[ncl_slope];
  if (kappa >= lambda)
    return "is " + format_number(kappa) + ", not below lambda " + format_number(lambda) +
           ": the unloading-reloading line must be flatter than the normal compression line "
           "(kappa/lambda is about 0.1-0.3 for clays, e.g. lambda 0.1, kappa 0.02)";
  return {};
}

std::string critical_state_ratio_plausible(double m, std::span<const double>) {
  if (m > 3.0)
    return "is " + format_number(m) +
           "; M = 6 sin(phi')/(3 - sin(phi')) is at most 3 (phi' = 90 degrees), about 0.8-1.4 "
           "for clays (phi' 20-35 degrees)";
  return {};
}

// preconsolidation_pressure may also be a formula in x, y, z (materials.cpp
// reads it); fallback 0 marks it absent.
const ModelParameter cam_clay_parameters[] = {
    {"lambda", Range::positive(), 0.1, true},
    {"kappa", Range::positive(), 0.03, true, kappa_below_lambda},
    {"critical_state_ratio", Range::positive(), 1.2, true, critical_state_ratio_plausible},
    {"initial_void_ratio", Range::positive(), 1.0, true},
    {"preconsolidation_pressure", Range::positive(), 0.0, false},
    {"overconsolidation_ratio",
     {1.0, std::numeric_limits<double>::infinity(), false, false},
     0.0,
     false},
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
    {"modified_cam_clay", cam_clay_parameters,
     [](std::span<const double> v) -> Plasticity {
       ModifiedCamClay m;
       m.lambda = v[ncl_slope];
       m.kappa = v[url_slope];
       m.critical_state_ratio = v[critical_ratio];
       m.initial_void_ratio = v[void_ratio];
       // A number; materials.cpp replaces it by the formula when it is one.
       if (v[preconsolidation] > 0)
         m.preconsolidation_pressure = constant_field_of_position(v[preconsolidation]);
       m.overconsolidation_ratio = v[overconsolidation] > 0 ? v[overconsolidation] : 1.0;
       return m;
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
