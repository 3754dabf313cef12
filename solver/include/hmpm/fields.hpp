// fields.hpp — the output fields: one table, everything else derives from it.
//
// A field is a per-particle quantity the solver can write into a series or
// a snapshot. `field_table` lists each one with its contract name, its kind
// and its SI unit; from it derive field_name and field_components (here),
// the names the job-spec parser accepts, the column and array names the
// result writers produce, the JSON Schema check (through `hmpm spec-keys`)
// and the units of the plots (hmpm-server's GET /fields, read by the
// dashboard and the Python client).
// To add a field: a Field enumerator, its row in field_table (same order),
// its Snapshot array in run.hpp and its sampling in the solver.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace hmpm {

enum class Field : std::uint8_t {
  position,
  displacement,
  velocity,
  pore_pressure,
  darcy_velocity,
  effective_stress,
  strain,
  porosity,
  total_stress,
  plastic_strain,
  // A material parameter's value at the particle (MaterialParameter,
  // problem.hpp, in the same order): the particle's own where the parameter
  // varies (random fields), else its material's. In the default snapshot
  // fields only when some material varies it.
  youngs_modulus,
  cohesion,
  friction_angle,
  hydraulic_conductivity,
  excess_pore_pressure,
  // Modified Cam-Clay's state variables (0 at particles of other models);
  // in the default snapshot fields only when some material is Cam-Clay.
  void_ratio,
  preconsolidation_pressure,
};

/// scalar: 1 component; vector: one per axis (dim); tensor: 6 in Voigt
/// order xx, yy, zz, xy, yz, zx in every dimension.
enum class FieldKind : std::uint8_t { scalar, vector, tensor };

struct FieldInfo {
  Field field;
  std::string_view name;  ///< the contract's name ("pore_pressure", ...)
  FieldKind kind;
  std::string_view unit;  ///< SI unit of every component ("-": dimensionless)
};

/// Every field, in the order of the Field enumerators.
inline constexpr std::array<FieldInfo, 17> field_table{{
    {Field::position, "position", FieldKind::vector, "m"},
    {Field::displacement, "displacement", FieldKind::vector, "m"},
    {Field::velocity, "velocity", FieldKind::vector, "m/s"},
    {Field::pore_pressure, "pore_pressure", FieldKind::scalar, "Pa"},
    {Field::darcy_velocity, "darcy_velocity", FieldKind::vector, "m/s"},
    {Field::effective_stress, "effective_stress", FieldKind::tensor, "Pa"},
    {Field::strain, "strain", FieldKind::tensor, "-"},
    {Field::porosity, "porosity", FieldKind::scalar, "-"},
    {Field::total_stress, "total_stress", FieldKind::tensor, "Pa"},
    // Accumulated equivalent plastic strain, sum of sqrt(2/3 deps_p : deps_p)
    // over the steps (zero for elastic materials).
    {Field::plastic_strain, "plastic_strain", FieldKind::scalar, "-"},
    // The material parameters (0 where the particle's material has none:
    // cohesion and friction angle of a linear-elastic material, the
    // hydraulic conductivity of a dry one).
    {Field::youngs_modulus, "youngs_modulus", FieldKind::scalar, "Pa"},
    {Field::cohesion, "cohesion", FieldKind::scalar, "Pa"},
    {Field::friction_angle, "friction_angle", FieldKind::scalar, "deg"},
    {Field::hydraulic_conductivity, "hydraulic_conductivity", FieldKind::scalar, "m/s"},
    // The pore pressure minus the steady one at the particle's current
    // position (output.consolidation's reference: its steady_pore_pressure,
    // else the hydrostatic pressure under the geostatic water table, else
    // 0); zero where the material has no pore water.
    {Field::excess_pore_pressure, "excess_pore_pressure", FieldKind::scalar, "Pa"},
    // Modified Cam-Clay's void ratio e and preconsolidation pressure p'c
    // (compression positive); 0 at particles of other models.
    {Field::void_ratio, "void_ratio", FieldKind::scalar, "-"},
    {Field::preconsolidation_pressure, "preconsolidation_pressure", FieldKind::scalar, "Pa"},
}};
inline constexpr int field_count = static_cast<int>(field_table.size());

constexpr bool field_table_is_in_enum_order() {
  for (std::size_t i = 0; i < field_table.size(); ++i)
    if (static_cast<std::size_t>(field_table[i].field) != i) return false;
  return true;
}
static_assert(field_table_is_in_enum_order(), "field_table rows must follow the Field enumerators");

/// The fields of the material parameters: youngs_modulus and after.
constexpr bool is_material_parameter_field(Field f) {
  return f >= Field::youngs_modulus && f <= Field::hydraulic_conductivity;
}

/// The fields of Modified Cam-Clay's state variables.
constexpr bool is_cam_clay_field(Field f) {
  return f == Field::void_ratio || f == Field::preconsolidation_pressure;
}

/// What field_info gives for a value outside the enumerators: "?", one component.
inline constexpr FieldInfo unknown_field{Field::position, "?", FieldKind::scalar, ""};

constexpr const FieldInfo& field_info(Field f) {
  const auto i = static_cast<std::size_t>(f);
  return i < field_table.size() ? field_table[i] : unknown_field;
}

/// Components of a kind in `dim` dimensions (vectors: dim; tensors: 6; scalars: 1).
constexpr int kind_components(FieldKind kind, int dim) {
  return kind == FieldKind::vector ? dim : kind == FieldKind::tensor ? 6 : 1;
}

/// Number of components a field has in `dim` dimensions (vectors: dim;
/// tensors: 6 in Voigt order xx, yy, zz, xy, yz, zx; scalars: 1).
constexpr int field_components(Field f, int dim) {
  return kind_components(field_info(f).kind, dim);
}

/// The contract's name of a field ("pore_pressure", ...), NUL-terminated.
constexpr const char* field_name(Field f) {
  return field_info(f).name.data();
}

/// "scalar", "vector" or "tensor".
constexpr std::string_view kind_name(FieldKind kind) {
  return kind == FieldKind::vector ? "vector" : kind == FieldKind::tensor ? "tensor" : "scalar";
}

}  // namespace hmpm
