// materials/elastic.hpp — linear isotropic elasticity shared by every soil model (internal).
//
// The explicit time step updates each particle's effective stress with an
// elastic predictor (the full strain increment through linear isotropic
// elasticity); a plastic model then brings the trial stress back onto its
// yield surface (one file per model beside this one: mohr_coulomb.hpp,
// drucker_prager.hpp; linear_elastic.hpp has no return). The helpers here
// are the elasticity the return mappings need in principal stress space.
//
// Conventions: stress as Voigt xx, yy, zz, xy, yz, zx (tensor components),
// Pa, compression negative (effective stress for saturated soils: the caller
// passes sigma' and adds the pore pressure itself). Principal stresses are
// ordered algebraically s1 >= s2 >= s3, so s3 is the most compressive.
//
// Each return function of a model reports ||d eps_p||, the Frobenius norm of
// the plastic strain increment. For a single smooth surface this is the
// plastic multiplier of the unit-normalised plastic potential; it is also
// the increment of the usual accumulated plastic strain, and 0 exactly when
// the step was elastic (the stress is then left bitwise untouched).
//
// Tangents (for the implicit schemes): each model also has a return that
// reports the algorithmic (consistent) tangent D_alg = d sigma_{n+1} /
// d eps_{n+1} of its stress update, a 6x6 `Tangent` in the same Voigt order.
// The strain columns are TENSOR strain components, as the explicit stress
// update uses them (de_xy = (dv_x/dy + dv_y/dx) dt / 2, sigma_xy += 2G de_xy):
// the elastic tangent's shear diagonal is 2G, not G. A column j of D_alg is
// the stress response to a unit change of the Voigt strain component j, the
// shear ones changing eps_ab and eps_ba together. An assembly written with
// engineering shear strains gamma = 2 eps uses D_alg with its shear columns
// (3..5) halved.
#pragma once

#include <Eigen/Core>

namespace hmpm::constitutive {

using Voigt = Eigen::Matrix<double, 6, 1>;
/// d sigma / d eps in Voigt xx, yy, zz, xy, yz, zx, tensor shear strains (see above).
using Tangent = Eigen::Matrix<double, 6, 6>;

/// Linear isotropic elasticity: Lame's lambda and the shear modulus G, Pa (G > 0).
struct Elastic {
  double lambda;
  double shear;
};

namespace detail {

constexpr double deg_to_rad = 3.14159265358979323846 / 180.0;

/// D b for the isotropic stiffness in principal space: lambda tr(b) 1 + 2G b.
inline Eigen::Vector3d stiffness_times(const Elastic& el, const Eigen::Vector3d& b) {
  return Eigen::Vector3d::Constant(el.lambda * b.sum()) + 2.0 * el.shear * b;
}

/// C^-1 x (compliance) in principal space: x/(2G) - lambda/(2G(3 lambda + 2G)) tr(x) 1.
inline Eigen::Vector3d compliance_times(const Elastic& el, const Eigen::Vector3d& x) {
  const double two_g = 2.0 * el.shear;
  return x / two_g -
         Eigen::Vector3d::Constant(el.lambda / (two_g * (3.0 * el.lambda + two_g)) * x.sum());
}

/// Voigt stress -> symmetric 3x3 tensor.
inline Eigen::Matrix3d to_tensor(const Voigt& v) {
  Eigen::Matrix3d m;
  m << v(0), v(3), v(5), v(3), v(1), v(4), v(5), v(4), v(2);
  return m;
}

}  // namespace detail

/// The elastic tangent in the convention above: lambda 1 (x) 1 + 2G I on the
/// normal block, 2G on the shear diagonal (tensor shear strains).
inline Tangent elastic_tangent(const Elastic& el) {
  Tangent d = Tangent::Zero();
  d.topLeftCorner<3, 3>().setConstant(el.lambda);
  d.diagonal().array() += 2.0 * el.shear;
  return d;
}

}  // namespace hmpm::constitutive
