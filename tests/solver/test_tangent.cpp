// The algorithmic (consistent) tangents of the soil models
// (solver/src/materials/: elastic_tangent, return_with_tangent and the
// models' *_with_tangent returns), for the Newton iterations of the
// implicit schemes.
//
//  * For each model and each region of its return (elastic; Drucker-Prager
//    cone, cut-off, corner, apex; Mohr-Coulomb main plane, both edges, apex,
//    the cut-off planes, lines and corners), at random stress states and
//    strain increments, D_alg agrees with a central finite difference of the
//    stress update eps -> return(sigma_n + D_e (eps - eps_n)).
//  * The stress returned is bit for bit the explicit scheme's return.
//  * A Newton solve of a mixed strain/stress-controlled material point
//    converges quadratically with D_alg (and only linearly with D_e, so the
//    assertion can fail).
// Voigt xx yy zz xy yz zx, tensor shear strains, compression negative, Pa.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "../../solver/src/materials/material.hpp"

namespace {

namespace cm = hmpm::constitutive;
using cm::Tangent;
using cm::Voigt;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double young = 1e7, poisson = 0.3;  // G = 3.85 MPa, K = 8.33 MPa
constexpr double stress_scale = 1e5;          // Pa: the stresses drawn below

hmpm::MaterialConstants constants(hmpm::Plasticity model) {
  hmpm::Material m;
  m.name = "soil";
  m.density = 2000;
  m.youngs_modulus = young;
  m.poisson_ratio = poisson;
  m.plasticity = std::move(model);
  return hmpm::material_constants(m, 9.81);
}

hmpm::InternalState no_state() {
  return {nullptr, 0};
}

/// The region a return takes, as a name: the test buckets samples by it and
/// checks the finite difference only where all perturbed points share it.
std::string region(const Voigt& trial, const hmpm::MaterialConstants& mc) {
  switch (mc.model) {
    case hmpm::Model::drucker_prager: {
      static const char* names[] = {"elastic", "cone", "cut-off", "corner", "apex"};
      return names[static_cast<int>(
          cm::drucker_prager_region(trial, mc.elastic, mc.drucker_prager))];
    }
    case hmpm::Model::mohr_coulomb: {
      Voigt s = trial;
      if (cm::return_mohr_coulomb(s, mc.elastic, mc.mohr_coulomb) == 0.0) return "elastic";
      Eigen::SelfAdjointEigenSolver<Matrix3d> eig;
      eig.computeDirect(cm::detail::to_tensor(trial));
      const Vector3d& ev = eig.eigenvalues();
      const Vector3d t(ev(2), ev(1), ev(0));
      const double scale = t.cwiseAbs().maxCoeff() + mc.mohr_coulomb.cohesion;
      cm::detail::ActiveSet a;
      cm::detail::mohr_coulomb_principal(t, mc.elastic, mc.mohr_coulomb, 1e-13 * scale, &a);
      if (a.fixed && a.count == 0) return "apex";
      std::string name = a.fixed ? "corner" : "planes";
      for (int i = 0; i < a.count; ++i) name += " " + std::to_string(a.planes[i]);
      return name;
    }
    case hmpm::Model::modified_cam_clay:  // test_cam_clay_tangent.cpp
    case hmpm::Model::linear_elastic:
      break;
  }
  return "elastic";
}

Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Voigt to_voigt(const Matrix3d& m) {
  Voigt v;
  v << m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(1, 2), m(0, 2);
  return v;
}

/// One stress update of a material point: sigma_n (admissible) and the
/// strain eps_n it was reached at; update(eps) is the returned stress.
struct Point {
  const hmpm::MaterialConstants* mc;
  Voigt sigma_n;
  Voigt eps_n;
  Voigt trial(const Voigt& eps) const {
    return sigma_n + cm::elastic_tangent(mc->elastic) * (eps - eps_n);
  }
  Voigt update(const Voigt& eps, Tangent* d = nullptr) const {
    Voigt s = trial(eps);
    Tangent local;
    hmpm::return_with_tangent(s, *mc, no_state(), d != nullptr ? *d : local);
    return s;
  }
};

/// Central difference of the stress update, column j = d sigma / d eps_j.
/// Returns false when a perturbed point leaves the region of `eps`.
bool finite_difference(const Point& pt, const Voigt& eps, double h, Tangent& fd) {
  const std::string r0 = region(pt.trial(eps), *pt.mc);
  for (int j = 0; j < 6; ++j) {
    Voigt ep = eps, em = eps;
    ep(j) += h;
    em(j) -= h;
    if (region(pt.trial(ep), *pt.mc) != r0 || region(pt.trial(em), *pt.mc) != r0) return false;
    fd.col(j) = (pt.update(ep) - pt.update(em)) / (2.0 * h);
  }
  return true;
}

/// Random admissible sigma_n (a random stress, returned) and strain
/// increment; the increment's size is log-uniform so that small and large
/// steps (far into the plastic regions, past edges and apexes) both occur.
Point random_point(const hmpm::MaterialConstants& mc, std::mt19937_64& rng, Voigt& eps) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), lg(-4.0, -1.7);
  const Matrix3d q = random_rotation(rng);
  const Vector3d s(u(rng) * stress_scale, u(rng) * stress_scale, u(rng) * stress_scale);
  Voigt sigma_n = to_voigt(q * s.asDiagonal() * q.transpose()) -
                  Voigt((Voigt() << 1, 1, 1, 0, 0, 0).finished()) * 0.5 * stress_scale;
  hmpm::return_to_yield_surface(sigma_n, mc, no_state());
  Point pt{&mc, sigma_n, Voigt::Zero()};
  const double size = std::pow(10.0, lg(rng));
  for (int i = 0; i < 6; ++i) eps(i) = size * u(rng);
  // Hydrostatic-heavy increments reach the apex and the cut-off corners.
  const double vol = size * u(rng);
  eps.head<3>().array() += vol;
  return pt;
}

