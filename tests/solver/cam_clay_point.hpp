// A material-point driver for Modified Cam-Clay (test_cam_clay.cpp,
// test_cam_clay_tangent.cpp): one particle's stress and state through the
// solver's dispatch (return_with_tangent with its InternalState slots),
// each step strain-controlled in some Voigt components and
// stress-controlled in the others, solved by Newton on the algorithmic
// tangent. Voigt xx yy zz xy yz zx, tensor shear strains, compression
// negative, Pa.
#pragma once

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <vector>

#include "../../solver/src/materials/material.hpp"

namespace cam_clay_test {

namespace cm = hmpm::constitutive;
using cm::Tangent;
using cm::Voigt;

/// The reference soil of the shared verification (section 14).
struct Soil {
  double lambda = 0.1, kappa = 0.03, m = 1.2, e0 = 1.0, poisson = 0.25, ocr = 1.0;
};

inline hmpm::MaterialConstants constants(const Soil& s) {
  hmpm::Material mat;
  mat.name = "clay";
  mat.density = 2000;
  mat.poisson_ratio = s.poisson;
  hmpm::ModifiedCamClay cc;
  cc.lambda = s.lambda;
  cc.kappa = s.kappa;
  cc.critical_state_ratio = s.m;
  cc.initial_void_ratio = s.e0;
  cc.overconsolidation_ratio = s.ocr;
  mat.plasticity = cc;
  return hmpm::material_constants(mat, 9.81);
}

inline Voigt isotropic(double p) {
  Voigt v = Voigt::Zero();
  v.head<3>().setConstant(-p);
  return v;
}

/// p (compression positive) and q of a stress.
inline double mean(const Voigt& s) {
  return -(s(0) + s(1) + s(2)) / 3.0;
}
inline double deviatoric(const Voigt& s) {
  const double p = -mean(s);
  const double dx = s(0) - p, dy = s(1) - p, dz = s(2) - p;
  return std::sqrt(1.5 * (dx * dx + dy * dy + dz * dz) + 3.0 * s.tail<3>().squaredNorm());
}

struct Point {
  hmpm::MaterialConstants mc;
  Voigt sigma;
  std::array<std::vector<double>, 2> slots{
      std::vector<double>{0.0}, std::vector<double>{0.0}};  ///< e, p'c (0: from e0 and OCR)
  Voigt eps = Voigt::Zero();
  double volumetric = 0.0;  ///< sum of -tr(de), the logarithmic volumetric strain

  double void_ratio() const { return slots[0][0]; }
  double preconsolidation() const { return slots[1][0]; }

  /// The update for increment de without committing it.
  Voigt trial(const Voigt& de, Tangent& d, double* plastic = nullptr) {
    Voigt s = sigma;
    const double r = hmpm::return_with_tangent(s, de, mc, {slots.data(), 0, false}, d);
    if (plastic) *plastic = r;
    return s;
  }

  /// One step: components with stress_controlled[i] reach target(i), the
  /// others take de(i). Returns the Newton iterations (or -1: no convergence).
  int step(const std::array<bool, 6>& stress_controlled, Voigt de, const Voigt& target,
           double tol = 1e-9) {
    std::vector<int> s;
    for (int i = 0; i < 6; ++i)
      if (stress_controlled[i]) s.push_back(i);
    const int n = static_cast<int>(s.size());
    Tangent d;
    int it = 0;
    for (; n > 0 && it < 60; ++it) {
      const Voigt sig = trial(de, d);
      Eigen::VectorXd r(n);
      Eigen::MatrixXd a(n, n);
      for (int i = 0; i < n; ++i) {
        r(i) = sig(s[i]) - target(s[i]);
        for (int j = 0; j < n; ++j) a(i, j) = d(s[i], s[j]);
      }
      if (r.cwiseAbs().maxCoeff() <= tol * (std::abs(mean(sig)) + 1.0)) break;
      const Eigen::VectorXd dx = a.partialPivLu().solve(-r);
      for (int i = 0; i < n; ++i) de(s[i]) += dx(i);
    }
    if (n > 0 && it == 60) return -1;
    hmpm::return_with_tangent(sigma, de, mc, {slots.data(), 0, true}, d);
    eps += de;
    volumetric -= de(0) + de(1) + de(2);
    return it;
  }
};

inline Point point(const Soil& s, double p0) {
  Point pt{constants(s), isotropic(p0)};
  return pt;
}

}  // namespace cam_clay_test
