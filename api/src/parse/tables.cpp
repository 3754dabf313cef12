// tables.cpp — the parser's tables as one JSON document (`hmpm spec-keys`):
// the accepted keys of every object, the values of every enumeration, the
// output fields with their kinds and units and the material models with their
// parameters. The JSON Schema test (tests/api/check_schema.py) and the
// result checks compare against it instead of keeping their own copies.
#include <cmath>

#include "material_models.hpp"
#include "parser.hpp"

namespace hmpm::api {
namespace {

json range_json(const Range& r) {
  json out = json::object();
  if (std::isfinite(r.lo)) out[r.lo_open ? "exclusiveMinimum" : "minimum"] = r.lo;
  if (std::isfinite(r.hi)) out[r.hi_open ? "exclusiveMaximum" : "maximum"] = r.hi;
  return out;
}

json list(parse::Keys keys) {
  json out = json::array();
  for (std::string_view k : keys) out.push_back(std::string(k));
  return out;
}

}  // namespace

std::string spec_tables_json() {
  json doc;
  json& objects = doc["objects"] = json::object();
  for (const SpecObjectKeys& e : spec_object_keys()) objects[e.location] = e.keys;
  doc["values"] = {
      {"/shape_function", list(parse::shape_function_names())},
      {"/materials/*/model", list(parse::material_model_names())},
      {"/tractions/*/face", list(parse::traction_faces())},
      {"/fluxes/*/face", list(parse::traction_faces())},
      {"/surface_pressures/*/face", list(parse::traction_faces())},
      {"/time/scheme", list(parse::scheme_names())},
      {"/time/implicit/linear_solver", list(parse::linear_solver_names())},
      {"/output/series/fields/*", list(parse::field_names())},
      {"/output/snapshots/fields/*", list(parse::field_names())},
  };
  json& fields = doc["fields"] = json::array();
  for (const FieldInfo& f : field_table)
    fields.push_back({{"name", std::string(f.name)},
                      {"kind", std::string(kind_name(f.kind))},
                      {"unit", std::string(f.unit)}});
  json& models = doc["models"] = json::array();
  for (const parse::MaterialModel& m : parse::material_models()) {
    json parameters = json::array();
    for (const parse::ModelParameter& p : m.parameters)
      parameters.push_back({{"key", std::string(p.key)},
                            {"required", p.required},
                            {"default", p.fallback},
                            {"range", range_json(p.range)}});
    models.push_back({{"name", std::string(m.name)}, {"parameters", parameters}});
  }
  return doc.dump(2) + "\n";
}

}  // namespace hmpm::api