struct Sampled {
  int checked = 0;
  double worst = 0.0;  ///< max |D_alg - D_fd| / max |D_e| over the region
};

/// Draws points until every region in `wanted` has `per_region` checked
/// samples (or the draws run out), asserting D_alg = D_fd to `tol` relative
/// to the elastic stiffness at each.
std::map<std::string, Sampled> check_tangent(const hmpm::MaterialConstants& mc,
                                             const std::vector<std::string>& wanted, int per_region,
                                             double tol, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::map<std::string, Sampled> out;
  const double d_scale = cm::elastic_tangent(mc.elastic).cwiseAbs().maxCoeff();
  // Strain perturbation: 1e-7 of the strain scale stress_scale / E = 1e-2.
  // Truncation: the update is smooth in a region with curvature on the
  // strain scale, so the central difference's error is ~(h / 1e-2)^2 =
  // 1e-14 of D; rounding: the stresses carry ~1e-15 stress_scale (the
  // closed-form eigen solver somewhat more), divided by 2h and by D ~ 1e7:
  // ~1e-15 * 1e5 / (2e-9 * 1e7) = 5e-9 (measured: up to 7e-8 on the
  // Mohr-Coulomb regions, from the eigenvectors). A wrong term of the
  // tangent is O(1) of D (or O(theta) ~ 1e-3 at least for the rotation
  // terms): the tolerance 1e-6 sits between.
  const double h = 1e-9;
  for (int draw = 0; draw < 200000; ++draw) {
    bool done = true;
    for (const std::string& w : wanted) done = done && out[w].checked >= per_region;
    if (done) break;
    Voigt eps;
    const Point pt = random_point(mc, rng, eps);
    const std::string r = region(pt.trial(eps), mc);
    if (out[r].checked >= per_region) continue;
    Tangent d, fd;
    const Voigt sig = pt.update(eps, &d);
    // The stress is bit for bit the explicit scheme's return.
    Voigt explicit_sig = pt.trial(eps);
    hmpm::return_to_yield_surface(explicit_sig, mc, no_state());
    for (int i = 0; i < 6; ++i) EXPECT_EQ(sig(i), explicit_sig(i)) << r;
    if (!finite_difference(pt, eps, h, fd)) continue;
    const double err = (d - fd).cwiseAbs().maxCoeff() / d_scale;
    EXPECT_LE(err, tol) << "region " << r << "\nD_alg\n" << d << "\nD_fd\n" << fd;
    out[r].checked++;
    out[r].worst = std::max(out[r].worst, err);
  }
  for (const auto& [name, s] : out)
    std::printf("  %-14s %4d samples, max |D_alg - D_fd| / max|D_e| = %.2e\n", name.c_str(),
                s.checked, s.worst);
  for (const std::string& w : wanted) EXPECT_GE(out[w].checked, per_region) << "region " << w;
  return out;
}

