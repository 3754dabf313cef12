// materials/varying.hpp — material parameters that vary from particle to
// particle (random fields; Material::varying): the per-particle constants
// the step reads, and the values set-up, the checks and the stable-step
// rules take from the fields (internal; varying.cpp).
//
// The homogeneous path costs nothing: a per-particle array exists only for
// what some material varies (none at all in a homogeneous run), and a phase
// asks "is there an array?" once per particle, on a pointer it read before
// its loop, then reads either the particle's entry or its material's
// constants (materials/material.hpp), the same numbers for a homogeneous
// material, so results are bit for bit those of before. Derived constants
// are computed once, at set-up: Lame's constants when E varies (no
// division in the step), the whole Mohr-Coulomb or Drucker-Prager
// constants when c or phi varies (their planes need sin and cos), k/gamma_w
// when the conductivity varies.
//
// Every array is sized for every particle of the run (a particle of a
// homogeneous material holds its material's values), so a phase indexes by
// the particle alone; they belong to ParticleState::for_each_array_of, so
// stages move them with their particles and checkpoints keep them.
//
// A new varying parameter: its MaterialParameter (problem.hpp) and output
// field (fields.hpp), parameter_of/set_parameter/parameter_applies here,
// what it derives in the set-up (Simulation::setup_varying, setup.hpp) and
// the phases that read it. Cam-Clay's p'c is the initial value of its
// state variable (ParticleState::internal): initialise_cam_clay_state
// (cam_clay_state.hpp) writes the particle's value there instead of
// deriving a constant.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "drucker_prager.hpp"
#include "elastic.hpp"
#include "hmpm/problem.hpp"
#include "mohr_coulomb.hpp"

namespace hmpm {

struct BodyLayout;

/// Per-particle constants of the parameters that vary; each array empty
/// when no material varies what it derives from.
struct VaryingConstants {
  /// The parameter's value at each particle (MaterialParameter order), for
  /// output: empty unless some material varies it.
  std::array<std::vector<double>, material_parameter_count> value;
  std::vector<constitutive::Elastic> elastic;  ///< lambda, G: when E varies
  /// When c or phi varies in a Mohr-Coulomb material (entries of particles
  /// of other models unused).
  std::vector<constitutive::MohrCoulombConstants> mohr_coulomb;
  /// When c or phi varies in a Drucker-Prager material.
  std::vector<constitutive::DruckerPragerConstants> drucker_prager;
  std::vector<double> permeability_over_gamma;  ///< k / (rho_f g): when k varies
};

/// The material parameter whose value a field is (is_material_parameter_field;
/// p'c's field is Cam-Clay's state, not one of these).
inline MaterialParameter parameter_of_field(Field f) {
  return static_cast<MaterialParameter>(static_cast<int>(f) -
                                        static_cast<int>(Field::youngs_modulus));
}

/// The contract's name of a parameter ("youngs_modulus", ...).
const char* parameter_name(MaterialParameter k);

/// The material's own value of the parameter (0 where it has none).
double parameter_of(const Material& m, MaterialParameter k);

/// Sets the material's value of the parameter (no effect where it has none).
void set_parameter(Material& m, MaterialParameter k, double value);

/// Whether the material has the parameter: E always, c and phi with a
/// Mohr-Coulomb or Drucker-Prager model, k with hydraulic, p'c with
/// Modified Cam-Clay.
bool parameter_applies(const Material& m, MaterialParameter k);

/// "must be > 0", ... when `value` is outside the parameter's range; empty
/// when acceptable.
std::string parameter_range_issue(MaterialParameter k, double value);

/// The values of material `material`'s varying parameters at its
/// particles: out[i] for m.varying[i], one per particle of the material's
/// bodies in the job's order (layouts: body_layouts(problem) with
/// positions). A random field is generated over all of them at once.
std::vector<std::vector<double>> varying_values(const Problem& problem, std::size_t material,
                                                const std::vector<BodyLayout>& layouts);

/// The materials with each varying parameter at the value that limits a
/// stable step most: the largest Young's modulus and hydraulic
/// conductivity any of its particles has (the materials as they are when
/// none varies; layouts computed only then).
std::vector<Material> limiting_materials(const Problem& problem);

}  // namespace hmpm
