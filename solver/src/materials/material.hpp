// materials/material.hpp — material constants derived once from a Material,
// and the one dispatch from a material to its soil model (internal).
//
// Everything the hot loops need is precomputed here, so the time step never
// recomputes moduli or looks anything up by name. The soil model is a small
// enum: the stress update branches on it per particle and calls the
// closed-form return mapping of the model's own file (linear_elastic.hpp,
// mohr_coulomb.hpp, drucker_prager.hpp) with the constants stored here (no
// virtual call, nothing derived from angles in the loop).
//
// Internal state variables: a model declares how many it keeps per particle
// (`state_variables`); the particle state holds them as a structure of
// arrays (ParticleState::internal, one array per variable, sized for the
// largest count among the materials that have particles) and the stress
// update hands the model its particle's slots (InternalState). Linear
// elasticity, Mohr-Coulomb and Drucker-Prager declare none; Modified
// Cam-Clay keeps two (the void ratio and p'c, modified_cam_clay.hpp), a
// softening Mohr-Coulomb material one (its softening strain).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <variant>
#include <vector>

#include "drucker_prager.hpp"
#include "elastic.hpp"
#include "hmpm/problem.hpp"
#include "linear_elastic.hpp"
#include "modified_cam_clay.hpp"
#include "mohr_coulomb.hpp"
#include "varying.hpp"

