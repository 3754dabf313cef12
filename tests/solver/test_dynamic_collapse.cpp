// Collapse detection in the schemes that follow the motion (explicit,
// semi_implicit; solver/src/collapse_watch.hpp, docs/job-spec.md
// "Collapse"), issue 44.
//
// A 2D column of dry sand (H0 = 1 m, half-width L0 = 0.5 m against a
// smooth symmetry plane, rough floor; Mohr-Coulomb phi = 35.26 deg, the
// plane-strain equivalent of 30 deg) under gravity, from its geostatic K0
// state:
// - cohesionless, it cannot stand (a vertical face of a frictional
//   material without cohesion has no statically admissible stress field):
//   it collapses, and the run must say so. It cannot say so before a
//   particle could have moved 10 % of the soil's height in free fall,
//   t >= sqrt(2 * 0.1 * H / g) with H the extent of the particle centres
//   (the height the watch measures; <= H0); a granular column of aspect
//   ratio 2 has spread over its height by about 2 sqrt(H0/g) (Lube et
//   al. 2005: the runout ends in about 3 sqrt(H0/g)), so the report must
//   come before 3 sqrt(H0/g).
// - with cohesion c = gamma H0 / tan(45 + phi/2), half of the lower-bound
//   critical height 2 c / gamma tan(45 + phi/2) of an unsupported vertical
//   face (the stress field sigma_v = gamma z, sigma_h = 0 is admissible and
//   nowhere beyond Mohr-Coulomb's surface up to that height) makes the
//   column stand with a factor of two on its height: nothing may be
//   reported, while the release of the geostatic stress at the free face
//   does yield a few particles (the watch is active and looking).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double g = 9.81;
constexpr double rho = 1800.0;
constexpr double h0 = 1.0, l0 = 0.5;
constexpr double cell = 0.05;

hmpm::Problem column(hmpm::Scheme scheme, double cohesion, hmpm::ShapeFunction shape,
                     int per_cell) {
  const double phi = std::asin(std::tan(30.0 * pi / 180.0)) * 180.0 / pi;
  hmpm::Problem p;
  p.dimension = 2;
  p.shape_function = shape;
  const int nx = 60, ny = 24;
  p.grid.max = {nx * cell, ny * cell, 0};
  p.grid.cells = {nx, ny, 1};
  hmpm::Material m;
  m.name = "sand";
  m.density = rho;
  m.youngs_modulus = rho * g * h0 / 1e-3;
  m.poisson_ratio = 0.3;
  m.plasticity = hmpm::MohrCoulomb{phi, 0.0, cohesion, 0.0};
  p.materials.push_back(m);
  hmpm::Body b;
  b.box.max = {l0, h0, 0};
  b.particles_per_cell = per_cell;
  const double k0 = 1.0 - std::sin(phi * pi / 180.0);
  for (int c = 0; c < 3; ++c) {
    const double k = c == 1 ? 1.0 : k0;
    b.initial.effective_stress[c] = [k](const hmpm::Vec3& x) { return -k * rho * g * (h0 - x[1]); };
  }
  p.bodies.push_back(b);
  p.gravity = {0, -g, 0};
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Boundary floor = problems::fixed_velocity(problems::plane(p, 1, 0.0), 1);
  floor.friction = std::numeric_limits<double>::infinity();
  p.boundaries.push_back(floor);
  p.time.scheme = scheme;
  p.time.end = 3.0 * std::sqrt(h0 / g);
  return p;
}

hmpm::RunResult run_one(const hmpm::Problem& p) {
  hmpm::RunOptions opt;
  opt.threads = 1;
  return hmpm::run(p, opt);
}

struct Case {
  hmpm::Scheme scheme;
  hmpm::ShapeFunction shape;
  int per_cell;
};

std::string name(const Case& c) {
  return std::string(c.scheme == hmpm::Scheme::explicit_scheme ? "explicit" : "semi_implicit") +
         (c.shape == hmpm::ShapeFunction::linear
              ? " linear"
              : (c.shape == hmpm::ShapeFunction::gimp ? " gimp" : " bspline")) +
         ", " + std::to_string(c.per_cell) + " per cell";
}

class DynamicCollapse : public ::testing::TestWithParam<Case> {};

TEST_P(DynamicCollapse, CohesionlessColumnIsReportedAfterFreeFallAndBeforeItSpreads) {
  const Case c = GetParam();
  hmpm::Problem p = column(c.scheme, 0.0, c.shape, c.per_cell);
  const hmpm::RunResult r = run_one(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << name(c) << ": " << r.message;
  ASSERT_TRUE(r.collapse.found) << name(c) << ": no collapse reported";
  EXPECT_EQ(r.collapse.criterion, "large_displacement");
  EXPECT_FALSE(r.collapse.stopped);  // the default of these schemes: go on
  const double spacing = cell / c.per_cell;
  const double height = h0 - spacing;  // the particle centres' extent
  EXPECT_GE(r.collapse.time, std::sqrt(2.0 * 0.1 * height / g)) << name(c);
  EXPECT_LE(r.collapse.time, 3.0 * std::sqrt(h0 / g)) << name(c);
  EXPECT_GT(r.collapse.max_displacement, 0.1 * height) << name(c);
  EXPECT_GT(r.collapse.yielding, 0) << name(c);
  // The status message and the warnings say so.
  EXPECT_NE(r.message.find("collapsed"), std::string::npos) << r.message;
  bool warned = false;
  for (const std::string& w : r.warnings)
    warned = warned || w.find("collapses") != std::string::npos;
  EXPECT_TRUE(warned) << name(c);
  EXPECT_NEAR(r.end_time, p.time.end, 1e-9);  // it went on to the end
}

TEST_P(DynamicCollapse, StopEndsTheRunThereWithTheReason) {
  const Case c = GetParam();
  hmpm::Problem p = column(c.scheme, 0.0, c.shape, c.per_cell);
  p.time.on_collapse = hmpm::CollapseAction::stop;
  const hmpm::RunResult r = run_one(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::failed) << name(c) << ": " << r.message;
  ASSERT_TRUE(r.collapse.found);
  EXPECT_TRUE(r.collapse.stopped);
  EXPECT_NE(r.message.find("the soil collapses"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("What to change"), std::string::npos) << r.message;
  EXPECT_NEAR(r.end_time, r.collapse.time, 1e-12);
  EXPECT_LT(r.end_time, p.time.end);
}

TEST_P(DynamicCollapse, ColumnWithCohesionStandsAndNothingIsReported) {
  const Case c = GetParam();
  const double phi = std::asin(std::tan(30.0 * pi / 180.0));
  const double cohesion = rho * g * h0 / std::tan(pi / 4 + phi / 2);
  hmpm::Problem p = column(c.scheme, cohesion, c.shape, c.per_cell);
  const hmpm::RunResult r = run_one(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << name(c) << ": " << r.message;
  EXPECT_FALSE(r.collapse.found) << name(c) << ": " << r.collapse.message;
}

INSTANTIATE_TEST_SUITE_P(
    Schemes, DynamicCollapse,
    ::testing::Values(Case{hmpm::Scheme::explicit_scheme, hmpm::ShapeFunction::linear, 2},
                      Case{hmpm::Scheme::explicit_scheme, hmpm::ShapeFunction::bspline, 1},
                      Case{hmpm::Scheme::semi_implicit, hmpm::ShapeFunction::gimp, 2}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string s = name(info.param);
      for (char& ch : s)
        if (ch == ' ' || ch == ',') ch = '_';
      return s;
    });

}  // namespace
