// Particle generation, numbering and the stable time step: set-up facts that
// every other test relies on, checked against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

// A material no body uses has no particles: its wave speed and diffusion
// limit must not shorten the step nor refuse a user dt (an unused hydraulic
// material used to refuse this job with its diffusion limit).
TEST(StableStep, OnlyMaterialsWithParticlesLimitTheStep) {
  hmpm::Problem p = bar_problem();
  hmpm::Material clay;
  clay.name = "unused clay";
  clay.density = 2000.0;
  clay.youngs_modulus = 1e6;
  hmpm::Hydraulic hy;
  hy.porosity = 0.4;
  hy.hydraulic_conductivity = 1e-2;
  clay.hydraulic = hy;
  p.materials.push_back(clay);
  const auto s = hmpm::stable_step(p);
  EXPECT_NEAR(s.mechanical, (1.0 / 13.0) / std::sqrt(10.0), 1e-15);
  EXPECT_TRUE(std::isinf(s.hydraulic));
  EXPECT_NEAR(s.wave_speed, std::sqrt(10.0), 1e-12);
  p.time.dt = 0.02;  // below the bar's limit 0.0243 s
  const auto issues = hmpm::check_problem(p);
  EXPECT_TRUE(issues.empty()) << issues.front().where.text() << ": " << issues.front().message;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_EQ(r.dt, 0.02);
}

TEST(StableStep, UserStepAboveLimitIsRefusedWithTheLimit) {
  hmpm::Problem p = bar_problem();
  p.time.dt = 0.1;
  const auto issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.parts, (std::vector<std::string>{"time", "dt"}));
  EXPECT_NE(issues[0].message.find("0.02433"), std::string::npos) << issues[0].message;
}

// A damping schedule (local_damping as a function of t) acts exactly while
// it is non-zero: a free body falling under g = 1 m/s^2 with alpha = 0.5 for
// t < 0.5 s and 0 afterwards reaches v = g (0.5 (1 - alpha) + 0.5) = 0.75
// m/s at t = 1 s (every node carries the same force, so Cundall damping
// removes alpha |f| from each). Tolerance: the first step of each phase
// sees the sign of the previous velocity (0 at t = 0), one step of g alpha dt.
TEST(LocalDamping, ScheduleActsOnlyWhileNonZero) {
  hmpm::Problem p = bar_problem();
  p.gravity = {-1.0, 0.0, 0.0};
  p.grid.min = {-1.0, 0.0, 0.0};  // room to fall 0.4 m
  p.grid.cells = {26, 1, 1};
  p.time.dt = 0.01;
  p.output.snapshot_interval = 1.0;
  p.output.snapshot_fields = {hmpm::Field::velocity};
  double v_end = 0.0;
  hmpm::RunOptions opt;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) { v_end = s.velocity[0]; };
  const double alpha = 0.5;
  p.local_damping = [alpha](double t) { return t < 0.5 ? alpha : 0.0; };
  const hmpm::RunResult r = hmpm::run(p, opt);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_NEAR(v_end, -(0.5 * (1 - alpha) + 0.5), alpha * 0.01 + 1e-12);
}

// A schedule that leaves [0, 1) fails the run at that step, without naming
// a particle (it is not a particle's failure).
TEST(LocalDamping, ScheduleOutOfRangeFailsTheRun) {
  hmpm::Problem p = bar_problem();
  p.time.dt = 0.01;
  p.local_damping = [](double t) { return t < 0.5 ? 0.1 : 1.0; };
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  EXPECT_NE(r.message.find("local_damping is 1 at t = 0.5"), std::string::npos) << r.message;
  EXPECT_EQ(r.message.find("particle"), std::string::npos) << r.message;
  EXPECT_NEAR(r.end_time, 0.51, 1e-12);
}

}  // namespace
