// Random fields (issue 43, verification §18): the generated field's
// statistics against its target. Each check is over many seeds at fixed
// points (independent samples), so its sampling error is known: the mean
// of M standard normals has standard error 1/sqrt(M), their variance
// sqrt(2/M), a correlation coefficient r about (1 - r^2)/sqrt(M). Bounds
// are 4 standard errors (a correct generator fails one check with
// probability 6e-5; the seeds are fixed, so the outcome is reproducible).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hmpm/random_field.hpp"

namespace {

using Points = std::vector<std::array<double, 3>>;
using hmpm::RandomField;

constexpr int seeds = 4000;

struct Moments {
  double mean = 0, variance = 0, fourth = 0;  // central
};

Moments moments(const std::vector<double>& v) {
  Moments m;
  for (double x : v) m.mean += x;
  m.mean /= static_cast<double>(v.size());
  for (double x : v) {
    const double d = x - m.mean;
    m.variance += d * d;
    m.fourth += d * d * d * d;
  }
  m.variance /= static_cast<double>(v.size() - 1);
  m.fourth /= static_cast<double>(v.size());
  return m;
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const Moments ma = moments(a), mb = moments(b);
  double c = 0;
  for (std::size_t i = 0; i < a.size(); ++i) c += (a[i] - ma.mean) * (b[i] - mb.mean);
  c /= static_cast<double>(a.size() - 1);
  return c / std::sqrt(ma.variance * mb.variance);
}

// The values of each point over `seeds` seeds: out[point][seed].
std::vector<std::vector<double>> over_seeds(RandomField f, int dim, const Points& points,
                                            bool gaussian) {
  std::vector<std::vector<double>> out(points.size());
  for (int s = 0; s < seeds; ++s) {
    f.seed = 1000 + static_cast<std::uint64_t>(s);
    const auto v =
        gaussian ? hmpm::gaussian_field(f, dim, points) : hmpm::sample_random_field(f, dim, points);
    for (std::size_t p = 0; p < points.size(); ++p) out[p].push_back(v[p]);
  }
  return out;
}

void expect_correlation(const std::vector<double>& a, const std::vector<double>& b, double target,
                        const char* what, double extra = 0.0) {
  const double r = correlation(a, b);
  const double se = (1 - target * target) / std::sqrt(static_cast<double>(seeds));
  std::printf("[ random field ] %s: correlation %.4f, target %.4f (4 SE = %.4f)\n", what, r, target,
              4 * se);
  EXPECT_NEAR(r, target, 4 * se + extra) << what;
}

void expect_standard_normal(const std::vector<double>& v, const char* what) {
  const Moments m = moments(v);
  const double n = static_cast<double>(v.size());
  EXPECT_NEAR(m.mean, 0.0, 4 / std::sqrt(n)) << what;
  EXPECT_NEAR(m.variance, 1.0, 4 * std::sqrt(2 / n)) << what;
}

TEST(RandomField, SameSeedSameFieldOtherSeedAnother) {
  RandomField f;
  f.correlation_length = {0.5, 0.3, 1.0};
  Points pts;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j) pts.push_back({0.1 * i, 0.07 * j, 0.0});
  f.seed = 42;
  const auto a = hmpm::gaussian_field(f, 2, pts), b = hmpm::gaussian_field(f, 2, pts);
  EXPECT_EQ(a, b);
  f.seed = 43;
  const auto c = hmpm::gaussian_field(f, 2, pts);
  int same = 0;
  for (std::size_t i = 0; i < a.size(); ++i) same += a[i] == c[i];
  EXPECT_EQ(same, 0);
  // The order of the points does not change a point's value.
  Points reversed(pts.rbegin(), pts.rend());
  f.seed = 42;
  const auto r = hmpm::gaussian_field(f, 2, reversed);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], r[a.size() - 1 - i]);
}

// 1D, a line at theta/8 spacing: every point standard normal, and the
// correlation at the lags theta/4, theta/2 and theta is exp(-2 lag/theta).
TEST(RandomField, MarkovCorrelationAtLagsOfAQuarterHalfAndWholeTheta) {
  const double theta = 2.0;
  RandomField f;
  f.correlation_length[0] = theta;
  Points pts;
  for (int i = 0; i <= 16; ++i) pts.push_back({theta / 8 * i, 0.0, 0.0});
  const auto v = over_seeds(f, 1, pts, true);
  expect_standard_normal(v[0], "point 0");
  expect_standard_normal(v[16], "point 16");
  expect_correlation(v[0], v[2], std::exp(-0.5), "lag theta/4");
  expect_correlation(v[0], v[4], std::exp(-1.0), "lag theta/2");
  expect_correlation(v[0], v[8], std::exp(-2.0), "lag theta");
  expect_correlation(v[5], v[13], std::exp(-2.0), "lag theta, elsewhere");
}

// 2D, two correlation lengths: separable (the diagonal lag's correlation is
// the product of the axes').
TEST(RandomField, SeparableIn2DWithAxisLengths) {
  RandomField f;
  f.correlation_length = {4.0, 1.0, 0.0};
  Points pts;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 8; ++i) pts.push_back({0.5 * i, 0.25 * j, 0.0});
  const auto v = over_seeds(f, 2, pts, true);
  auto at = [&](int i, int j) {
    return v[(static_cast<std::size_t>(j) * 9) + static_cast<std::size_t>(i)];
  };
  expect_correlation(at(0, 0), at(4, 0), std::exp(-1.0), "x lag 2 m (theta_x 4 m)");
  expect_correlation(at(0, 0), at(0, 2), std::exp(-1.0), "y lag 0.5 m (theta_y 1 m)");
  expect_correlation(at(0, 0), at(4, 2), std::exp(-2.0), "diagonal");
  expect_correlation(at(8, 4), at(0, 0), std::exp(-4.0 - 2.0), "far corner");
}

