// materials/varying.cpp — see varying.hpp: the values of varying material
// parameters at the particles.
#include "materials/varying.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include "hmpm/format.hpp"
#include "hmpm/random_field.hpp"
#include "hmpm/run.hpp"
#include "particle_layout.hpp"

namespace hmpm {

namespace {

/// f(cohesion, friction angle) of the material, when its model has them
/// (Material or const Material).
template <class M, class F>
void with_strength(M& m, F&& f) {
  std::visit(
      [&f](auto& model) {
        using T = std::decay_t<decltype(model)>;
        if constexpr (std::is_same_v<T, MohrCoulomb> || std::is_same_v<T, DruckerPrager>)
          f(model.cohesion, model.friction_angle_deg);
      },
      m.plasticity);
}

}  // namespace

const char* parameter_name(MaterialParameter k) {
  switch (k) {
    case MaterialParameter::youngs_modulus:
      return "youngs_modulus";
    case MaterialParameter::cohesion:
      return "cohesion";
    case MaterialParameter::friction_angle:
      return "friction_angle";
    case MaterialParameter::hydraulic_conductivity:
      return "hydraulic_conductivity";
    case MaterialParameter::preconsolidation_pressure:
      return "preconsolidation_pressure";
  }
  return "?";
}

double parameter_of(const Material& m, MaterialParameter k) {
  double out = 0.0;
  switch (k) {
    case MaterialParameter::youngs_modulus:
      return m.youngs_modulus;
    case MaterialParameter::hydraulic_conductivity:
      return m.hydraulic ? m.hydraulic->hydraulic_conductivity : 0.0;
    case MaterialParameter::cohesion:
    case MaterialParameter::friction_angle:
      with_strength(m, [&](const double& c, const double& phi) {
        out = k == MaterialParameter::cohesion ? c : phi;
      });
      break;
    case MaterialParameter::preconsolidation_pressure:
      // A number (the parser's constant function, or set_parameter's);
      // a formula's value at the origin, which no phase reads.
      if (const auto* cc = std::get_if<ModifiedCamClay>(&m.plasticity))
        if (cc->preconsolidation_pressure) out = cc->preconsolidation_pressure(Vec3{0.0, 0.0, 0.0});
      break;
  }
  return out;
}

void set_parameter(Material& m, MaterialParameter k, double value) {
  switch (k) {
    case MaterialParameter::youngs_modulus:
      m.youngs_modulus = value;
      break;
    case MaterialParameter::hydraulic_conductivity:
      if (m.hydraulic) m.hydraulic->hydraulic_conductivity = value;
      break;
    case MaterialParameter::cohesion:
    case MaterialParameter::friction_angle:
      with_strength(
          m, [&](double& c, double& phi) { (k == MaterialParameter::cohesion ? c : phi) = value; });
      break;
    case MaterialParameter::preconsolidation_pressure:
      if (auto* cc = std::get_if<ModifiedCamClay>(&m.plasticity))
        cc->preconsolidation_pressure = [value](const Vec3&) { return value; };
      break;
  }
}

bool parameter_applies(const Material& m, MaterialParameter k) {
  switch (k) {
    case MaterialParameter::youngs_modulus:
      return true;
    case MaterialParameter::hydraulic_conductivity:
      return m.hydraulic.has_value();
    case MaterialParameter::cohesion:
    case MaterialParameter::friction_angle:
      return std::holds_alternative<MohrCoulomb>(m.plasticity) ||
             std::holds_alternative<DruckerPrager>(m.plasticity);
    case MaterialParameter::preconsolidation_pressure:
      return std::holds_alternative<ModifiedCamClay>(m.plasticity);
  }
  return false;
}

std::string parameter_range_issue(MaterialParameter k, double value) {
  if (!std::isfinite(value)) return "is not a finite number";
  switch (k) {
    case MaterialParameter::youngs_modulus:
    case MaterialParameter::preconsolidation_pressure:
      if (!(value > 0)) return "must be > 0";
      break;
    case MaterialParameter::cohesion:
    case MaterialParameter::hydraulic_conductivity:
      if (!(value >= 0)) return "must be >= 0";
      break;
    case MaterialParameter::friction_angle:
      if (!(value >= 0 && value < 90)) return "must be in [0, 90)";
      break;
  }
  return {};
}

std::vector<std::vector<double>> varying_values(const Problem& problem, std::size_t material,
                                                const std::vector<BodyLayout>& layouts) {
  const Material& m = problem.materials[material];
  std::vector<std::array<double, 3>> points;
  for (std::size_t b = 0; b < problem.bodies.size() && b < layouts.size(); ++b)
    if (static_cast<std::size_t>(problem.bodies[b].material) == material)
      points.insert(points.end(), layouts[b].positions.begin(), layouts[b].positions.end());
  std::vector<std::vector<double>> out;
  out.reserve(m.varying.size());
  for (const VaryingParameter& v : m.varying) {
    if (v.random_field) {
      out.push_back(sample_random_field(*v.random_field, problem.dimension, points));
    } else {
      std::vector<double> values(points.size(), parameter_of(m, v.parameter));
      if (v.value)
        for (std::size_t i = 0; i < points.size(); ++i) values[i] = v.value(points[i]);
      out.push_back(std::move(values));
    }
  }
  return out;
}

std::vector<Field> default_snapshot_fields(const Problem& problem) {
  std::vector<Field> out;
  for (const FieldInfo& f : field_table) {
    bool wanted = !is_material_parameter_field(f.field) && !is_cam_clay_field(f.field);
    for (const Material& m : problem.materials)
      wanted = wanted || (is_cam_clay_field(f.field) &&
                          std::holds_alternative<ModifiedCamClay>(m.plasticity));
    for (const Material& m : problem.materials)
      for (const VaryingParameter& v : m.varying)
        wanted = wanted || (is_material_parameter_field(f.field) &&
                            v.parameter == parameter_of_field(f.field));
    if (wanted) out.push_back(f.field);
  }
  return out;
}

std::vector<Material> limiting_materials(const Problem& problem) {
  std::vector<Material> out = problem.materials;
  const bool any =
      std::any_of(out.begin(), out.end(), [](const Material& m) { return !m.varying.empty(); });
  if (!any) return out;
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  for (std::size_t i = 0; i < out.size(); ++i) {
    Material& m = out[i];
    if (m.varying.empty()) continue;
    const std::vector<std::vector<double>> values = varying_values(problem, i, layouts);
    for (std::size_t k = 0; k < m.varying.size(); ++k) {
      const MaterialParameter p = m.varying[k].parameter;
      if (p != MaterialParameter::youngs_modulus && p != MaterialParameter::hydraulic_conductivity)
        continue;
      if (values[k].empty()) continue;
      set_parameter(m, p, *std::max_element(values[k].begin(), values[k].end()));
    }
  }
  return out;
}

}  // namespace hmpm