// Justification of the tolerance: see check_tangent (rounding ~5e-9,
// truncation ~1e-14, a wrong term O(1e-3) or more).
constexpr double fd_tol = 1e-6;
constexpr int per_region = 20;

TEST(Tangent, ElasticTangentIsTheStiffnessInTensorShearConvention) {
  const hmpm::MaterialConstants mc = constants(hmpm::LinearElastic{});
  const Tangent d = hmpm::elastic_tangent(mc);
  // Uniaxial strain: sigma_xx = (lambda + 2G) eps, sigma_yy = lambda eps;
  // tensor shear eps_xy gives sigma_xy = 2G eps_xy (the explicit update's
  // sig[3] += 2G de[3]).
  const double lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  const double g = young / (2 * (1 + poisson));
  EXPECT_DOUBLE_EQ(d(0, 0), lambda + 2 * g);
  EXPECT_DOUBLE_EQ(d(1, 0), lambda);
  EXPECT_DOUBLE_EQ(d(3, 3), 2 * g);
  EXPECT_EQ(d(3, 0), 0.0);
  EXPECT_EQ((d - d.transpose()).cwiseAbs().maxCoeff(), 0.0);
  std::printf("linear elastic:\n");
  const auto r = check_tangent(mc, {"elastic"}, per_region, fd_tol, 1);
  EXPECT_EQ(r.size(), 1u);
}

TEST(Tangent, DruckerPragerMatchesFiniteDifferencesInEveryRegion) {
  // Cut-off below the apex (p_t = 10 kPa < k / alpha = 34.6 kPa): cone,
  // cut-off and corner; non-associated and associated flow.
  for (double psi : {10.0, 30.0}) {
    std::printf("Drucker-Prager phi 30 psi %.0f c 20 kPa, cut-off 10 kPa:\n", psi);
    check_tangent(constants(hmpm::DruckerPrager{30.0, psi, 20e3, 10e3}),
                  {"elastic", "cone", "cut-off", "corner"}, per_region, fd_tol, 2);
  }
  // Cut-off at the apex (tensile strength above c cot phi): the apex.
  std::printf("Drucker-Prager phi 30 psi 5 c 20 kPa, cut-off at the apex:\n");
  check_tangent(constants(hmpm::DruckerPrager{30.0, 5.0, 20e3, 1e9}), {"elastic", "cone", "apex"},
                per_region, fd_tol, 3);
}