namespace hmpm {

/// Which stress update a material uses after the elastic trial: one entry
/// per file of materials/ (the order is not significant).
enum class Model : std::uint8_t { linear_elastic, mohr_coulomb, drucker_prager, modified_cam_clay };

/// Whether the caller computes the elastic trial sigma_n + D_e deps with
/// the material's constant elasticity before the return (every model but
/// Modified Cam-Clay, whose pressure-dependent elasticity makes the trial
/// its own: it takes sigma_n and deps, modified_cam_clay.hpp).
constexpr bool elastic_trial_outside(Model m) {
  return m != Model::modified_cam_clay;
}

/// Number of per-particle internal state variables the model keeps (a
/// softening Mohr-Coulomb material keeps one more: see the overload on
/// MaterialConstants below).
constexpr int state_variable_count(Model m) {
  switch (m) {
    case Model::mohr_coulomb:
      return constitutive::MohrCoulombModel::state_variables;
    case Model::drucker_prager:
      return constitutive::DruckerPragerModel::state_variables;
    case Model::modified_cam_clay:
      return constitutive::ModifiedCamClayModel::state_variables;
    case Model::linear_elastic:
      break;
  }
  return constitutive::LinearElasticModel::state_variables;
}

/// One particle's internal state variables: variable k is arrays[k][p].
/// Models that declare none never touch it. `commit` false: the update
/// reads the state at the step's start and leaves it (the Newton
/// iterations of the quasi-static scheme); true: it writes the new state.
struct InternalState {
  std::vector<double>* arrays;
  std::size_t p;
  bool commit = true;
  double& operator[](int k) const { return arrays[k][p]; }
};

struct MaterialConstants {
  Model model = Model::linear_elastic;
  constitutive::Elastic elastic{0.0, 0.0};              ///< the trial's lambda and G
  constitutive::MohrCoulombConstants mohr_coulomb;      ///< used when model == mohr_coulomb
  constitutive::DruckerPragerConstants drucker_prager;  ///< used when model == drucker_prager
  constitutive::ModifiedCamClayConstants cam_clay;      ///< used when model == modified_cam_clay
  double lambda = 0.0;                                  ///< Lame's first parameter, Pa
  double shear_modulus = 0.0;                           ///< G, Pa
  double constrained_modulus = 0.0;                     ///< E(1-nu)/((1+nu)(1-2nu)), Pa
  double mixture_density = 0.0;                         ///< kg/m^3
  bool saturated = false;
  double porosity = 0.0;
  double storage = 0.0;              ///< Q = (1-n)/Ks + n/Kf, 1/Pa
  double undrained_p_modulus = 0.0;  ///< constrained modulus + 1/Q (saturated), Pa
  double fluid_density = 0.0;
  double permeability_over_gamma = 0.0;  ///< k / (rho_f g), m^3 s / kg
  double darcy_inertia_density = 0.0;    ///< rho_f, or 0 when Darcy's rho_f a is dropped
};

/// Number of per-particle internal state variables material `c` keeps.
inline int state_variable_count(const MaterialConstants& c) {
  if (c.model == Model::mohr_coulomb && c.mohr_coulomb.softens)
    return constitutive::MohrCoulombModel::softening_state_variables;
  return state_variable_count(c.model);
}

inline MaterialConstants material_constants(const Material& m, double gravity_constant) {
  MaterialConstants c;
  const double E = m.youngs_modulus, nu = m.poisson_ratio;
  c.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  c.shear_modulus = E / (2 * (1 + nu));
  c.constrained_modulus = c.lambda + 2 * c.shear_modulus;
  c.mixture_density = m.density;
  c.undrained_p_modulus = c.constrained_modulus;
  c.elastic = {c.lambda, c.shear_modulus};
  std::visit(
      [&c, nu](const auto& model) {
        using T = std::decay_t<decltype(model)>;
        if constexpr (std::is_same_v<T, MohrCoulomb>) {
          c.model = Model::mohr_coulomb;
          c.mohr_coulomb = constitutive::make_mohr_coulomb(model);
        } else if constexpr (std::is_same_v<T, DruckerPrager>) {
          c.model = Model::drucker_prager;
          c.drucker_prager = constitutive::make_drucker_prager(model);
        } else if constexpr (std::is_same_v<T, ModifiedCamClay>) {
          c.model = Model::modified_cam_clay;
          c.cam_clay = constitutive::make_modified_cam_clay(model, nu);
        }
      },
      m.plasticity);
  if (m.hydraulic) {
    const Hydraulic& h = *m.hydraulic;
    c.saturated = true;
    c.porosity = h.porosity;
    c.fluid_density = h.fluid_density;
    c.mixture_density = (1 - h.porosity) * m.density + h.porosity * h.fluid_density;
    const double solid_term =
        std::isinf(h.solid_bulk_modulus) ? 0.0 : (1 - h.porosity) / h.solid_bulk_modulus;
    c.storage = solid_term + h.porosity / h.fluid_bulk_modulus;
    c.undrained_p_modulus += 1.0 / c.storage;
    c.permeability_over_gamma = h.hydraulic_conductivity / (h.fluid_density * gravity_constant);
    c.darcy_inertia_density = h.darcy_inertia ? h.fluid_density : 0.0;
  }
  return c;
}

/// Modified Cam-Clay's update of particle state `state` (material.hpp's
/// slots 0 e, 1 p'c): sig holds sigma_n on entry; the new state is written
/// when state.commit.
inline double update_cam_clay(constitutive::Voigt& sig, const constitutive::Voigt& de,
                              const MaterialConstants& mc, InternalState state,
                              constitutive::Tangent* d_alg) {
  using M = constitutive::ModifiedCamClayModel;
  double e = state[M::void_ratio_slot], pc = state[M::preconsolidation_slot];
  const double plastic = constitutive::update_modified_cam_clay(sig, de, mc.cam_clay, e, pc, d_alg);
  if (state.commit) {
    state[M::void_ratio_slot] = e;
    state[M::preconsolidation_slot] = pc;
  }
  return plastic;
}

/// Mohr-Coulomb's return for particle p's constants `mc` (softening ones
/// read and, when state.commit, write its softening strain).
inline double update_mohr_coulomb(constitutive::Voigt& sig, const constitutive::Elastic& el,
                                  const constitutive::MohrCoulombConstants& mc, InternalState state,
                                  constitutive::Tangent* d_alg) {
  if (!mc.softens)
    return d_alg ? constitutive::return_mohr_coulomb_with_tangent(sig, el, mc, *d_alg)
                 : constitutive::return_mohr_coulomb(sig, el, mc);
  using M = constitutive::MohrCoulombModel;
  double kappa = state[M::softening_slot];
  const double plastic = constitutive::return_mohr_coulomb_softening(sig, el, mc, kappa, d_alg);
  if (state.commit) state[M::softening_slot] = kappa;
  return plastic;
}

/// Plastic correction of the elastic trial stress (effective stress, so dry
/// and saturated alike): the closed-form return mapping of the material's
/// model; linear-elastic materials in a run with plastic ones pass through.
/// `state` is the particle's internal state variables (materials/ models
/// that declare none ignore it). Returns ||d eps_p|| (the Frobenius norm of
/// the plastic strain increment, tensor components), 0 when elastic.
/// For particle p, whose parameters may vary (materials/varying.hpp): `el`
/// is the elasticity of its trial, and its strength constants are its own
/// where `varying` has them. `de` is the step's strain increment (tensor
/// components): for a model whose trial is its own
/// (!elastic_trial_outside(mc.model): Modified Cam-Clay) `sig` holds sigma_n
/// on entry, not the trial, and the update takes de; the others ignore it.
inline double return_to_yield_surface(constitutive::Voigt& sig,
                                      [[maybe_unused]] const constitutive::Voigt& de,
                                      const MaterialConstants& mc, const constitutive::Elastic& el,
                                      const VaryingConstants& varying, std::size_t p,
                                      [[maybe_unused]] InternalState state) {
  switch (mc.model) {
    case Model::mohr_coulomb:
      return update_mohr_coulomb(
          sig, el, varying.mohr_coulomb.empty() ? mc.mohr_coulomb : varying.mohr_coulomb[p], state,
          nullptr);
    case Model::drucker_prager:
      return constitutive::return_drucker_prager(
          sig, el, varying.drucker_prager.empty() ? mc.drucker_prager : varying.drucker_prager[p]);
    case Model::modified_cam_clay:
      return update_cam_clay(sig, de, mc, state, nullptr);
    case Model::linear_elastic:
      break;
  }
  return 0.0;
}

/// Particle p's elasticity: its own where E varies, else its material's.
inline const constitutive::Elastic& elastic_of(const MaterialConstants& mc,
                                               const VaryingConstants& varying, std::size_t p) {
  return varying.elastic.empty() ? mc.elastic : varying.elastic[p];
}

/// Particle p's k / (rho_f g): its own where k varies, else its material's.
inline double permeability_of(const MaterialConstants& mc, const VaryingConstants& varying,
                              std::size_t p) {
  return varying.permeability_over_gamma.empty() ? mc.permeability_over_gamma
                                                 : varying.permeability_over_gamma[p];
}

/// The same for a material's own constants (a homogeneous material).
inline double return_to_yield_surface(constitutive::Voigt& sig, const constitutive::Voigt& de,
                                      const MaterialConstants& mc, InternalState state) {
  static const VaryingConstants homogeneous;
  return return_to_yield_surface(sig, de, mc, mc.elastic, homogeneous, 0, state);
}

/// The same for a model whose trial is outside (sig: the trial; no de).
inline double return_to_yield_surface(constitutive::Voigt& sig, const MaterialConstants& mc,
                                      InternalState state) {
  return return_to_yield_surface(sig, constitutive::Voigt::Zero(), mc, state);
}

/// The increment of the accumulated equivalent plastic strain,
/// sqrt(2/3 deps_p : deps_p), from ||d eps_p|| (the returns' report): the
/// usual measure, equal to the axial plastic strain of an isochoric
/// uniaxial plastic flow.
inline double equivalent_plastic_strain(double plastic_norm) {
  return 0.816496580927726 * plastic_norm;  // sqrt(2/3)
}

/// The material's elastic tangent d sigma / d eps (Voigt xx yy zz xy yz zx,
/// tensor shear strains: 2G on the shear diagonal; materials/elastic.hpp).
inline constitutive::Tangent elastic_tangent(const MaterialConstants& mc) {
  return constitutive::elastic_tangent(mc.elastic);
}

/// return_to_yield_surface with the algorithmic (consistent) tangent, for
/// Newton iterations of the implicit schemes. `sig` holds the elastic trial
/// sigma_n + D_e (eps_{n+1} - eps_n) on entry and the returned stress on exit
/// (bit for bit return_to_yield_surface's); `d_alg` receives
/// d sigma_{n+1} / d eps_{n+1} in the convention of elastic_tangent (the
/// elastic tangent for linear-elastic materials and elastic steps; for
/// Modified Cam-Clay, whose sig is sigma_n on entry and takes de as in
/// return_to_yield_surface, its pressure-dependent elastic tangent).
/// Returns ||d eps_p||, 0 when the step was elastic. Not for hot loops of
/// the explicit scheme: it costs a spectral derivative per plastic point.
inline double return_with_tangent(constitutive::Voigt& sig, const MaterialConstants& mc,
                                  InternalState state, constitutive::Tangent& d_alg);

/// return_with_tangent for particle p, whose parameters may vary (as
/// return_to_yield_surface above).
inline double return_with_tangent(constitutive::Voigt& sig,
                                  [[maybe_unused]] const constitutive::Voigt& de,
                                  const MaterialConstants& mc, const constitutive::Elastic& el,
                                  const VaryingConstants& varying, std::size_t p,
                                  [[maybe_unused]] InternalState state,
                                  constitutive::Tangent& d_alg) {
  switch (mc.model) {
    case Model::mohr_coulomb:
      return update_mohr_coulomb(
          sig, el, varying.mohr_coulomb.empty() ? mc.mohr_coulomb : varying.mohr_coulomb[p], state,
          &d_alg);
    case Model::drucker_prager:
      return constitutive::return_drucker_prager_with_tangent(
          sig, el, varying.drucker_prager.empty() ? mc.drucker_prager : varying.drucker_prager[p],
          d_alg);
    case Model::modified_cam_clay:
      return update_cam_clay(sig, de, mc, state, &d_alg);
    case Model::linear_elastic:
      break;
  }
  d_alg = constitutive::elastic_tangent(el);
  return 0.0;
}

inline double return_with_tangent(constitutive::Voigt& sig, const constitutive::Voigt& de,
                                  const MaterialConstants& mc, InternalState state,
                                  constitutive::Tangent& d_alg) {
  static const VaryingConstants homogeneous;
  return return_with_tangent(sig, de, mc, mc.elastic, homogeneous, 0, state, d_alg);
}

inline double return_with_tangent(constitutive::Voigt& sig, const MaterialConstants& mc,
                                  InternalState state, constitutive::Tangent& d_alg) {
  return return_with_tangent(sig, constitutive::Voigt::Zero(), mc, state, d_alg);
}

/// The u-p equations with Darcy's rho_f a term are not dissipative: one
/// Fourier mode of the 1D equations has the characteristic polynomial
///   rho Q s^3 + rho k' q^2 s^2 + q^2 (E Q + 1) s + E k q^4,
/// (k = k/gamma_w, k' = k (1 - rho_f/rho), E the constrained modulus), and
/// Routh-Hurwitz makes every mode grow when E Q > (rho - rho_f)/rho_f, for
/// any wavenumber and any permeability > 0. This returns
/// E Q rho_f / (rho - rho_f): above 1 the material is in that regime
/// (infinity when the grains are not denser than the fluid), 0 when the
/// term is dropped or nothing flows.
inline double darcy_inertia_growth_ratio(const MaterialConstants& c) {
  if (!c.saturated || c.darcy_inertia_density <= 0.0 || c.permeability_over_gamma <= 0.0)
    return 0.0;
  const double buoyant = c.mixture_density - c.fluid_density;
  if (buoyant <= 0.0) return std::numeric_limits<double>::infinity();
  return c.constrained_modulus * c.storage * c.fluid_density / buoyant;
}

}  // namespace hmpm
