// Particle generation, numbering and the stable time step: set-up facts that
// every other test relies on, checked against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>

#include "hmpm/run.hpp"

namespace {

hmpm::Problem bar_problem() {
  hmpm::Problem p;
  p.dimension = 1;
  p.grid.min = {0, 0, 0};
  p.grid.max = {1, 0, 0};
  p.grid.cells = {13, 1, 1};
  hmpm::Material m;
  m.name = "bar";
  m.density = 1.0;
  m.youngs_modulus = 10.0;
  p.materials.push_back(m);
  hmpm::Body b;
  b.box.max = {1, 0, 0};
  b.particles_per_cell = 1;
  p.bodies.push_back(b);
  p.time.end = 1.0;
  return p;
}

TEST(Layout, BarHasOneParticlePerCellAtCellCentres) {
  const hmpm::Problem p = bar_problem();
  const auto x = hmpm::initial_positions(p);
  ASSERT_EQ(x.size(), 13u);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i][0], (i + 0.5) / 13.0, 1e-15);
}

TEST(Layout, NumberingIsXFastestThenY) {
  hmpm::Problem p = bar_problem();
  p.dimension = 2;
  p.grid.max = {2, 1, 0};
  p.grid.cells = {2, 1, 1};
  p.bodies[0].box.max = {2, 1, 0};
  p.bodies[0].particles_per_cell = 2;
  const auto x = hmpm::initial_positions(p);
  ASSERT_EQ(x.size(), 8u);  // 2 cells x (2 x 2) particles
  EXPECT_DOUBLE_EQ(x[0][0], 0.25);
  EXPECT_DOUBLE_EQ(x[1][0], 0.75);
  EXPECT_DOUBLE_EQ(x[3][0], 1.75);
  EXPECT_DOUBLE_EQ(x[3][1], 0.25);
  EXPECT_DOUBLE_EQ(x[4][1], 0.75);
  EXPECT_EQ(hmpm::nearest_particle(p, {1.7, 0.8, 0}), 7);
}

TEST(StableStep, DryBarIsCellOverWaveSpeed) {
  const hmpm::Problem p = bar_problem();
  const auto s = hmpm::stable_step(p);
  EXPECT_NEAR(s.mechanical, (1.0 / 13.0) / std::sqrt(10.0), 1e-15);
  EXPECT_TRUE(std::isinf(s.hydraulic));
  EXPECT_NEAR(s.chosen, 0.5 * s.limit, 1e-18);
}

TEST(StableStep, UserStepAboveLimitIsRefusedWithTheLimit) {
  hmpm::Problem p = bar_problem();
  p.time.dt = 0.1;
  const auto issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where, "time/dt");
  EXPECT_NE(issues[0].message.find("0.02433"), std::string::npos) << issues[0].message;
}

}  // namespace