// With tensor shear strains the Voigt matrix is D = C diag(1,1,1,2,2,2)
// for the tensor C (sigma_xy = ... + 2 C_xyxy eps_xy), so the symmetry of an
// associated return shows in D diag(1,1,1,1/2,1/2,1/2), the engineering-
// shear form an assembly with gamma = 2 eps uses.
TEST(Tangent, DruckerPragerTangentIsSymmetricForAssociatedFlow) {
  const hmpm::MaterialConstants mc = constants(hmpm::DruckerPrager{30.0, 30.0, 20e3, 10e3});
  std::mt19937_64 rng(4);
  int cone = 0;
  for (int i = 0; i < 2000 && cone < 20; ++i) {
    Voigt eps;
    const Point pt = random_point(mc, rng, eps);
    if (region(pt.trial(eps), mc) != "cone") continue;
    Tangent d;
    pt.update(eps, &d);
    d.rightCols<3>() *= 0.5;
    // Symmetric to rounding (entries ~1e7 Pa, ~1e-16 relative each).
    EXPECT_LE((d - d.transpose()).cwiseAbs().maxCoeff(), 1e-12 * d.cwiseAbs().maxCoeff());
    ++cone;
  }
  EXPECT_EQ(cone, 20);
  // The non-associated tangent is not: the test can tell.
  const hmpm::MaterialConstants na = constants(hmpm::DruckerPrager{30.0, 10.0, 20e3, 10e3});
  for (int i = 0; i < 2000; ++i) {
    Voigt eps;
    const Point pt = random_point(na, rng, eps);
    if (region(pt.trial(eps), na) != "cone") continue;
    Tangent d;
    pt.update(eps, &d);
    d.rightCols<3>() *= 0.5;
    EXPECT_GT((d - d.transpose()).cwiseAbs().maxCoeff(), 1e-3 * d.cwiseAbs().maxCoeff());
    break;
  }
}

TEST(Tangent, MohrCoulombMatchesFiniteDifferencesInEveryRegion) {
  // Cut-off at the apex: main plane (planes 0), triaxial compression edge
  // (0 1), triaxial extension edge (0 2), apex.
  for (double psi : {10.0, 30.0}) {
    std::printf("Mohr-Coulomb phi 30 psi %.0f c 20 kPa, cut-off at the apex:\n", psi);
    check_tangent(constants(hmpm::MohrCoulomb{30.0, psi, 20e3, 1e9}),
                  {"elastic", "planes 0", "planes 0 1", "planes 0 2", "apex"}, per_region, fd_tol,
                  5);
  }
  // Cut-off at 10 kPa below the apex (34.6 kPa): the cut-off plane
  // s1 = sigma_t (3), its line with the main plane (0 3), the line
  // s1 = s2 = sigma_t (3 4), the corner on the extension edge (0 2 3) and
  // the cut-off apex, beside the Mohr-Coulomb regions.
  for (double psi : {10.0, 30.0}) {
    std::printf("Mohr-Coulomb phi 30 psi %.0f c 20 kPa, cut-off 10 kPa:\n", psi);
    check_tangent(constants(hmpm::MohrCoulomb{30.0, psi, 20e3, 10e3}),
                  {"elastic", "planes 0", "planes 0 1", "planes 0 2", "planes 3", "planes 0 3",
                   "planes 3 4", "corner 0 2 3", "corner 0 3 4", "corner 0 1 3", "corner 3 4 5"},
                  per_region, fd_tol, 6);
  }
  // Tresca (phi = 0, no apex): the plane and both edges.
  std::printf("Tresca c 20 kPa:\n");
  check_tangent(constants(hmpm::MohrCoulomb{0.0, 0.0, 20e3, 0.0}),
                {"elastic", "planes 0", "planes 0 1", "planes 0 2"}, per_region, fd_tol, 7);
}

