// Modified Cam-Clay at a material point against the closed forms of the
// shared verification (docs/verification.md, section 14), in 3D:
// lambda = 0.1, kappa = 0.03, M = 1.2, nu = 0.25, p'0 = 200 kPa, e0 = 1.
//  * isotropic compression p'0 -> 2 p'0 on the NCL: e = e0 - lambda ln 2;
//    unloading back along the URL: + kappa ln 2;
//  * undrained triaxial compression (NC): p'/p'0 = (M^2/(M^2+eta^2))^Lambda
//    along the whole path, Lambda = (lambda-kappa)/lambda; critical state
//    p'f = p'0 2^-Lambda, qf = M p'f, excess pore pressure p'0 + qf/3 - p'f;
//  * drained triaxial compression (cell pressure held): qf = 3 M p'0/(3-M),
//    volumetric strain (e0 - e)/(1 + e0) at critical state from the NCL/URL;
//  * OCR 2 and 8 (drained and undrained) end on the critical state line;
//  * the error of a drained path falls with the strain increment.
// The driver (cam_clay_point.hpp) goes through the solver's dispatch.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cam_clay_point.hpp"

namespace {

using cam_clay_test::deviatoric;
using cam_clay_test::mean;
using cam_clay_test::Point;
using cam_clay_test::Soil;
using cam_clay_test::Voigt;

constexpr double p0 = 200e3;
const std::array<bool, 6> normal_stresses{true, true, true, false, false, false};
const std::array<bool, 6> lateral_stresses{true, true, false, false, false, false};
const std::array<bool, 6> strains{false, false, false, false, false, false};

TEST(CamClay, IsotropicCompressionFollowsTheNclAndUnloadingTheUrl) {
  const Soil soil;
  Point pt = cam_clay_test::point(soil, p0);
  const int n = 50;
  for (int k = 1; k <= n; ++k)
    ASSERT_GE(pt.step(normal_stresses, Voigt::Zero(),
                      cam_clay_test::isotropic(p0 * std::pow(2.0, double(k) / n))),
              0);
  const double e_loaded = soil.e0 - soil.lambda * std::log(2.0);
  std::printf("isotropic 200 -> 400 kPa: e = %.9f, closed form %.9f, p'c = %.6g\n", pt.void_ratio(),
              e_loaded, pt.preconsolidation());
  EXPECT_NEAR(pt.void_ratio(), e_loaded, 1e-3 * e_loaded);
  EXPECT_NEAR(pt.void_ratio(), e_loaded, 1e-9);  // exact on the NCL at any step
  EXPECT_NEAR(pt.preconsolidation(), 2 * p0, 1e-6 * p0);
  for (int k = 1; k <= n; ++k)
    ASSERT_GE(pt.step(normal_stresses, Voigt::Zero(),
                      cam_clay_test::isotropic(2 * p0 * std::pow(0.5, double(k) / n))),
              0);
  const double e_unloaded = e_loaded + soil.kappa * std::log(2.0);
  std::printf("unloaded to 200 kPa: e = %.9f, closed form %.9f\n", pt.void_ratio(), e_unloaded);
  EXPECT_NEAR(pt.void_ratio(), e_unloaded, 1e-3 * e_unloaded);
  EXPECT_NEAR(pt.void_ratio(), e_unloaded, 1e-9);
  EXPECT_NEAR(pt.preconsolidation(), 2 * p0, 1e-6 * p0);  // elastic: p'c kept
}

/// Undrained triaxial compression: isochoric, axial strain -de per step.
void undrained_path(Point& pt, double de, double axial) {
  const Voigt step = (Voigt() << de / 2, de / 2, -de, 0, 0, 0).finished();
  for (double a = 0; a < axial; a += de) ASSERT_GE(pt.step(strains, step, Voigt::Zero()), 0);
}

TEST(CamClay, UndrainedTriaxialFollowsTheClosedFormToTheCriticalState) {
  const Soil soil;
  Point pt = cam_clay_test::point(soil, p0);
  const double big_lambda = (soil.lambda - soil.kappa) / soil.lambda, m2 = soil.m * soil.m;
  const double de = 1e-4;
  const Voigt step = (Voigt() << de / 2, de / 2, -de, 0, 0, 0).finished();
  double worst = 0.0;
  for (int k = 0; k < 3000; ++k) {  // to 30 % axial strain
    ASSERT_GE(pt.step(strains, step, Voigt::Zero()), 0);
    const double p = mean(pt.sigma), eta = deviatoric(pt.sigma) / p;
    const double closed = p0 * std::pow(m2 / (m2 + eta * eta), big_lambda);
    worst = std::max(worst, std::abs(p - closed));
  }
  const double p = mean(pt.sigma), q = deviatoric(pt.sigma);
  const double pf = p0 * std::pow(2.0, -big_lambda), qf = soil.m * pf;
  const double du = p0 + q / 3 - p, duf = p0 + qf / 3 - pf;
  std::printf(
      "undrained: worst |p' - closed form| %.3g Pa (%.2g of p'0); at 30 %%: p' %.2f kPa "
      "(%.2f), q %.2f kPa (%.2f), du %.2f kPa (%.2f), e %.9f\n",
      worst, worst / p0, p / 1e3, pf / 1e3, q / 1e3, qf / 1e3, du / 1e3, duf / 1e3,
      pt.void_ratio());
  EXPECT_LT(worst, 5e-3 * p0);
  EXPECT_NEAR(pf, 123.11e3, 10.0);  // the brief's numbers
  EXPECT_NEAR(qf, 147.74e3, 10.0);
  EXPECT_NEAR(duf, 126.13e3, 10.0);
  EXPECT_NEAR(p, pf, 1e-2 * pf);
  EXPECT_NEAR(q, qf, 1e-2 * qf);
  EXPECT_NEAR(du, duf, 1e-2 * duf);
  EXPECT_NEAR(pt.void_ratio(), soil.e0, 1e-12);  // no volume change
}

/// Drained triaxial compression, cell pressure p0 held: axial strain -de
/// per step until `axial`.
void drained_path(Point& pt, double de, double axial) {
  const Voigt step = (Voigt() << 0, 0, -de, 0, 0, 0).finished();
  const int n = static_cast<int>(std::lround(axial / de));
  for (int k = 0; k < n; ++k)
    ASSERT_GE(pt.step(lateral_stresses, step, cam_clay_test::isotropic(p0)), 0);
}

TEST(CamClay, DrainedTriaxialReachesTheCriticalStateOfTheClosedForm) {
  const Soil soil;
  Point pt = cam_clay_test::point(soil, p0);
  drained_path(pt, 2e-4, 1.0);
  const double p = mean(pt.sigma), q = deviatoric(pt.sigma);
  const double qf = 3 * soil.m * p0 / (3 - soil.m), pf = qf / soil.m;
  // e on the URL through the critical state's yield surface (p'c = 2 p'f).
  const double ef =
      soil.e0 - soil.kappa * std::log(pf / p0) - (soil.lambda - soil.kappa) * std::log(2 * pf / p0);
  const double ev = (soil.e0 - pt.void_ratio()) / (1 + soil.e0),
               evf = (soil.e0 - ef) / (1 + soil.e0);
  const double ev_strain = 1 - std::exp(-pt.volumetric);  // dV/V0 from the strain path
  std::printf(
      "drained at 100 %% axial: q %.2f kPa (%.2f), p' %.2f kPa, q - 3(p'-p'0) %.3g Pa, "
      "eps_v (e) %.4f %% (%.4f %%), eps_v (strain) %.4f %%\n",
      q / 1e3, qf / 1e3, p / 1e3, q - 3 * (p - p0), 100 * ev, 100 * evf, 100 * ev_strain);
  EXPECT_NEAR(qf, 400e3, 1e-9 * qf);
  EXPECT_NEAR(evf, 0.0498, 1e-4);
  EXPECT_NEAR(q, qf, 1e-2 * qf);
  EXPECT_NEAR(q, 3 * (p - p0), 1e-6 * p0);  // the stress path of the test
  EXPECT_NEAR(ev, evf, 1e-2 * evf);
  EXPECT_NEAR(ev_strain, evf, 1e-2 * evf);
}

TEST(CamClay, OverconsolidatedSamplesReachTheCriticalStateLine) {
  for (const double ocr : {2.0, 8.0}) {
    Soil soil;
    soil.ocr = ocr;
    Point drained = cam_clay_test::point(soil, p0);
    drained_path(drained, 2e-4, 1.0);
    Point undrained = cam_clay_test::point(soil, p0);
    undrained_path(undrained, 1e-4, 0.6);
    const double eta_d = deviatoric(drained.sigma) / mean(drained.sigma);
    const double eta_u = deviatoric(undrained.sigma) / mean(undrained.sigma);
    std::printf("OCR %g: q/p' drained %.5f, undrained %.5f (M = %.2f); p'c %.4g, %.4g kPa\n", ocr,
                eta_d, eta_u, soil.m, drained.preconsolidation() / 1e3,
                undrained.preconsolidation() / 1e3);
    EXPECT_NEAR(eta_d, soil.m, 1e-2 * soil.m) << "OCR " << ocr;
    EXPECT_NEAR(eta_u, soil.m, 1e-2 * soil.m) << "OCR " << ocr;
    // On the critical state line the yield surface is at p'c = 2 p'.
    EXPECT_NEAR(drained.preconsolidation(), 2 * mean(drained.sigma), 2e-2 * mean(drained.sigma));
  }
}

TEST(CamClay, ErrorFallsWithTheStrainIncrement) {
  // Drained NC path to 4 % axial strain (hardening, far from the critical
  // state), against a path of 1e-6 increments.
  const Soil soil;
  auto q_at = [&](double de) {
    Point pt = cam_clay_test::point(soil, p0);
    drained_path(pt, de, 0.04);
    return deviatoric(pt.sigma);
  };
  const double reference = q_at(1e-6);
  double previous = 1e300;
  for (const double de : {4e-3, 1e-3, 2.5e-4}) {
    const double err = std::abs(q_at(de) - reference);
    std::printf("drained q at 4 %%, increments %.2g: error %.4g Pa (%.2g of q)\n", de, err,
                err / reference);
    EXPECT_LT(err, 0.6 * previous) << "increment " << de;
    previous = err;
  }
  EXPECT_LT(previous, 5e-3 * reference);  // first order: 0.23 % at 2.5e-4
}

}  // namespace
