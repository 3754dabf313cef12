// Modified Cam-Clay through a scheme: a dry 1D oedometer in the
// quasi-static scheme (Newton on the algorithmic tangent), 10 cells, from
// the isotropic NC state p'0 = 200 kPa to a vertical load of 4 p'0.
//  * Every particle keeps e + kappa ln(p'/p'0) + (lambda - kappa) ln(p'c/p'c0)
//    = e0 (the elastic and plastic volume laws together, exact per step):
//    the state is committed once per step, with the step's strain;
//  * the void ratio follows the volume the scheme gives:
//    (1 + e)/(1 + e0) = exp(eps_xx) (the accumulated strain);
//  * on the K0 normal compression line (the load's last doubling) e falls
//    by lambda per unit ln p';
//  * Newton converges in a few iterations per step (elastic points take the
//    model's pressure-dependent tangent too).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double p0 = 200e3, lambda = 0.1, kappa = 0.03, e0 = 1.0;

hmpm::RunResult oedometer() {
  hmpm::Problem p = problems::column(1, 0, 1.0, 10, 2);
  hmpm::Material m;
  m.name = "clay";
  m.density = 2000;
  m.youngs_modulus = 3 * 0.5 * 2 * p0 / kappa;  // the reference stiffness
  m.poisson_ratio = 0.25;
  hmpm::ModifiedCamClay cc;
  cc.lambda = lambda;
  cc.kappa = kappa;
  cc.critical_state_ratio = 1.2;
  cc.initial_void_ratio = e0;
  cc.overconsolidation_ratio = 1.0;
  m.plasticity = cc;
  p.materials.push_back(m);
  for (int c = 0; c < 3; ++c)
    p.bodies[0].initial.effective_stress[c] = [](const hmpm::Vec3&) { return -p0; };
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Traction t;
  t.particles.min = {1.0 - 0.05, 0, 0};
  t.particles.max = {1.0, 1, 1};
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [](double time) { return -p0 * (1.0 + 3.0 * std::min(1.0, time)); };
  p.tractions.push_back(t);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 1.0;
  p.time.dt = 0.02;
  p.time.implicit.max_iterations = 30;
  p.output.series_particles = {0, 5, 10, 15};  // below the loaded top cell
  p.output.series_fields = {hmpm::Field::effective_stress, hmpm::Field::strain,
                            hmpm::Field::void_ratio, hmpm::Field::preconsolidation_pressure};
  return hmpm::run(p);
}

TEST(CamClayScheme, QuasiStaticOedometerKeepsTheVolumeLawsAndTheNcl) {
  const hmpm::RunResult r = oedometer();
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size(), nt = s.time.size();
  ASSERT_GE(nt, 40u);
  auto at = [&](int field, std::size_t k, std::size_t i, int comps, int c) {
    return s.values[static_cast<std::size_t>(field)]
                   [(k * np + i) * static_cast<std::size_t>(comps) + static_cast<std::size_t>(c)];
  };
  auto mean = [&](std::size_t k, std::size_t i) {
    return -(at(0, k, i, 6, 0) + at(0, k, i, 6, 1) + at(0, k, i, 6, 2)) / 3.0;
  };
  double worst_law = 0, worst_volume = 0;
  for (std::size_t k = 1; k < nt; ++k)
    for (std::size_t i = 0; i < np; ++i) {
      const double e = at(2, k, i, 1, 0), pc = at(3, k, i, 1, 0), p = mean(k, i);
      const double law = e + kappa * std::log(p / p0) + (lambda - kappa) * std::log(pc / p0);
      worst_law = std::max(worst_law, std::abs(law - e0));
      const double volume = std::exp(at(1, k, i, 6, 0));
      worst_volume = std::max(worst_volume, std::abs((1 + e) / (1 + e0) - volume));
    }
  // The K0 NCL: the last half of the loading (2.5 p'0 -> 4 p'0 vertical).
  const std::size_t mid = nt / 2, last = nt - 1, i = 1;
  const double slope =
      -(at(2, last, i, 1, 0) - at(2, mid, i, 1, 0)) / std::log(mean(last, i) / mean(mid, i));
  const double k0 = at(0, last, i, 6, 1) / at(0, last, i, 6, 0);
  std::printf(
      "Cam-Clay oedometer (quasi-static): max |e + kappa ln p' + (lambda-kappa) ln p'c - "
      "e0| = %.3g, max |(1+e)/(1+e0) - exp(eps)| = %.3g; NCL slope %.5f (lambda %.2f), "
      "K0 %.4f, e %.5f, p' %.1f kPa; Newton: %lld iterations in %lld steps, at most %d\n",
      worst_law, worst_volume, slope, lambda, k0, at(2, last, i, 1, 0), mean(last, i) / 1e3,
      static_cast<long long>(r.iterations.nonlinear), static_cast<long long>(r.steps),
      r.iterations.max_nonlinear);
  for (std::size_t i = 0; i < np; ++i) {  // set-up: e0 and p'c = OCR p'0
    EXPECT_EQ(at(2, 0, i, 1, 0), e0);
    EXPECT_NEAR(at(3, 0, i, 1, 0), p0, 1e-9 * p0);
  }
  EXPECT_LT(worst_law, 1e-9);
  EXPECT_LT(worst_volume, 1e-3);
  EXPECT_NEAR(slope, lambda, 0.02 * lambda);
  EXPECT_LE(r.iterations.max_nonlinear, 8);
}

