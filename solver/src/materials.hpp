// materials.hpp — material constants derived once from a Material (internal).
//
// Everything the hot loops need is precomputed here, so the time step never
// recomputes moduli or looks anything up by name.
#pragma once

#include <cmath>
#include <limits>

#include "hmpm/problem.hpp"

namespace hmpm {

struct MaterialConstants {
  double lambda = 0.0;               ///< Lame's first parameter, Pa
  double shear_modulus = 0.0;        ///< G, Pa
  double constrained_modulus = 0.0;  ///< E(1-nu)/((1+nu)(1-2nu)), Pa
  double mixture_density = 0.0;      ///< kg/m^3
  bool saturated = false;
  double porosity = 0.0;
  double storage = 0.0;              ///< Q = (1-n)/Ks + n/Kf, 1/Pa
  double undrained_p_modulus = 0.0;  ///< constrained modulus + 1/Q (saturated), Pa
  double fluid_density = 0.0;
  double permeability_over_gamma = 0.0;  ///< k / (rho_f g), m^3 s / kg
};

inline MaterialConstants material_constants(const Material& m, double gravity_constant) {
  MaterialConstants c;
  const double E = m.youngs_modulus, nu = m.poisson_ratio;
  c.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  c.shear_modulus = E / (2 * (1 + nu));
  c.constrained_modulus = c.lambda + 2 * c.shear_modulus;
  c.mixture_density = m.density;
  c.undrained_p_modulus = c.constrained_modulus;
  if (m.hydraulic) {
    const Hydraulic& h = *m.hydraulic;
    c.saturated = true;
    c.porosity = h.porosity;
    c.fluid_density = h.fluid_density;
    c.mixture_density = (1 - h.porosity) * m.density + h.porosity * h.fluid_density;
    const double solid_term = std::isinf(h.solid_bulk_modulus) ? 0.0 : (1 - h.porosity) / h.solid_bulk_modulus;
    c.storage = solid_term + h.porosity / h.fluid_bulk_modulus;
    c.undrained_p_modulus += 1.0 / c.storage;
    c.permeability_over_gamma = h.hydraulic_conductivity / (h.fluid_density * gravity_constant);
  }
  return c;
}

}  // namespace hmpm