// Uneven spacing (the recursion's step depends on the gap) and an infinite
// correlation length (every point the same draw).
TEST(RandomField, UnevenSpacingAndInfiniteCorrelationLength) {
  RandomField f;
  f.correlation_length[0] = 1.0;
  const Points pts = {{0.0, 0, 0}, {0.13, 0, 0}, {0.5, 0, 0}, {1.37, 0, 0}};
  const auto v = over_seeds(f, 1, pts, true);
  expect_correlation(v[0], v[1], std::exp(-0.26), "gap 0.13");
  expect_correlation(v[0], v[3], std::exp(-2.74), "gap 1.37");
  expect_correlation(v[2], v[3], std::exp(-1.74), "gap 0.87");
  RandomField uniform_field;  // infinite lengths by default
  Points grid;
  for (int i = 0; i < 7; ++i) grid.push_back({1.0 * i, 0.5 * i, 0.0});
  const auto u = over_seeds(uniform_field, 2, grid, true);
  for (std::size_t p = 1; p < grid.size(); ++p) EXPECT_EQ(u[p], u[0]);
  expect_standard_normal(u[0], "infinite length");
}

// The target distributions' mean and variance at a point, over the seeds:
// lognormal (Griffiths and Fenton's c_u: mean 10 kPa, COV 0.3 and 1.0),
// normal and uniform. Standard errors from the samples' own moments.
TEST(RandomField, TargetMeanAndVarianceOfEachDistribution) {
  struct Target {
    RandomField::Distribution d;
    double first, second;
    const char* name;
  };
  for (const Target& t : {Target{RandomField::Distribution::lognormal, 10e3, 0.3, "lognormal 0.3"},
                          Target{RandomField::Distribution::lognormal, 10e3, 1.0, "lognormal 1.0"},
                          Target{RandomField::Distribution::normal, 30.0, 3.0, "normal"},
                          Target{RandomField::Distribution::uniform, 25.0, 35.0, "uniform"}}) {
    RandomField f;
    f.distribution = t.d;
    f.first = t.first;
    f.second = t.second;
    f.correlation_length[0] = 1.0;
    const Points pts = {{0.0, 0, 0}, {0.25, 0, 0}};
    const auto v = over_seeds(f, 1, pts, false);
    const Moments m = moments(v[0]);
    const double n = seeds, sd = f.standard_deviation();
    const double se_mean = std::sqrt(m.variance / n);
    const double se_var = std::sqrt((m.fourth - m.variance * m.variance) / n);
    std::printf("[ random field ] %s: mean %.5g (target %.5g), variance %.5g (target %.5g)\n",
                t.name, m.mean, f.mean(), m.variance, sd * sd);
    EXPECT_NEAR(m.mean, f.mean(), 4 * se_mean) << t.name;
    EXPECT_NEAR(m.variance, sd * sd, 4 * se_var) << t.name;
    for (double x : v[0]) {
      if (t.d == RandomField::Distribution::lognormal) {
        EXPECT_GT(x, 0.0);
      } else if (t.d == RandomField::Distribution::uniform) {
        EXPECT_GE(x, t.first);
        EXPECT_LE(x, t.second);
      }
    }
  }
}

// One long field: its spatial mean and variance converge to the target as
// the domain grows. Over a length L >> theta the spatial mean of this
// process has variance (1/L) int rho = theta/L, its spatial variance
// (2/L) int rho^2 = theta/L: standard errors sqrt(theta/L).
TEST(RandomField, ALongFieldsSpatialStatisticsApproachTheTarget) {
  RandomField f;
  f.correlation_length[0] = 1.0;
  f.seed = 7;
  Points pts;
  const double L = 2000.0, dx = 0.05;
  for (int i = 0; i * dx <= L; ++i) pts.push_back({i * dx, 0.0, 0.0});
  const Moments m = moments(hmpm::gaussian_field(f, 1, pts));
  std::printf("[ random field ] one field over 2000 theta: mean %.4f, variance %.4f\n", m.mean,
              m.variance);
  EXPECT_NEAR(m.mean, 0.0, 4 * std::sqrt(1.0 / L));
  EXPECT_NEAR(m.variance, 1.0, 4 * std::sqrt(1.0 / L));
}

// Scattered points (explicit particles): the nearest node of a regular
// lattice at theta/16; correlations within the sampling error plus the
// snapping's (each point moves at most theta/32 per axis).
TEST(RandomField, ScatteredPointsKeepTheCorrelation) {
  RandomField f;
  f.correlation_length = {1.0, 1.0, 0.0};
  Points pts;
  std::uint64_t state = 12345;
  auto next = [&]() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int i = 0; i < 300; ++i) pts.push_back({4 * next(), 4 * next(), 0.0});
  pts.push_back({1.0, 1.0, 0.0});
  pts.push_back({1.5, 1.0, 0.0});
  const auto v = over_seeds(f, 2, pts, true);
  const std::size_t a = pts.size() - 2, b = pts.size() - 1;
  expect_standard_normal(v[a], "scattered point");
  expect_correlation(v[a], v[b], std::exp(-1.0), "scattered, lag theta/2",
                     2 * (1.0 / 16) * std::exp(-1.0));
}

}  // namespace