// Trials with two equal principal stresses (an axisymmetric strain from an
// isotropic state, as in a triaxial test): the eigenvectors
// in the tied plane are arbitrary and the spectral terms take their limits.
// The finite differences (whose shear perturbations split the tie) still
// agree, on the compression edge (axial compression), the extension edge
// (axial extension) and the Drucker-Prager cone.
TEST(Tangent, TiedPrincipalStressesMatchFiniteDifferences) {
  struct Case {
    hmpm::Plasticity model;
    double sigma0;   ///< isotropic sigma_n, Pa
    double axial;    ///< axial strain increment
    bool isochoric;  ///< lateral -axial/2 (triaxial shear), else uniaxial strain
    const char* region;
    double h = 1e-9;  ///< the strain perturbation
    double tol = fd_tol;
  };
  const hmpm::Plasticity mc{hmpm::MohrCoulomb{30.0, 10.0, 5e3, 0.0}};
  const hmpm::Plasticity mc_cut{hmpm::MohrCoulomb{30.0, 10.0, 20e3, 10e3}};
  const hmpm::Plasticity dp{hmpm::DruckerPrager{30.0, 10.0, 5e3, 0.0}};
  const Case cases[] = {
      {mc, -100e3, -4e-2, true, "planes 0 1"},  // compression edge, s1 = s2
      {mc, -100e3, -2e-2, true, "planes 0 1"},
      {mc, -100e3, 1e-2, true, "planes 0 2"},  // extension edge, s2 = s3
      {mc, -100e3, 3e-2, true, "planes 0 2"},
      // Uniaxial tension past the cut-off: s1 = sigma_t, the tied s2 = s3
      // are free (their theta is 1, not 0). Here the return does not tie
      // s2 = s3, so the closed-form eigen solver's error at a double root,
      // ~sqrt(eps) |sigma| ~ 3e-4 Pa, reaches the returned stress and the
      // finite difference: with h = 1e-6 it is ~3e-4 / (2e-6 * 1.4e7) = 1e-5
      // of D (truncation (1e-6 / 1e-2)^2 = 1e-8), hence 1e-4; theta = 0
      // instead of 1 would be an error of 0.5.
      {mc_cut, -20e3, 3e-3, false, "planes 3", 1e-6, 1e-4},
      {dp, -100e3, -4e-2, true, "cone"},
      {dp, -100e3, -2e-2, true, "cone"},
      {dp, -100e3, 1e-2, true, "cone"},
      {dp, -100e3, 3e-2, true, "cone"},
  };
  for (const Case& c : cases) {
    const hmpm::MaterialConstants m = constants(c.model);
    const double d_scale = cm::elastic_tangent(m.elastic).cwiseAbs().maxCoeff();
    for (int axis = 0; axis < 3; ++axis) {
      Point pt{&m, Voigt::Zero(), Voigt::Zero()};
      pt.sigma_n.head<3>().setConstant(c.sigma0);
      Voigt eps = Voigt::Zero();
      if (c.isochoric) eps.head<3>().setConstant(-0.5 * c.axial);
      eps(axis) = c.axial;
      const std::string r = region(pt.trial(eps), m);
      EXPECT_EQ(r, c.region);
      Tangent d, fd;
      pt.update(eps, &d);
      ASSERT_TRUE(finite_difference(pt, eps, c.h, fd)) << r;
      const double err = (d - fd).cwiseAbs().maxCoeff() / d_scale;
      EXPECT_LE(err, c.tol) << r << "\n" << d << "\n" << fd;
      std::printf("  strain %+.0e along %d: %-11s |D_alg - D_fd| / max|D_e| = %.2e\n", c.axial,
                  axis, r.c_str(), err);
    }
  }
}

