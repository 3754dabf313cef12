// Random fields of material parameters through the job path (issue 43,
// docs/job-spec.md "Random fields"): the spec's random_field parsed,
// generated over the particles at set-up, reported in the snapshots under
// the parameter's name; the errors with their JSON paths.
//
// The statistics of one realisation over a domain much larger than the
// correlation length: the particles lie on a regular lattice, so the
// sampling variances of the field's mean and variance are sums over the
// lattice's lags, computed here exactly for the separable Markov
// correlation rho = exp(-2|dx|/theta) exp(-2|dy|/theta) (a Gaussian field):
//   Var(mean G)   = (1/n^2) sum_ij rho_ij
//   Var(mean E)   = (m^2/n^2) sum_ij (exp(s^2 rho_ij) - 1)   (lognormal E)
//   Var(s^2 of G) ~ (2/n^2) sum_ij rho_ij^2
// and each statistic must lie within 4 of its standard errors of the
// target (probability 6e-5 of a false failure; the seed is fixed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"
#include "spec_support.hpp"
#include "test_support.hpp"

namespace {

using hmpm::api::testing::issue_at;
using nlohmann::json;

constexpr double mean_e = 20e6, cov_e = 0.5, theta = 1.0;
constexpr int cells = 80, ppc = 2;
constexpr double side = 16.0;  // m: 16 correlation lengths, 160 x 160 particles

json spec(std::uint64_t seed) {
  json s = {{"dimension", 2},
            {"grid", {{"min", {0, 0}}, {"max", {side, side}}, {"cells", {cells, cells}}}},
            {"materials",
             {{"clay",
               {{"model", "linear_elastic"},
                {"density", 1800},
                {"youngs_modulus",
                 {{"random_field",
                   {{"distribution", {{"lognormal", {{"mean", mean_e}, {"cov", cov_e}}}}},
                    {"correlation_length", {theta, theta}},
                    {"seed", seed}}}}},
                {"poisson_ratio", 0.3}}}}},
            {"bodies",
             {{{"material", "clay"},
               {"box", {{"min", {0, 0}}, {"max", {side, side}}}},
               {"particles_per_cell", ppc}}}},
            {"boundaries",
             {{{"nodes", {{"box", {{"min", {0, 0}}, {"max", {side, 0}}}}}}, {"velocity", {0, 0}}}}},
            {"time", {{"end", 1e-6}}},
            {"output", {{"snapshots", {{"interval", 1e-6}}}}}};
  return s;
}

/// The particles' Young's moduli in the first snapshot of the job's run.
std::vector<double> generated(std::uint64_t seed) {
  const hmpm::api::ParseResult r = hmpm::api::parse_job(spec(seed).dump());
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  if (!r.job) return {};
  std::vector<double> out;
  hmpm::RunOptions o;
  o.on_snapshot = [&](const hmpm::Snapshot& s) {
    if (!out.empty()) return;
    EXPECT_NE(std::find(s.fields.begin(), s.fields.end(), hmpm::Field::youngs_modulus),
              s.fields.end())
        << "the default snapshot fields carry the varying parameter";
    out = s.youngs_modulus;
  };
  const hmpm::RunResult run = hmpm::run(r.job->problem, o);
  EXPECT_EQ(run.status, hmpm::RunStatus::successful) << run.message;
  return out;
}

/// sum over the lattice's pairs of f(rho): per axis n points spaced d.
template <class F>
double lag_sum(int n, double d, F&& f) {
  double total = 0;
  for (int kx = -(n - 1); kx < n; ++kx)
    for (int ky = -(n - 1); ky < n; ++ky) {
      const double rho = std::exp(-2.0 * std::abs(kx) * d / theta - 2.0 * std::abs(ky) * d / theta);
      total +=
          static_cast<double>(n - std::abs(kx)) * static_cast<double>(n - std::abs(ky)) * f(rho);
    }
  return total;
}

TEST(RandomFields, GeneratedFieldHasTheTargetStatistics) {
  const std::vector<double> e = generated(42);
  const int per_axis = cells * ppc;
  const auto n = static_cast<std::size_t>(per_axis) * static_cast<std::size_t>(per_axis);
  ASSERT_EQ(e.size(), n);
  const double d = side / per_axis;
  const double s2 = std::log(1 + cov_e * cov_e), mu = std::log(mean_e) - s2 / 2;
  const double nn = static_cast<double>(n) * static_cast<double>(n);
  // Gaussian space: G = (ln E - mu) / s.
  double g_mean = 0, e_mean = 0;
  for (double v : e) {
    g_mean += (std::log(v) - mu) / std::sqrt(s2);
    e_mean += v;
  }
  g_mean /= static_cast<double>(n);
  e_mean /= static_cast<double>(n);
  double g_var = 0;
  for (double v : e) {
    const double g = (std::log(v) - mu) / std::sqrt(s2) - g_mean;
    g_var += g * g;
  }
  g_var /= static_cast<double>(n - 1);
  const double var_g_mean = lag_sum(per_axis, d, [](double r) { return r; }) / nn;
  const double var_e_mean =
      mean_e * mean_e * lag_sum(per_axis, d, [&](double r) { return std::expm1(s2 * r); }) / nn;
  const double var_g_var = 2 * lag_sum(per_axis, d, [](double r) { return r * r; }) / nn;
  // E[s^2] of correlated samples: 1 - Var(mean) n/(n - 1).
  const double expected_var = 1 - var_g_mean * static_cast<double>(n) / static_cast<double>(n - 1);
  EXPECT_LT(std::abs(g_mean), 4 * std::sqrt(var_g_mean))
      << "standard error " << std::sqrt(var_g_mean);
  EXPECT_LT(std::abs(e_mean - mean_e), 4 * std::sqrt(var_e_mean))
      << "mean E " << e_mean << ", standard error " << std::sqrt(var_e_mean);
  EXPECT_LT(std::abs(g_var - expected_var), 4 * std::sqrt(var_g_var))
      << "variance of ln E / s^2: " << g_var << ", standard error " << std::sqrt(var_g_var);
  // The bounds are tight enough to mean something: a field with a wrong
  // spread (the COV of E off by 20 %) would fail the variance check.
  EXPECT_LT(4 * std::sqrt(var_g_var), 0.25);
  // Correlated in space: neighbours along x at d = theta/10 correlate at
  // exp(-0.2) = 0.82 (the estimate's spread is far below the 0.1 allowed).
  double c = 0, v0 = 0;
  for (int y = 0; y < per_axis; ++y)
    for (int x = 0; x + 1 < per_axis; ++x) {
      const double a =
          (std::log(e[(static_cast<std::size_t>(y) * static_cast<std::size_t>(per_axis)) +
                      static_cast<std::size_t>(x)]) -
           mu) /
          std::sqrt(s2);
      const double b =
          (std::log(e[(static_cast<std::size_t>(y) * static_cast<std::size_t>(per_axis)) +
                      static_cast<std::size_t>(x) + 1]) -
           mu) /
          std::sqrt(s2);
      c += a * b;
      v0 += a * a;
    }
  EXPECT_NEAR(c / v0, std::exp(-2.0 * d / theta), 0.1);
}

TEST(RandomFields, SameSeedSameFieldOtherSeedAnother) {
  const std::vector<double> a = generated(7), b = generated(7), c = generated(8);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(RandomFields, SnapshotFilesCarryTheParameter) {
  const hmpm::api::ParseResult r = hmpm::api::parse_job(spec(3).dump());
  ASSERT_TRUE(r.job);
  const auto dir = std::filesystem::temp_directory_path() / "hmpm-random-field-vtu";
  std::filesystem::remove_all(dir);
  const hmpm::api::JobOutcome out = hmpm::api::run_job(*r.job, dir);
  ASSERT_EQ(out.run.status, hmpm::RunStatus::successful) << out.run.message;
  const std::string vtu = hmpm::api::testing::read_text(dir / "snapshot_0000.vtu");
  EXPECT_NE(vtu.find("Name=\"youngs_modulus\""), std::string::npos);
  // A homogeneous job's default snapshots do not.
  json homogeneous = spec(3);
  homogeneous["materials"]["clay"]["youngs_modulus"] = mean_e;
  const hmpm::api::ParseResult h = hmpm::api::parse_job(homogeneous.dump());
  ASSERT_TRUE(h.job);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(hmpm::api::run_job(*h.job, dir).run.status, hmpm::RunStatus::successful);
  EXPECT_EQ(hmpm::api::testing::read_text(dir / "snapshot_0000.vtu").find("youngs_modulus"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(RandomFields, ErrorsNameTheirPath) {
  const std::string e = "/materials/clay/youngs_modulus/random_field";
  json s = spec(1);
  s["materials"]["clay"]["youngs_modulus"]["random_field"]["distribution"] = {
      {"gamma", {{"mean", 1}}}};
  EXPECT_NE(issue_at(s, e + "/distribution").find("lognormal"), std::string::npos);

  s = spec(1);
  s["materials"]["clay"]["youngs_modulus"]["random_field"]["distribution"]["lognormal"]["cov"] =
      -0.1;
  EXPECT_NE(issue_at(s, e + "/distribution/lognormal/cov").find(">= 0"), std::string::npos);

  s = spec(1);
  s["materials"]["clay"]["youngs_modulus"]["random_field"]["correlation_length"] = {1, 1, 1};
  EXPECT_NE(issue_at(s, e + "/correlation_length").find("expected 2"), std::string::npos);

  s = spec(1);
  s["materials"]["clay"]["youngs_modulus"]["random_field"]["correlation_length"] = {1, "long"};
  EXPECT_NE(issue_at(s, e + "/correlation_length/1").find("infinite"), std::string::npos);

  s = spec(1);
  s["materials"]["clay"]["density"] = s["materials"]["clay"]["youngs_modulus"];
  const std::string density = issue_at(s, "/materials/clay/density");
  EXPECT_NE(density.find("cannot vary"), std::string::npos) << density;
  EXPECT_NE(density.find("youngs_modulus, cohesion, friction_angle"), std::string::npos) << density;

  s = spec(1);
  s["materials"]["clay"]["youngs_modulus"]["random_field"]["distribution"] = {
      {"normal", {{"mean", 1e6}, {"std", 1e6}}}};
  const std::string normal = issue_at(s, "/materials/clay/youngs_modulus");
  EXPECT_NE(normal.find("lognormal"), std::string::npos) << normal;

  // Cohesion of a Mohr-Coulomb material may vary; of an elastic one it is
  // refused as before (the model does not read it).
  s = spec(1);
  s["materials"]["clay"]["model"] = "mohr_coulomb";
  s["materials"]["clay"]["friction_angle"] = 0;
  s["materials"]["clay"]["dilatancy_angle"] = 0;
  s["materials"]["clay"]["cohesion"] = {
      {"random_field",
       {{"distribution", {{"lognormal", {{"mean", 10e3}, {"cov", 0.3}}}}},
        {"correlation_length", {2, "infinite"}},
        {"seed", 5}}}};
  const hmpm::api::ParseResult ok = hmpm::api::parse_job(s.dump());
  for (const auto& err : ok.errors) ADD_FAILURE() << err.path << ": " << err.message;
  ASSERT_TRUE(ok.job);
  ASSERT_EQ(ok.job->problem.materials[0].varying.size(), 2u);
  const hmpm::RandomField& f = *ok.job->problem.materials[0].varying[1].random_field;
  EXPECT_EQ(ok.job->problem.materials[0].varying[1].parameter, hmpm::MaterialParameter::cohesion);
  EXPECT_EQ(f.correlation_length[0], 2.0);
  EXPECT_TRUE(std::isinf(f.correlation_length[1]));
}

}  // namespace