// The explicit scheme, p'c a function of position: set-up writes each
// particle's p'c from its initial position and e0 (the series at t = 0);
// the column under its initial stress stays at rest, elastic.
TEST(CamClayScheme, ExplicitColumnTakesPreconsolidationFromPosition) {
  hmpm::Problem p = problems::column(1, 0, 1.0, 10, 2);
  hmpm::Material m;
  m.name = "clay";
  m.density = 2000;
  m.youngs_modulus = 3 * 0.5 * 2 * 4e5 / kappa;  // at the largest p'c
  m.poisson_ratio = 0.25;
  hmpm::ModifiedCamClay cc;
  cc.lambda = lambda;
  cc.kappa = kappa;
  cc.initial_void_ratio = e0;
  cc.preconsolidation_pressure = [](const hmpm::Vec3& x) { return 3e5 + 1e5 * x[0]; };
  m.plasticity = cc;
  p.materials.push_back(m);
  for (int c = 0; c < 3; ++c)
    p.bodies[0].initial.effective_stress[c] = [](const hmpm::Vec3&) { return -p0; };
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Traction t;
  t.particles.min = {1.0 - 0.05, 0, 0};
  t.particles.max = {1.0, 1, 1};
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [](double) { return -p0; };
  p.tractions.push_back(t);
  p.time.end = 0.01;
  p.output.series_particles = {0, 9, 19};
  p.output.series_fields = {hmpm::Field::effective_stress, hmpm::Field::void_ratio,
                            hmpm::Field::preconsolidation_pressure};
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size(), last = s.time.size() - 1;
  for (std::size_t i = 0; i < np; ++i) {
    const double x0 = s.initial_positions[i][0];
    EXPECT_EQ(s.values[1][i], e0);
    EXPECT_NEAR(s.values[2][i], 3e5 + 1e5 * x0, 1e-6);
    EXPECT_NEAR(s.values[2][last * np + i], 3e5 + 1e5 * x0, 1e-6);  // elastic: kept
    EXPECT_NEAR(s.values[0][(last * np + i) * 6], -p0, 0.05 * p0);
    EXPECT_NEAR(s.values[1][last * np + i], e0, 1e-3);
  }
  std::printf("explicit Cam-Clay column: %lld steps, p'c %.0f .. %.0f Pa at t = 0\n",
              static_cast<long long>(r.steps), s.values[2][0], s.values[2][np - 1]);
}

// A stage that gives a body Cam-Clay: the particles' state starts from
// their stress at that moment (e0 and OCR x p'), after an elastic first
// stage loaded the oedometer to 2 p'0; the load then stays, so the clay
// (OCR 2) stays elastic and keeps that p'c.
TEST(CamClayScheme, AStageSwitchStartsTheStateFromTheStressThen) {
  hmpm::Problem p = problems::column(1, 0, 1.0, 10, 2);
  hmpm::Material elastic;
  elastic.name = "elastic";
  elastic.density = 2000;
  elastic.youngs_modulus = 2e7;
  elastic.poisson_ratio = 0.25;
  p.materials.push_back(elastic);
  hmpm::Material clay = elastic;
  clay.name = "clay";
  hmpm::ModifiedCamClay cc;
  cc.lambda = lambda;
  cc.kappa = kappa;
  cc.initial_void_ratio = e0;
  cc.overconsolidation_ratio = 2.0;
  clay.plasticity = cc;
  p.materials.push_back(clay);
  for (int c = 0; c < 3; ++c)
    p.bodies[0].initial.effective_stress[c] = [](const hmpm::Vec3&) { return -p0; };
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Traction t;
  t.particles.min = {1.0 - 0.05, 0, 0};
  t.particles.max = {1.0, 1, 1};
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [](double time) { return -p0 * (1.0 + std::min(1.0, time)); };
  p.tractions.push_back(t);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 1.0;
  p.time.dt = 0.25;
  hmpm::Stage switched;
  switched.name = "cam-clay";
  switched.end = 2.0;
  switched.body_materials = {{0, 1}};
  p.stages.push_back(switched);
  p.output.series_particles = {0, 5, 10};
  p.output.series_fields = {hmpm::Field::effective_stress, hmpm::Field::void_ratio,
                            hmpm::Field::preconsolidation_pressure};
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size(), last = s.time.size() - 1;
  for (std::size_t i = 0; i < np; ++i) {
    EXPECT_EQ(s.values[1][i], 0.0);  // elastic in the first stage: no state
    const double* sig = &s.values[0][(last * np + i) * 6];
    const double mean = -(sig[0] + sig[1] + sig[2]) / 3.0;
    std::printf("after the switch: particle %lld e %.9f p'c %.1f Pa, 2 p' %.1f Pa\n",
                static_cast<long long>(s.particles[i]), s.values[1][last * np + i],
                s.values[2][last * np + i], 2 * mean);
    // The second stage re-solves equilibrium with the clay's stiffness in
    // the moved configuration (0.15 % of p'), elastically: p'c stays what
    // the switch set, OCR times the stress then.
    EXPECT_NEAR(s.values[1][last * np + i], e0, 1e-4);
    EXPECT_NEAR(s.values[2][last * np + i], 2 * mean, 5e-3 * mean);
    for (std::size_t k = 0; k <= last; ++k)
      if (s.time[k] > 1.0 + 1e-9) {
        EXPECT_EQ(s.values[2][k * np + i], s.values[2][last * np + i]);
      }
    EXPECT_GT(mean, 1.2 * p0);  // the elastic stage's load, not the initial stress
  }
}

}  // namespace
