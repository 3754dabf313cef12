// material_models.hpp — the constitutive models a job spec can name: one table.
//
// Each entry is a model's spec name, the parameters it reads (key, range,
// value when absent, required or not, and an optional check against the
// parameters read before it) and the function that builds the solver's
// hmpm::Plasticity from the values. The materials reader, the keys a
// material accepts, its messages ("applies only to models ...") and the
// JSON Schema check (`hmpm spec-keys`) all derive from this table. To add a
// model: its struct in the hmpm::Plasticity variant (solver), its return
// mapping in the solver, and one entry here with its builder.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hmpm/problem.hpp"
#include "spec_reader.hpp"

namespace hmpm::api::parse {

struct ModelParameter {
  std::string_view key;
  Range range;
  double fallback;  ///< value when the key is absent
  bool required;
  /// Checks the value against the parameters read before it (their values
  /// in parameter order); returns a message, or empty when acceptable.
  std::string (*check)(double value, std::span<const double> earlier) = nullptr;
};

struct MaterialModel {
  std::string_view name;
  std::span<const ModelParameter> parameters;
  /// The solver's model from the parameter values, in parameter order.
  Plasticity (*build)(std::span<const double> values);
};

/// Every model, the default ("linear_elastic") first.
std::span<const MaterialModel> material_models();
/// The model named `name`, or nullptr.
const MaterialModel* find_material_model(std::string_view name);
/// The model names, in table order.
std::span<const std::string_view> material_model_names();
/// Every parameter key of any model, each once, in first-seen table order.
std::span<const std::string_view> model_parameter_keys();
/// "models 'mohr_coulomb' and 'drucker_prager'": the models that read `key`.
std::string models_reading(std::string_view key);

}  // namespace hmpm::api::parse
