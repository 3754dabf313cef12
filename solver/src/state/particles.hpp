// state/particles.hpp — the particle state as a structure of arrays (internal).
//
// Particles carry everything that survives a step (the grid, state/grid.hpp,
// is scratch space cleared every step). Fixed-size Eigen types, one
// std::vector per field, all sized once at set-up: nothing here allocates
// during the time loop. Arrays of the fluid phase are empty when no material
// is saturated; the internal state variables of the soil models
// (materials/material.hpp) are one array per variable, none when no model
// of the run declares any.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "materials/varying.hpp"

namespace hmpm {

template <int Dim>
using VecD = Eigen::Matrix<double, Dim, 1>;
/// Symmetric tensor in Voigt order xx, yy, zz, xy, yz, zx (tensor components,
/// not engineering shear strains).
using Voigt = Eigen::Matrix<double, 6, 1>;

template <int Dim>
struct ParticleState {
  using Vec = VecD<Dim>;
  std::vector<Vec> x;   ///< position, m
  std::vector<Vec> x0;  ///< initial position, m (displacement = x - x0; not touched by the step)
  std::vector<Vec> v;   ///< velocity, m/s
  std::vector<double> mass;    ///< kg (per unit area in 1D, per unit thickness in 2D); constant
  std::vector<double> volume;  ///< current volume, m^3 (per unit area / thickness)
  std::vector<Voigt> stress;   ///< effective stress sigma', Pa, compression negative
  std::vector<Voigt> strain;   ///< small-strain accumulation, tensor components
  std::vector<std::uint16_t> material;
  /// Per axis, the cell the particle's stencil is anchored to (Shape::locate),
  /// set by the step's first phase and reused by the later ones of the same
  /// step (particles move in the last).
  std::vector<std::array<std::int32_t, Dim>> cell;
  std::vector<double> half_length;  ///< GIMP particle half-length in cell units; empty otherwise
  /// GIMP: 1 / (2 half_length), so the stencil multiplies instead of
  /// dividing (a division per axis and pass was 15 % of a 2D GIMP step);
  /// empty otherwise.
  std::vector<double> box_inverse;

  // Fluid phase (empty when dry).
  std::vector<double> pressure;      ///< transported pore pressure state, Pa (FLIP increments)
  std::vector<double> pressure_out;  ///< pore pressure interpolated from the nodal field, Pa
  std::vector<double> porosity;      ///< n
  std::vector<Vec> darcy;            ///< Darcy velocity w, m/s

  /// Accumulated equivalent plastic strain, sum over steps of
  /// sqrt(2/3 deps_p : deps_p) (equivalent_plastic_strain in
  /// materials/material.hpp); empty when no material is plastic.
  std::vector<double> plastic_strain;

  /// Internal state variables of the soil models: internal[k][p] is
  /// variable k of particle p (its meaning is the particle's model's).
  /// As many arrays as the most any model with particles declares.
  std::vector<std::vector<double>> internal;

  /// Material parameters that vary from particle to particle (random
  /// fields; materials/varying.hpp): arrays only for what some material
  /// varies, none in a homogeneous run.
  VaryingConstants varying;

  /// Staged jobs whose stages add or remove bodies: each particle's index
  /// in the job's numbering (the contract's), as particles come and go;
  /// empty otherwise.
  std::vector<std::int64_t> id;

  std::size_t size() const { return x.size(); }

  /// f(array of states[0], array of states[1], ...) for every array above,
  /// the same array of each state together, in a fixed order (the
  /// checkpoint writes and reads the whole particle state through it, the
  /// stages move particles between states with it: a new array belongs
  /// here too). The states must have as many internal arrays.
  template <class F, class... States>
  static void for_each_array_of(F&& f, States&... states) {
    f(states.x...);
    f(states.x0...);
    f(states.v...);
    f(states.mass...);
    f(states.volume...);
    f(states.stress...);
    f(states.strain...);
    f(states.material...);
    f(states.cell...);
    f(states.half_length...);
    f(states.box_inverse...);
    f(states.pressure...);
    f(states.pressure_out...);
    f(states.porosity...);
    f(states.darcy...);
    f(states.plastic_strain...);
    f(states.id...);
    for (int k = 0; k < material_parameter_count; ++k)
      f(states.varying.value[static_cast<std::size_t>(k)]...);
    f(states.varying.elastic...);
    f(states.varying.mohr_coulomb...);
    f(states.varying.drucker_prager...);
    f(states.varying.permeability_over_gamma...);
    const std::size_t internals = std::min({states.internal.size()...});
    for (std::size_t k = 0; k < internals; ++k) f(states.internal[k]...);
  }

  template <class F>
  void for_each_array(F&& f) {
    for_each_array_of(f, *this);
  }

  /// Moves the particles p with leaves(p) to the end of `to` (in order),
  /// closing the gaps here (the others keep their order). Arrays this
  /// state does not use (empty) stay empty in both.
  template <class Pred>
  void move_to(ParticleState& to, Pred&& leaves) {
    const std::size_t n = size();
    std::vector<std::uint8_t> go(n);
    for (std::size_t p = 0; p < n; ++p) go[p] = leaves(p) ? 1 : 0;
    for_each_array_of(
        [&](auto& from, auto& into) {
          if (from.size() != n || n == 0) return;
          std::size_t kept = 0;
          for (std::size_t p = 0; p < n; ++p) {
            if (go[p])
              into.push_back(from[p]);
            else
              from[kept++] = from[p];
          }
          from.resize(kept);
        },
        *this, to);
  }

  void resize(std::size_t n, bool fluid, bool gimp, int state_variables = 0, bool plastic = false) {
    internal.assign(static_cast<std::size_t>(state_variables), std::vector<double>(n, 0.0));
    if (plastic) plastic_strain.assign(n, 0.0);
    x.resize(n);
    x0.resize(n);
    v.assign(n, Vec::Zero());
    mass.resize(n);
    volume.resize(n);
    stress.assign(n, Voigt::Zero());
    strain.assign(n, Voigt::Zero());
    material.resize(n);
    cell.resize(n);
    if (gimp) {
      half_length.resize(n);
      box_inverse.resize(n);
    }
    if (fluid) {
      pressure.assign(n, 0.0);
      pressure_out.assign(n, 0.0);
      porosity.assign(n, 0.0);
      darcy.assign(n, Vec::Zero());
    }
  }

  std::int64_t bytes() const {
    const std::size_t n = size();
    std::size_t per = sizeof(Vec) * 3 + sizeof(double) * 2 + sizeof(Voigt) * 2 +
                      sizeof(std::uint16_t) + sizeof(std::array<std::int32_t, Dim>);
    if (!half_length.empty()) per += 2 * sizeof(double);
    if (!pressure.empty()) per += sizeof(double) * 3 + sizeof(Vec);
    per += sizeof(double) * internal.size();
    if (!plastic_strain.empty()) per += sizeof(double);
    if (!id.empty()) per += sizeof(std::int64_t);
    for (const std::vector<double>& v : varying.value)
      if (!v.empty()) per += sizeof(double);
    if (!varying.elastic.empty()) per += sizeof(constitutive::Elastic);
    if (!varying.mohr_coulomb.empty()) per += sizeof(constitutive::MohrCoulombConstants);
    if (!varying.drucker_prager.empty()) per += sizeof(constitutive::DruckerPragerConstants);
    if (!varying.permeability_over_gamma.empty()) per += sizeof(double);
    return static_cast<std::int64_t>(n * per);
  }
};

}  // namespace hmpm
