// materials.cpp — the "materials" section: named materials, their elastic
// constants, their constitutive model (parameters from material_models.cpp)
// and their optional hydraulic properties.
#include <algorithm>
#include <cmath>

#include "material_models.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

// Keys every material reads; the model's parameters, "hydraulic" and
// "softening" (softening.cpp) follow.
constexpr std::string_view material_common_allowed[] = {"model", "density", "youngs_modulus",
                                                        "poisson_ratio"};
// youngs_modulus too, except for modified_cam_clay (read_material).
constexpr std::string_view material_required[] = {"model", "density", "poisson_ratio"};
constexpr std::string_view hydraulic_allowed[] = {"porosity",           "hydraulic_conductivity",
                                                  "fluid_bulk_modulus", "fluid_density",
                                                  "solid_bulk_modulus", "darcy_inertia"};
constexpr std::string_view hydraulic_required[] = {"porosity", "hydraulic_conductivity",
                                                   "fluid_bulk_modulus"};

// The keys a material accepts: the common ones, every model's parameters, "hydraulic".
Keys material_key_names() {
  static const std::vector<std::string_view> keys = [] {
    std::vector<std::string_view> out(std::begin(material_common_allowed),
                                      std::end(material_common_allowed));
    for (std::string_view k : model_parameter_keys()) out.push_back(k);
    out.push_back("hydraulic");
    out.push_back("softening");
    return out;
  }();
  return keys;
}

// A parameter that may vary from particle to particle: a number in
// `range`, or {"random_field": ...} (random_fields.cpp), recorded in
// m.varying with the distribution's mean as the material's nominal value.
std::optional<double> read_varying(ParseContext& c, Material& m, MaterialParameter k, const json& j,
                                   const std::string& path, const Range& range) {
  if (!j.is_object()) return c.r.number(j, path, range);
  const std::optional<RandomField> f = read_random_field(c, j, path);
  if (!f) return std::nullopt;
  m.varying.push_back({k, *f, {}});
  return f->mean();
}

// The model parameters that may vary.
std::optional<MaterialParameter> varying_parameter(std::string_view key) {
  if (key == "cohesion") return MaterialParameter::cohesion;
  if (key == "friction_angle") return MaterialParameter::friction_angle;
  if (key == "preconsolidation_pressure") return MaterialParameter::preconsolidation_pressure;
  return std::nullopt;
}

// The model's parameters: keys of other models refused, required ones
// present, each read in table order and checked against those before it.
Plasticity read_model(ParseContext& c, Material& mat, const MaterialModel& model, const json& j,
                      const std::string& path) {
  SpecReader& r = c.r;
  const auto reads = [&](std::string_view key) {
    return std::any_of(model.parameters.begin(), model.parameters.end(),
                       [&](const ModelParameter& p) { return p.key == key; });
  };
  for (std::string_view key : model_parameter_keys())
    if (!reads(key) && j.contains(key))
      r.error(child_pointer(path, key),
              "applies only to " + models_reading(key) + ", not '" + std::string(model.name) + "'");
  for (const ModelParameter& p : model.parameters)
    if (p.required && !j.contains(p.key))
      r.error(child_pointer(path, p.key),
              "is required for model '" + std::string(model.name) + "'");
  std::vector<double> values;
  FieldOfPosition position_value;
  for (const ModelParameter& p : model.parameters) {
    values.push_back(p.fallback);
    if (!j.contains(p.key)) continue;
    const std::string pp = child_pointer(path, p.key);
    const json& value = j[std::string(p.key)];
    const std::optional<MaterialParameter> k = varying_parameter(p.key);
    if (p.key == "preconsolidation_pressure" && value.is_string()) {
      // A formula in x, y, z, evaluated at set-up at each particle of the
      // material (values below 100 Pa or not finite are taken as 100 Pa,
      // materials/modified_cam_clay.hpp); not in the finiteness check of
      // a body's formulas, as the bodies of the material are not read yet.
      const std::size_t before = c.position_formulas.size();
      position_value = read_value_of_position(c, value, pp);
      c.position_formulas.resize(before);
      continue;
    }
    if (auto v = k ? read_varying(c, mat, *k, value, pp, p.range) : r.number(value, pp, p.range)) {
      values.back() = *v;
      if (p.check)
        if (std::string why = p.check(*v, std::span(values).first(values.size() - 1)); !why.empty())
          r.error(pp, std::move(why));
    }
  }
  Plasticity out = model.build(values);
  if (auto* cc = std::get_if<ModifiedCamClay>(&out)) {
    const bool pc = j.contains("preconsolidation_pressure"),
               ocr = j.contains("overconsolidation_ratio");
    if (pc == ocr)
      r.error(child_pointer(path, "preconsolidation_pressure"),
              pc ? "is given with overconsolidation_ratio; give one of them (p'c itself, or OCR "
                   "times the initial mean effective stress)"
                 : "or overconsolidation_ratio is required for model 'modified_cam_clay' (p'c "
                   "itself, or OCR times the initial mean effective stress; 1 for a normally "
                   "consolidated clay)");
    if (position_value) cc->preconsolidation_pressure = position_value;
  }
  return out;
}

