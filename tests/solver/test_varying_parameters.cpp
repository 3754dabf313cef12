// Material parameters that vary from particle to particle (issue 43,
// verification §18): Material::varying, a random field or a function of
// position, read by the stress update through the particle index.
//
// The columns: an elastic column of height H on a fixed base, laterally
// confined (1D, or 2D between roller walls), loaded by q on its top face,
// no gravity. In uniaxial strain the static strain is q/M, M = E (1 - nu) /
// ((1 + nu)(1 - 2 nu)) the constrained modulus (E itself for nu = 0), so the
// settlement is q H / M; with linear shape functions and the load on the
// top node the discrete static solution is exact for a uniform column, and
// for one of two layers meeting on a node plane (piecewise uniform strain),
// so the tolerances are those of the solve (the quasi-static scheme's
// Newton tolerance) and of the small geometric nonlinearity (strains of
// 1e-6: relative 1e-5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

struct ColumnCase {
  int dim = 1;
  double H = 1.0, q = 10.0, nu = 0.0, rho = 2000.0, E = 10e6;
  int cells = 10, ppc = 2;
  hmpm::Scheme scheme = hmpm::Scheme::quasi_static;
  double constrained(double e) const { return e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); }
};

hmpm::Problem loaded_column(const ColumnCase& c) {
  const int axis = c.dim - 1;
  hmpm::Problem p = problems::column(c.dim, axis, c.H, c.cells, c.ppc);
  p.materials.push_back(problems::elastic(c.rho, c.E, c.nu));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, axis, 0.0), axis));
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  t.particles.min[axis] = c.H - c.H / (c.cells * c.ppc);  // the top row of particles
  t.axis = axis;
  t.side = +1;
  t.traction[axis] = problems::constant(-c.q);
  p.tractions.push_back(t);
  p.time.scheme = c.scheme;
  if (c.scheme == hmpm::Scheme::quasi_static) {
    p.time.end = 1.0;
    p.time.dt = 1.0;  // one step: no inertia, the static state
  }
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::strain, hmpm::Field::youngs_modulus};
  p.output.series_interval = p.time.end;
  return p;
}

struct Settled {
  double settlement = 0;        ///< -integral of the vertical strain over the height
  double e_min = 0, e_max = 0;  ///< of the particles' Young's moduli
  hmpm::RunStatus status = hmpm::RunStatus::failed;
};

Settled settle(const ColumnCase& c, const hmpm::Problem& p) {
  const hmpm::RunResult r = hmpm::run(p);
  Settled out;
  out.status = r.status;
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size(), row = s.time.size() - 1;
  const int axis = c.dim - 1;
  out.e_min = inf;
  out.e_max = -inf;
  for (std::size_t i = 0; i < np; ++i) {
    out.settlement -= s.values[0][(row * np + i) * 6 + static_cast<std::size_t>(axis)];
    out.e_min = std::min(out.e_min, s.values[1][row * np + i]);
    out.e_max = std::max(out.e_max, s.values[1][row * np + i]);
  }
  // Equal initial volumes, one column of cells: each particle stands for
  // H / (particles along the height) of it.
  const double across = c.dim == 1 ? 1.0 : std::pow(c.ppc, c.dim - 1);
  out.settlement *= c.H / (static_cast<double>(np) / across) / across;
  return out;
}

hmpm::RandomField lognormal(double mean, double cov, double theta, std::uint64_t seed) {
  hmpm::RandomField f;
  f.distribution = hmpm::RandomField::Distribution::lognormal;
  f.first = mean;
  f.second = cov;
  f.correlation_length = {theta, theta, theta};
  f.seed = seed;
  return f;
}

// (a) The infinite-correlation-length limit: each sample is uniform, E_i
// the one draw, and settles q H / M(E_i); over the samples the mean
// settlement is q H (1 + v^2) / mu for nu = 0 (E[1/E] of a lognormal of
// mean mu and COV v is (1 + v^2)/mu), times (1 + nu)(1 - 2 nu)/(1 - nu)
// otherwise. The mean of N samples is within 3 standard errors (the
// samples' own standard deviation / sqrt N) of it: a correct solver fails
// with probability 0.3 %, and the seeds are fixed.
void infinite_correlation(ColumnCase c, int samples) {
  const double mu = c.E, v = 0.3;
  std::vector<double> settlement;
  for (int k = 0; k < samples; ++k) {
    hmpm::Problem p = loaded_column(c);
    hmpm::VaryingParameter e;
    e.parameter = hmpm::MaterialParameter::youngs_modulus;
    e.random_field = lognormal(mu, v, inf, 100 + static_cast<std::uint64_t>(k));
    p.materials[0].varying.push_back(e);
    const Settled s = settle(c, p);
    if (s.status != hmpm::RunStatus::successful) return;
    ASSERT_EQ(s.e_min, s.e_max) << "sample " << k << ": not uniform";
    const double exact = c.q * c.H / c.constrained(s.e_min);
    EXPECT_NEAR(s.settlement / exact, 1.0, 1e-5) << "sample " << k << ", E = " << s.e_min;
    settlement.push_back(s.settlement);
  }
  double mean = 0, var = 0;
  for (double x : settlement) mean += x;
  mean /= samples;
  for (double x : settlement) var += (x - mean) * (x - mean);
  var /= samples - 1;
  const double se = std::sqrt(var / samples);
  // constrained(1) = M/E, so the mean of q H / M is q H (1 + v^2) / (mu M/E):
  const double target = c.q * c.H * (1 + v * v) / (mu * c.constrained(1.0));
  EXPECT_LT(std::abs(mean - target), 3 * se)
      << "mean " << mean << ", closed form " << target << ", standard error " << se;
  // The spread is there (not a constant field): the samples' COV of 1/E is
  // about v.
  EXPECT_GT(std::sqrt(var) / mean, 0.2);
}

