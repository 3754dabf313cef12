// Modified Cam-Clay's algorithmic tangent (return_with_tangent through the
// dispatch) against central finite differences of its stress update
// eps -> update(sigma_n, eps - eps_n; e_n, p'c_n), at random states and
// strain increments: elastic steps (the pressure-dependent elastic
// tangent), plastic steps on the wet side (hardening, p' > p'c/2) and on
// the dry side (softening, p' < p'c/2). Also: the explicit path
// (return_to_yield_surface) gives bit for bit the same stress and state,
// the zero and tensile mean stress give finite numbers, and a
// non-committing update leaves the state alone.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "cam_clay_point.hpp"

namespace {

using cam_clay_test::mean;
using cam_clay_test::Point;
using cam_clay_test::Soil;
using cam_clay_test::Tangent;
using cam_clay_test::Voigt;

enum class Side { elastic, wet, dry };

/// A random admissible state (sigma_n inside or on the yield surface of
/// p'c = 200 kPa, e_n in [0.6, 1.4]) and an increment that takes the
/// step to `side`.
struct Sample {
  Point pt;
  Voigt de;
};

bool make_sample(std::mt19937_64& rng, Side side, Sample& out) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  const Soil soil;
  const double pc = 200e3, m = soil.m;
  // sigma_n: p in (0.05, 1) pc, q within the ellipse, random deviatoric direction.
  const double p = side == Side::dry   ? (0.08 + 0.3 * u01(rng)) * pc
                   : side == Side::wet ? (0.55 + 0.4 * u01(rng)) * pc
                                       : (0.1 + 0.85 * u01(rng)) * pc;
  const double q_max = m * std::sqrt(std::max(p * (pc - p), 0.0));
  const double q = (side == Side::elastic ? 0.7 : 0.999) * u01(rng) * q_max;
  Voigt dir;
  for (int i = 0; i < 6; ++i) dir(i) = u(rng);
  const double tr = (dir(0) + dir(1) + dir(2)) / 3.0;
  dir.head<3>().array() -= tr;
  const double qd = cam_clay_test::deviatoric(dir);
  Voigt sigma = cam_clay_test::isotropic(p) + (q / qd) * dir;
  Sample s{cam_clay_test::point(soil, p), Voigt::Zero()};
  s.pt.sigma = sigma;
  s.pt.slots[0][0] = 0.6 + 0.8 * u01(rng);
  s.pt.slots[1][0] = pc;
  // The increment: size log-uniform; plastic samples push outward (the
  // normal direction plus noise), elastic ones are small and inward.
  const double size = std::pow(10.0, -5.0 + 2.5 * u01(rng));
  Voigt d;
  for (int i = 0; i < 6; ++i) d(i) = u(rng);
  if (side != Side::elastic) {
    // df/dsigma = (3/M^2) s - (2p - pc)/3 1 (compression negative).
    Voigt normal = (3.0 / (m * m)) * (q / qd) * dir;
    normal.head<3>().array() -= (2 * p - pc) / 3.0;
    d = normal.normalized() + 0.3 * d.normalized();
  } else {
    d *= 1e-2;
  }
  s.de = size * d.normalized();
  Tangent t;
  double plastic = 0.0;
  s.pt.trial(s.de, t, &plastic);
  if ((side == Side::elastic) != (plastic == 0.0)) return false;
  out = s;
  return true;
}

TEST(CamClayTangent, MatchesFiniteDifferencesElasticWetAndDry) {
  std::mt19937_64 rng(39);
  for (const Side side : {Side::elastic, Side::wet, Side::dry}) {
    int checked = 0;
    double worst = 0.0;
    for (int attempt = 0; attempt < 2000 && checked < 40; ++attempt) {
      Sample s;
      if (!make_sample(rng, side, s)) continue;
      Tangent d, scratch;
      double plastic = 0.0;
      s.pt.trial(s.de, d, &plastic);
      const double h = 1e-7 * std::max(s.de.norm(), 1e-5);
      Tangent fd;
      bool same = true;
      for (int j = 0; j < 6 && same; ++j) {
        Voigt ep = s.de, em = s.de;
        ep(j) += h;
        em(j) -= h;
        double rp = 0, rm = 0;
        const Voigt sp = s.pt.trial(ep, scratch, &rp), sm = s.pt.trial(em, scratch, &rm);
        same = (rp > 0) == (plastic > 0) && (rm > 0) == (plastic > 0);
        fd.col(j) = (sp - sm) / (2 * h);
      }
      if (!same) continue;
      ++checked;
      const double err = (d - fd).norm() / d.norm();
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-5) << "side " << static_cast<int>(side) << "\nD =\n"
                           << d << "\nFD =\n"
                           << fd;
    }
    std::printf("side %d: %d samples, worst |D - FD| / |D| = %.3g\n", static_cast<int>(side),
                checked, worst);
    EXPECT_GE(checked, 20) << "side " << static_cast<int>(side);
  }
}

TEST(CamClayTangent, ExplicitPathIsBitForBitAndTrialsLeaveTheState) {
  std::mt19937_64 rng(7);
  for (const Side side : {Side::elastic, Side::wet, Side::dry}) {
    Sample s;
    while (!make_sample(rng, side, s)) {
    }
    const double e = s.pt.slots[0][0], pc = s.pt.slots[1][0];
    Tangent d;
    const Voigt with_tangent = s.pt.trial(s.de, d);
    EXPECT_EQ(s.pt.slots[0][0], e);  // commit false: the state stays
    EXPECT_EQ(s.pt.slots[1][0], pc);
    Voigt sig = s.pt.sigma;
    hmpm::return_to_yield_surface(sig, s.de, s.pt.mc, {s.pt.slots.data(), 0, true});
    for (int i = 0; i < 6; ++i) EXPECT_EQ(sig(i), with_tangent(i));
    EXPECT_NE(s.pt.slots[0][0], e);  // committed: e follows the volume change
  }
}

TEST(CamClayTangent, ZeroAndTensileMeanStressStayFinite) {
  for (const double p : {0.0, -50e3}) {
    Point pt = cam_clay_test::point(Soil{}, p);
    pt.sigma(3) = 1e3;
    for (const Voigt& de : {Voigt((Voigt() << -1e-3, -1e-3, -1e-3, 0, 0, 0).finished()),
                            Voigt((Voigt() << 1e-3, 2e-3, -1e-3, 1e-3, 0, 0).finished())}) {
      Voigt sig = pt.sigma;
      std::array<std::vector<double>, 2> slots{std::vector<double>{0.0}, std::vector<double>{0.0}};
      Tangent d;
      hmpm::return_with_tangent(sig, de, pt.mc, {slots.data(), 0, true}, d);
      EXPECT_TRUE(sig.allFinite() && d.allFinite()) << sig.transpose();
      EXPECT_GT(mean(sig), 0.0);
      EXPECT_GT(slots[0][0], 0.0);
      EXPECT_GE(slots[1][0], hmpm::constitutive::mean_stress_floor);
    }
  }
}

}  // namespace