/// A material point under mixed control: eps_xx and eps_xy prescribed
/// (compression with shear, so the principal axes rotate), sigma_yy,
/// sigma_zz, sigma_yz and sigma_zx held at their initial values. Each load
/// step solves R(u) = sigma_k(eps(u)) - sigma_bar_k = 0 for the free strains
/// u = (eps_yy, eps_zz, eps_yz, eps_zx) by Newton with the Jacobian
/// K = D[k][k] (k = 1, 2, 4, 5) from `tangent` (D_alg or D_e). Returns the
/// residual norms of every step's iterations.
std::vector<std::vector<double>> newton_path(const hmpm::MaterialConstants& mc, bool consistent,
                                             int steps, double dstrain) {
  static constexpr int free_idx[4] = {1, 2, 4, 5};
  Voigt sigma_n;
  sigma_n << -100e3, -80e3, -120e3, 0, 0, 0;
  const Voigt sigma_bar = sigma_n;
  Voigt eps_n = Voigt::Zero();
  std::vector<std::vector<double>> history;
  for (int step = 0; step < steps; ++step) {
    Point pt{&mc, sigma_n, eps_n};
    Voigt eps = eps_n;
    eps(0) -= dstrain;
    eps(3) += 0.5 * dstrain;
    std::vector<double> res;
    Voigt sig;
    for (int it = 0; it < 60; ++it) {
      Tangent d;
      sig = pt.update(eps, &d);
      if (!consistent) d = hmpm::elastic_tangent(mc);
      Eigen::Vector4d r;
      Eigen::Matrix4d k;
      for (int a = 0; a < 4; ++a) {
        r(a) = sig(free_idx[a]) - sigma_bar(free_idx[a]);
        for (int b = 0; b < 4; ++b) k(a, b) = d(free_idx[a], free_idx[b]);
      }
      res.push_back(r.norm());
      if (r.norm() <= 1e-9 * stress_scale) break;  // 1e-4 Pa: ~1e5 above rounding
      const Eigen::Vector4d du = k.partialPivLu().solve(-r);
      for (int a = 0; a < 4; ++a) eps(free_idx[a]) += du(a);
    }
    history.push_back(res);
    sigma_n = sig;
    eps_n = eps;
  }
  return history;
}

/// Checks quadratic convergence: every plastic step converges, and each
/// iteration with r_k in the asymptotic range (below 1e-2 of the stress
/// scale, above 1e-6 Pa where rounding, ~1e-10 Pa, is still far) satisfies
/// r_{k+1} <= C r_k^2 / stress_scale. A linearly converging iteration has
/// r_{k+1} / r_k = const, which violates the bound as r_k -> 0. Returns the
/// largest observed r_{k+1} stress_scale / r_k^2, the most iterations and
/// how many iterations were in the asymptotic range.
struct Convergence {
  double worst = 0.0;
  int most = 0;
  int checked = 0;
};
Convergence quadratic_constant(const std::vector<std::vector<double>>& history) {
  double worst = 0.0;
  int most = 0, checked = 0;
  for (const auto& res : history) {
    most = std::max(most, static_cast<int>(res.size()));
    for (std::size_t k = 0; k + 1 < res.size(); ++k) {
      if (res[k] > 1e-2 * stress_scale || res[k] < 1e-6) continue;
      worst = std::max(worst, res[k + 1] * stress_scale / (res[k] * res[k]));
      ++checked;
    }
  }
  return {worst, most, checked};
}

void expect_quadratic(const hmpm::MaterialConstants& mc, const char* name) {
  const auto with_d_alg = newton_path(mc, true, 30, 1e-3);
  const auto [c, iters, checked] = quadratic_constant(with_d_alg);
  int plastic_steps = 0;
  for (const auto& res : with_d_alg) {
    EXPECT_LE(res.back(), 1e-9 * stress_scale) << name << ": a step did not converge";
    plastic_steps += res.size() > 2;
  }
  const auto with_d_e = newton_path(mc, false, 30, 1e-3);
  const auto [c_e, iters_e, checked_e] = quadratic_constant(with_d_e);
  std::printf(
      "%s: D_alg max r_{k+1} s / r_k^2 = %.3g over %d iterations, at most %d per step; "
      "D_e: %.3g over %d, %d per step; %d steps with > 1 Newton correction\n",
      name, c, checked, iters, c_e, checked_e, iters_e, plastic_steps);
  // The path yields (the test would be vacuous in the elastic range, where
  // one iteration solves the linear problem exactly).
  EXPECT_GE(plastic_steps, 10) << name;
  EXPECT_GE(checked, 10) << name;  // the bound is not checked vacuously
  // C: for the quadratic bound r_{k+1} <= C r_k^2 / s; a constant of order
  // 1..100 for these curvatures (the return's curvature is 1 / stress scale
  // in stress). The modified Newton with D_e must violate it (its ratio
  // r_{k+1}/r_k is fixed, so r_{k+1} s / r_k^2 grows as r_k shrinks).
  EXPECT_LE(c, 100.0) << name;
  EXPECT_LE(iters, 6) << name;
  EXPECT_GT(c_e, 100.0) << name;
}