TEST(VaryingParameters, InfiniteCorrelationLengthColumn1D) {
  infinite_correlation(ColumnCase{}, 400);
}

TEST(VaryingParameters, InfiniteCorrelationLengthConfinedColumn2D) {
  ColumnCase c;
  c.dim = 2;
  c.nu = 0.3;
  infinite_correlation(c, 100);
}

// (c) A deterministic check of per-particle parameters: E1 in the upper
// half, E2 in the lower, meeting on a node plane; series springs settle
// q H/2 (1/M1 + 1/M2). Through the quasi-static scheme (its stiffness and
// stress) and the explicit one (the stress update of the hot loop), the
// explicit one damped to rest (local damping 0.2; the residual motion after
// 400 periods of the stiff layer is far below the 1e-4 asked; the explicit
// scheme updates volumes and positions, an error of the order of the
// strain, 2.5e-6 here: measured 2.9e-4 at q = 1 kPa, strain 2.5e-4).
void two_halves(ColumnCase c, double tolerance) {
  const double e1 = 4e6, e2 = 16e6;
  const int axis = c.dim - 1;
  hmpm::Problem p = loaded_column(c);
  if (c.scheme == hmpm::Scheme::explicit_scheme) {
    p.time.end = 3.0;
    p.local_damping = problems::constant(0.2);
    p.output.series_interval = p.time.end;
  }
  hmpm::VaryingParameter e;
  e.parameter = hmpm::MaterialParameter::youngs_modulus;
  const double half = c.H / 2;
  e.value = [=](const hmpm::Vec3& x) { return x[static_cast<std::size_t>(axis)] > half ? e1 : e2; };
  p.materials[0].varying.push_back(e);
  // The stable step sees the stiffer layer: its wave speed is the fastest.
  const hmpm::StableStep step = hmpm::stable_step(p);
  EXPECT_DOUBLE_EQ(step.wave_speed, std::sqrt(c.constrained(e2) / c.rho));
  const Settled s = settle(c, p);
  EXPECT_EQ(s.e_min, e1);
  EXPECT_EQ(s.e_max, e2);
  const double exact = c.q * half * (1 / c.constrained(e1) + 1 / c.constrained(e2));
  EXPECT_NEAR(s.settlement / exact, 1.0, tolerance) << "settlement " << s.settlement;
  // Not the homogeneous answer of either modulus.
  EXPECT_GT(std::abs(s.settlement / (c.q * c.H / c.constrained(e1)) - 1), 0.3);
}

TEST(VaryingParameters, TwoHalvesSettleAsSeriesSprings) {
  two_halves(ColumnCase{}, 1e-5);
  ColumnCase c2;
  c2.dim = 2;
  c2.nu = 0.3;
  two_halves(c2, 1e-5);
}

TEST(VaryingParameters, TwoHalvesExplicit) {
  ColumnCase c;
  c.scheme = hmpm::Scheme::explicit_scheme;
  two_halves(c, 1e-4);
  c.dim = 2;
  c.nu = 0.3;
  two_halves(c, 1e-4);
}

// A parameter the material does not have cannot vary; a normal field that
// leaves the parameter's range is refused with the particle's value.
TEST(VaryingParameters, ChecksNameTheParameter) {
  ColumnCase c;
  hmpm::Problem p = loaded_column(c);
  hmpm::VaryingParameter coh;
  coh.parameter = hmpm::MaterialParameter::cohesion;
  coh.value = [](const hmpm::Vec3&) { return 1e3; };
  p.materials[0].varying.push_back(coh);
  auto issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.text(), "materials/soil/cohesion");
  EXPECT_NE(issues[0].message.find("does not apply"), std::string::npos) << issues[0].message;

  p = loaded_column(c);
  hmpm::VaryingParameter e;
  e.parameter = hmpm::MaterialParameter::youngs_modulus;
  hmpm::RandomField f;
  f.distribution = hmpm::RandomField::Distribution::normal;
  f.first = 1e6;
  f.second = 2e6;  // P[E < 0] = 0.31 per particle
  f.correlation_length = {0.1, 0.1, 0.1};
  f.seed = 7;
  e.random_field = f;
  p.materials[0].varying.push_back(e);
  issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.text(), "materials/soil/youngs_modulus");
  EXPECT_NE(issues[0].message.find("lognormal"), std::string::npos) << issues[0].message;
}

}  // namespace