void read_hydraulic(ParseContext& c, Material& m, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, hydraulic_allowed, hydraulic_required)) return;
  Hydraulic h;
  r.number_at(j, path, "porosity", {0.0, 1.0, true, true}, h.porosity);
  if (j.contains("hydraulic_conductivity"))
    if (auto v = read_varying(c, m, MaterialParameter::hydraulic_conductivity,
                              j["hydraulic_conductivity"], path + "/hydraulic_conductivity",
                              Range::non_negative()))
      h.hydraulic_conductivity = *v;
  r.number_at(j, path, "fluid_bulk_modulus", Range::positive(), h.fluid_bulk_modulus);
  r.number_at(j, path, "fluid_density", Range::positive(), h.fluid_density);
  r.number_at(j, path, "solid_bulk_modulus", Range::positive(), h.solid_bulk_modulus);
  if (j.contains("darcy_inertia"))
    if (auto v = r.boolean(j["darcy_inertia"], path + "/darcy_inertia")) h.darcy_inertia = *v;
  m.hydraulic = h;
}

void read_material(ParseContext& c, const std::string& name, const json& j,
                   const std::string& path) {
  SpecReader& r = c.r;
  Material m;
  m.name = name;
  if (name.empty() || name.size() > 100)
    r.error(path, "material names must have 1 to 100 characters");
  if (r.object(j, path, material_key_names(), material_required)) {
    r.number_at(j, path, "density", Range::positive(), m.density);
    if (j.contains("youngs_modulus"))
      if (auto v = read_varying(c, m, MaterialParameter::youngs_modulus, j["youngs_modulus"],
                                path + "/youngs_modulus", Range::positive()))
        m.youngs_modulus = *v;
    if (j.contains("poisson_ratio")) {
      const json& v = j["poisson_ratio"];
      const std::string vp = path + "/poisson_ratio";
      if (v.is_number() && v.get<double>() == 0.5)
        r.error(vp,
                "is 0.5; must be in (-1, 0.5): an incompressible skeleton has an infinite "
                "wave speed, so no explicit time step is stable");
      else if (auto nu = r.number(v, vp, {-1.0, 0.5, true, true}))
        m.poisson_ratio = *nu;
    }
    const MaterialModel* model = &material_models().front();
    if (j.contains("model"))
      if (auto s = r.one_of(j["model"], path + "/model", material_model_names()))
        model = find_material_model(*s);
    m.plasticity = read_model(c, m, *model, j, path);
    if (const auto* cc = std::get_if<ModifiedCamClay>(&m.plasticity)) {
      // Optional: the reference stiffness of the stable-step rules and the
      // implicit schemes' scalings; by default the elastic E at p' = p'c
      // when p'c is a number, else at 100 kPa (docs/job-spec.md).
      if (!j.contains("youngs_modulus")) {
        // A random field's mean (its nominal value, read_varying) as p'c.
        const bool pc_number = j.contains("preconsolidation_pressure") &&
                               (j["preconsolidation_pressure"].is_number() ||
                                j["preconsolidation_pressure"].is_object());
        const double p_pc = pc_number && cc->preconsolidation_pressure
                                ? cc->preconsolidation_pressure(Vec3{0.0, 0.0, 0.0})
                                : 0.0;
        const double p_ref = p_pc > 0 && std::isfinite(p_pc) ? p_pc : 1e5;
        if (cc->kappa > 0 && cc->initial_void_ratio > 0 && m.poisson_ratio < 0.5)
          m.youngs_modulus = 3.0 * (1.0 - 2.0 * m.poisson_ratio) * (1.0 + cc->initial_void_ratio) *
                             p_ref / cc->kappa;
      }
    } else if (!j.contains("youngs_modulus")) {
      r.error(child_pointer(path, "youngs_modulus"), "is required");
    }
    if (j.contains("softening")) read_softening(c, m, j["softening"], path + "/softening");
    if (j.contains("hydraulic")) read_hydraulic(c, m, j["hydraulic"], path + "/hydraulic");
  }
  c.material_index[name] = static_cast<int>(c.p.materials.size());
  c.p.materials.push_back(std::move(m));
}

}  // namespace

void material_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/materials/*", material_key_names()));
  out.push_back(keys_entry("/materials/*/hydraulic", hydraulic_allowed));
  softening_keys(out);
}

void read_materials(ParseContext& c, const json& j, const std::string& path) {
  if (!j.is_object()) {
    c.r.error(path, std::string("expected an object of named materials, got ") + j.type_name());
    return;
  }
  if (j.empty()) c.r.error(path, "is empty; at least one material is needed");
  for (const auto& [name, value] : j.items())
    read_material(c, name, value, child_pointer(path, name));
}

}  // namespace hmpm::api::parse