TEST(Tangent, NewtonConvergesQuadraticallyWithTheConsistentTangent) {
  expect_quadratic(constants(hmpm::DruckerPrager{30.0, 10.0, 5e3, 0.0}), "Drucker-Prager");
  expect_quadratic(constants(hmpm::MohrCoulomb{30.0, 10.0, 5e3, 0.0}), "Mohr-Coulomb");
}

// Drained triaxial compression, strain-driven: eps_xx prescribed in steps,
// the cell pressure sigma_yy = sigma_zz = sigma_0 held by solving for the
// lateral strain u = eps_yy = eps_zz (the axisymmetric unknown: on the
// Mohr-Coulomb compression edge the two lateral stresses are tied, so the
// 2x2 lateral block of D_alg is singular and only their sum is
// determined). Newton with D_alg: K = D_yy,yy + D_yy,zz. The axial stress
// must reach the closed-form peak and stay there; each step converges in
// a few iterations (the return is affine along this axisymmetric path).
TEST(Tangent, NewtonTriaxialCompressionReachesThePeak) {
  const double s0 = -100e3, c = 5e3, phi = 30.0 * 3.14159265358979323846 / 180.0;
  const double sp = std::sin(phi), cp = std::cos(phi);
  // Mohr-Coulomb: (1 + sin phi) s0 - (1 - sin phi) sa = 2 c cos phi.
  const double mc_peak = ((1 + sp) * s0 - 2 * c * cp) / (1 - sp);
  // Drucker-Prager: (s0 - sa)/sqrt(3) + alpha (sa + 2 s0)/3 = k.
  const double tp = std::tan(phi), root = std::sqrt(9.0 + 12.0 * tp * tp);
  const double alpha = 3.0 * tp / root, k = 3.0 * c / root;
  const double dp_peak =
      (k - s0 * (1.0 / std::sqrt(3.0) + 2.0 * alpha / 3.0)) / (alpha / 3.0 - 1.0 / std::sqrt(3.0));
  const std::pair<hmpm::Plasticity, double> cases[] = {
      {hmpm::MohrCoulomb{30.0, 10.0, c, 0.0}, mc_peak},
      {hmpm::DruckerPrager{30.0, 10.0, c, 0.0}, dp_peak}};
  for (const auto& [model, peak] : cases) {
    const hmpm::MaterialConstants mc = constants(model);
    Voigt sigma_n = Voigt::Zero(), eps_n = Voigt::Zero();
    sigma_n.head<3>().setConstant(s0);
    int most = 0;
    for (int step = 0; step < 40; ++step) {
      Point pt{&mc, sigma_n, eps_n};
      Voigt eps = eps_n;
      eps(0) -= 1e-3;
      Voigt sig;
      int it = 0;
      for (; it < 20; ++it) {
        Tangent d;
        sig = pt.update(eps, &d);
        const double r = sig(1) - s0;
        if (std::abs(r) <= 1e-9 * stress_scale) break;
        eps(1) -= r / (d(1, 1) + d(1, 2));
        eps(2) = eps(1);
      }
      most = std::max(most, it + 1);
      EXPECT_LE(std::abs(sig(2) - s0), 1e-9 * stress_scale);
      sigma_n = sig;
      eps_n = eps;
    }
    // The path (40e-3 axial strain, the elastic limit is near 1e-2) ends on
    // the peak: perfectly plastic, to the Newton tolerance.
    std::printf(
        "triaxial: axial stress %.6e Pa, closed-form peak %.6e Pa, at most %d evaluations\n",
        sigma_n(0), peak, most);
    EXPECT_NEAR(sigma_n(0), peak, 1e-6 * std::abs(peak));
    EXPECT_LE(most, 4);
  }
}

}  // namespace
