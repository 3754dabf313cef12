// state.hpp — particle and grid state as structures of arrays (internal).
//
// Particles carry everything that survives a step; the grid is scratch space
// cleared every step. Fixed-size Eigen types, one std::vector per field, all
// sized once at set-up: nothing here allocates during the time loop.
// Arrays of the fluid phase are empty when no material is saturated.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace hmpm {

template <int Dim>
using VecD = Eigen::Matrix<double, Dim, 1>;
/// Symmetric tensor in Voigt order xx, yy, zz, xy, yz, zx (tensor components,
/// not engineering shear strains).
using Voigt = Eigen::Matrix<double, 6, 1>;

template <int Dim>
struct ParticleState {
  using Vec = VecD<Dim>;
  std::vector<Vec> x;         ///< position, m
  std::vector<Vec> x0;        ///< initial position, m (displacement = x - x0; not touched by the step)
  std::vector<Vec> v;         ///< velocity, m/s
  std::vector<double> mass;   ///< kg (per unit area in 1D, per unit thickness in 2D); constant
  std::vector<double> volume; ///< current volume, m^3 (per unit area / thickness)
  std::vector<Voigt> stress;  ///< effective stress sigma', Pa, compression negative
  std::vector<Voigt> strain;  ///< small-strain accumulation, tensor components
  std::vector<std::uint16_t> material;
  /// Per axis, the cell the particle's stencil is anchored to (Shape::locate),
  /// set by the step's first phase and reused by the later ones of the same
  /// step (particles move in the last).
  std::vector<std::array<std::int32_t, Dim>> cell;
  std::vector<double> half_length;  ///< GIMP particle half-length in cell units; empty otherwise

  // Fluid phase (empty when dry).
  std::vector<double> pressure;       ///< transported pore pressure state, Pa (FLIP increments)
  std::vector<double> pressure_out;   ///< pore pressure interpolated from the nodal field, Pa
  std::vector<double> porosity;       ///< n
  std::vector<Vec> darcy;             ///< Darcy velocity w, m/s

  std::size_t size() const { return x.size(); }

  void resize(std::size_t n, bool fluid, bool gimp) {
    x.resize(n); x0.resize(n); v.assign(n, Vec::Zero());
    mass.resize(n); volume.resize(n);
    stress.assign(n, Voigt::Zero()); strain.assign(n, Voigt::Zero());
    material.resize(n);
    cell.resize(n);
    if (gimp) half_length.resize(n);
    if (fluid) {
      pressure.assign(n, 0.0); pressure_out.assign(n, 0.0);
      porosity.assign(n, 0.0); darcy.assign(n, Vec::Zero());
    }
  }

  std::int64_t bytes() const {
    const std::size_t n = size();
    std::size_t per = sizeof(Vec) * 3 + sizeof(double) * 2 + sizeof(Voigt) * 2 + sizeof(std::uint16_t) +
                      sizeof(std::array<std::int32_t, Dim>);
    if (!half_length.empty()) per += sizeof(double);
    if (!pressure.empty()) per += sizeof(double) * 3 + sizeof(Vec);
    return static_cast<std::int64_t>(n * per);
  }
};

template <int Dim>
struct GridState {
  using Vec = VecD<Dim>;
  std::int64_t count = 0;
  int cells[Dim];
  std::int64_t stride[3] = {1, 1, 1};
  double origin[Dim];
  double h[Dim];
  double inv_h[Dim];

  std::vector<double> mass;    ///< m_i
  std::vector<Vec> momentum;   ///< m_i v_i at the start of the step
  std::vector<Vec> force;      ///< internal + external force
  std::vector<Vec> velocity;   ///< Lagrangian velocity after the momentum update
  std::vector<Vec> accel;      ///< (v^L - v^n) / dt, constrained components included
  std::vector<Vec> remap;      ///< momentum re-mapped from updated particle velocities (MUSL)

  // Fluid phase (empty when dry).
  std::vector<double> storage;   ///< s_i = sum N Q V
  std::vector<double> pressure;  ///< p_i at the start of the step (after boundary values)
  std::vector<double> flux;      ///< right-hand side of s_i dp_i/dt
  std::vector<double> dp;        ///< p_i^{n+1} - p_i^n

  Vec node_position(std::int64_t i) const {
    Vec x;
    std::int64_t r = i;
    for (int a = Dim - 1; a >= 0; --a) {
      const std::int64_t q = r / stride[a];
      r -= q * stride[a];
      x[a] = origin[a] + static_cast<double>(q) * h[a];
    }
    return x;
  }

  void resize(bool fluid) {
    const auto n = static_cast<std::size_t>(count);
    mass.assign(n, 0.0);
    momentum.assign(n, Vec::Zero()); force.assign(n, Vec::Zero());
    velocity.assign(n, Vec::Zero()); accel.assign(n, Vec::Zero()); remap.assign(n, Vec::Zero());
    if (fluid) {
      storage.assign(n, 0.0); pressure.assign(n, 0.0); flux.assign(n, 0.0); dp.assign(n, 0.0);
    }
  }

  std::int64_t bytes() const {
    std::size_t per = sizeof(double) + sizeof(Vec) * 5;
    if (!storage.empty()) per += sizeof(double) * 4;
    return static_cast<std::int64_t>(static_cast<std::size_t>(count) * per);
  }
};

}  // namespace hmpm
