// materials/linear_elastic.hpp — the linear-elastic soil model (internal).
//
// The elastic predictor of the stress update is the whole model: no return
// mapping, no internal state. Listed beside the plastic models so that every
// model has the same three members the stress update reads.
#pragma once

#include "elastic.hpp"

namespace hmpm::constitutive {

/// The model as the stress update sees it (see MohrCoulombModel).
struct LinearElasticModel {
  struct Constants {};
  static constexpr int state_variables = 0;
  static inline void return_stress(Voigt&, const Elastic&, const Constants&) {}
};

}  // namespace hmpm::constitutive
