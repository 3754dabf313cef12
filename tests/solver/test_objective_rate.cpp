// The Jaumann stress rate: the per-component form against the matrix form
// W sigma - sigma W, and a stress integrated under a steady spin against the
// exact rotation R sigma R^T (objectivity: a rigid rotation must rotate the
// stress, keep its invariants, and create none).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "../../solver/src/objective_rate.hpp"

namespace {

using Voigt = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d tensor(const Voigt& s) {
  Eigen::Matrix3d m;
  m << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
  return m;
}

TEST(ObjectiveRate, ComponentsMatchTheMatrixForm) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    Voigt s;
    for (int c = 0; c < 6; ++c) s[c] = 1e5 * u(gen);
    Eigen::Matrix3d l;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) l(i, j) = u(gen);
    const double dt = 1e-3;
    const Eigen::Matrix3d w = 0.5 * (l - l.transpose()) * dt;
    const Eigen::Matrix3d expected = tensor(s) + w * tensor(s) - tensor(s) * w;
    Voigt got = s;
    hmpm::rotate_jaumann<3>(got, l, dt);
    // Same arithmetic in another order: round-off of |sigma| = 1e5 only.
    EXPECT_LT((tensor(got) - expected).cwiseAbs().maxCoeff(), 1e-9);

    // The 2D form is the 3D form with a spin about z only.
    Eigen::Matrix3d lz = Eigen::Matrix3d::Zero();
    lz.topLeftCorner<2, 2>() = l.topLeftCorner<2, 2>();
    Voigt s2 = s, s3 = s;
    s2[4] = s2[5] = s3[4] = s3[5] = 0.0;  // plane strain: no out-of-plane shear
    hmpm::rotate_jaumann<2>(s2, Eigen::Matrix2d(l.topLeftCorner<2, 2>()), dt);
    hmpm::rotate_jaumann<3>(s3, lz, dt);
    EXPECT_LT((s2 - s3).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// A steady spin of angle theta = omega t about an arbitrary axis, integrated
// in n forward steps. Forward Euler on the rotation ODE has a global error of
// order theta * (omega dt) |sigma| (its amplification per step is
// 1 + O((omega dt)^2), accumulated over theta/(omega dt) steps plus the phase
// error); with omega dt = 1e-4 and theta = pi/2 that is about 1.6e-4, so
// 1e-3 |sigma| bounds it with margin, and halving dt must halve the error.
double rotation_error(int steps) {
  const double theta = M_PI / 2, omega = 2.0, dt = theta / omega / steps;
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 2.0, 2.0).normalized();
  // L = skew(omega * axis): the velocity gradient of v = omega axis x x.
  Eigen::Matrix3d l;
  const Eigen::Vector3d o = omega * axis;
  l << 0, -o.z(), o.y(), o.z(), 0, -o.x(), -o.y(), o.x(), 0;
  Voigt s;
  s << -100.0, -50.0, -20.0, 10.0, -5.0, 3.0;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(theta, axis).toRotationMatrix();
  const Eigen::Matrix3d exact = r * tensor(s) * r.transpose();
  for (int n = 0; n < steps; ++n) hmpm::rotate_jaumann<3>(s, l, dt);
  return (tensor(s) - exact).norm() / exact.norm();
}

TEST(ObjectiveRate, SteadySpinRotatesTheStress) {
  const double e1 = rotation_error(7854);  // omega dt = 1e-4
  const double e2 = rotation_error(2 * 7854);
  EXPECT_LT(e1, 1e-3);
  EXPECT_NEAR(e1 / e2, 2.0, 0.1);  // first order in dt, as forward Euler must be
}

}  // namespace
