// Cam-Clay's preconsolidation pressure as a random field (issue 43,
// docs/job-spec.md "Random fields"): each particle starts from its own p'c,
// and that p'c is what its stress update uses.
//
// The problem: a dry 1D oedometer (no gravity) of 12 cells with one
// particle per cell at p' = 100 kPa, loaded to a vertical stress of
// 400 kPa in the quasi-static scheme, above every particle's p'c (uniform
// 120-250 kPa), so every particle yields and hardens. Checked:
// - at t = 0 each particle's p'c is the field generated at its position;
// - at the end each particle's state lies on the volume law from its own
//   start, e - e0 = -(lambda - kappa) ln(p'c/p'c0) - kappa ln(p'/p'0): the
//   model's exponential elasticity and hardening make it exact for any step,
//   so 1e-9 is round-off over the steps (a particle started from the mean
//   p'c instead would miss it by (lambda - kappa) ln(mean/own), 1e-2 to 6e-2);
// - with an infinite correlation length (one draw for the whole material)
//   the column is the column of that number, to round-off (1e-12).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/random_field.hpp"
#include "hmpm/run.hpp"

namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling

constexpr int cells = 12;
constexpr double height = 1.2, p0 = 1e5;  // the load, -1e5 - 3e5 min(t, 1), ends at 400 kPa

json field(double theta) {
  return {{"random_field",
           {{"distribution", {{"uniform", {{"min", 1.2e5}, {"max", 2.5e5}}}}},
            {"correlation_length", {theta}},
            {"seed", 7}}}};
}

json field_infinite() {
  json f = field(0.3);
  f["random_field"]["correlation_length"] = {"infinite"};
  return f;
}

json oedometer(const json& preconsolidation) {
  const double top = height - height / cells / 2;  // the top particle's centre
  return {{"dimension", 1},
          {"grid", {{"min", {0.0}}, {"max", {height}}, {"cells", {cells}}}},
          {"materials",
           {{"clay",
             {{"model", "modified_cam_clay"},
              {"density", 1800},
              {"youngs_modulus", 2e7},  // the schemes' reference stiffness: the same in every run
              {"poisson_ratio", 0.25},
              {"lambda", 0.1},
              {"kappa", 0.02},
              {"critical_state_ratio", 1.2},
              {"initial_void_ratio", 0.9},
              {"preconsolidation_pressure", preconsolidation}}}}},
          {"bodies",
           {{{"material", "clay"},
             {"box", {{"min", {0.0}}, {"max", {height}}}},
             {"particles_per_cell", 1},
             {"initial", {{"effective_stress", {-p0, -p0, -p0, 0, 0, 0}}}}}}},
          {"gravity", {0.0}},
          {"boundaries",
           {{{"nodes", {{"box", {{"min", {0.0}}, {"max", {0.0}}}}}}, {"velocity", {0.0}}}}},
          {"tractions",
           {{{"particles", {{"box", {{"min", {top - 0.01}}, {"max", {height}}}}}},
             {"face", "x+"},
             {"traction", {std::string("-1e5 - 3e5 * min(t, 1)")}}}}},
          {"time", {{"end", 1.0}, {"scheme", "quasi_static"}, {"dt", 0.1}}},
          {"output",
           {{"snapshots",
             {{"interval", 1.0},
              {"fields",
               {"position", "strain", "effective_stress", "void_ratio",
                "preconsolidation_pressure"}}}}}}};
}

struct Ends {
  std::vector<double> x0, pc0;                       // at t = 0
  std::vector<double> strain, void_ratio, pc, mean;  // at the end: eps_xx, e, p'c, p'
};

Ends run(const json& spec) {
  const hmpm::api::ParseResult r = hmpm::api::parse_job(spec.dump());
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  Ends out;
  if (!r.job) return out;
  hmpm::RunOptions o;
  int seen = 0;
  o.on_snapshot = [&](const hmpm::Snapshot& s) {
    if (seen++ == 0) {
      for (std::size_t p = 0; p < s.position.size() / 3; ++p) out.x0.push_back(s.position[3 * p]);
      out.pc0 = s.preconsolidation_pressure;
      return;
    }
    out.strain.clear();
    out.mean.clear();
    for (std::size_t p = 0; p < s.strain.size() / 6; ++p) {
      out.strain.push_back(s.strain[6 * p]);
      const double* sig = &s.effective_stress[6 * p];
      out.mean.push_back(-(sig[0] + sig[1] + sig[2]) / 3.0);
    }
    out.void_ratio = s.void_ratio;
    out.pc = s.preconsolidation_pressure;
  };
  const hmpm::RunResult res = hmpm::run(r.job->problem, o);
  EXPECT_EQ(res.status, hmpm::RunStatus::successful) << res.message;
  EXPECT_EQ(seen, 2) << "a snapshot at t = 0 and one at the end";
  return out;
}

/// The field of field(theta) generated at the particles' initial positions.
std::vector<double> expected_field(const std::vector<double>& x0, double theta) {
  hmpm::RandomField f;
  f.distribution = hmpm::RandomField::Distribution::uniform;
  f.first = 1.2e5;
  f.second = 2.5e5;
  f.correlation_length = {theta, 0.0, 0.0};
  f.seed = 7;
  std::vector<std::array<double, 3>> points;
  points.reserve(x0.size());
  for (double x : x0) points.push_back({x, 0.0, 0.0});
  return hmpm::sample_random_field(f, 1, points);
}

TEST(CamClayRandomField, EachParticleStartsFromTheFieldAtItsPosition) {
  const Ends e = run(oedometer(field(0.3)));
  ASSERT_EQ(e.pc0.size(), static_cast<std::size_t>(cells));
  ASSERT_EQ(e.x0.size(), static_cast<std::size_t>(cells));
  const std::vector<double> expected = expected_field(e.x0, 0.3);
  for (std::size_t p = 0; p < e.pc0.size(); ++p)
    EXPECT_NEAR(e.pc0[p], expected[p], 1e-9 * expected[p]) << "particle " << p;
  // A field, not one value: the particles' p'c spread over the range.
  const auto [lo, hi] = std::minmax_element(e.pc0.begin(), e.pc0.end());
  EXPECT_GT(*hi - *lo, 0.2 * (2.5e5 - 1.2e5));
}

TEST(CamClayRandomField, EachParticleHardensFromItsOwnPreconsolidationPressure) {
  const Ends e = run(oedometer(field(0.3)));
  ASSERT_EQ(e.void_ratio.size(), static_cast<std::size_t>(cells));
  const std::vector<double> own = expected_field(e.x0, 0.3);  // the field's p'c0
  for (std::size_t p = 0; p < e.void_ratio.size(); ++p) {
    // Yielded: p'c has grown from the particle's own start.
    EXPECT_GT(e.pc[p], 1.05 * own[p]) << "particle " << p;
    // e - e0 = -(lambda - kappa) ln(p'c/p'c0) - kappa ln(p'/p'0).
    const double law = 0.9 - 0.08 * std::log(e.pc[p] / own[p]) - 0.02 * std::log(e.mean[p] / p0);
    EXPECT_NEAR(e.void_ratio[p], law, 1e-9) << "particle " << p;
  }
}

TEST(CamClayRandomField, InfiniteCorrelationIsTheColumnOfTheDrawnValue) {
  const Ends random = run(oedometer(field_infinite()));
  ASSERT_EQ(random.strain.size(), static_cast<std::size_t>(cells));
  for (double pc : random.pc0) EXPECT_EQ(pc, random.pc0[0]) << "one value for the material";
  const Ends uniform = run(oedometer(random.pc0[0]));
  ASSERT_EQ(uniform.strain.size(), static_cast<std::size_t>(cells));
  for (std::size_t p = 0; p < uniform.strain.size(); ++p) {
    EXPECT_NEAR(random.strain[p], uniform.strain[p], 1e-12 * std::abs(uniform.strain[p]))
        << "particle " << p;
    EXPECT_NEAR(random.pc[p], uniform.pc[p], 1e-12 * uniform.pc[p]) << "particle " << p;
  }
  // The draw is not the mean (which a p'c left at the nominal value would give).
  const Ends mean = run(oedometer(1.85e5));
  EXPECT_GT(std::abs(mean.strain[0] - random.strain[0]), 1e-3 * std::abs(mean.strain[0]));
}

TEST(CamClayRandomField, AStageCannotSwitchABodyToOrFromIt) {
  json s = oedometer(field(0.3));
  s["materials"]["stiff"] = {{"model", "linear_elastic"},
                             {"density", 1800},
                             {"youngs_modulus", 2e7},
                             {"poisson_ratio", 0.25}};
  s["stages"] = {{{"end", 2.0}, {"body_materials", {{{"body", 0}, {"material", "stiff"}}}}}};
  const hmpm::api::ParseResult r = hmpm::api::parse_job(s.dump());
  const bool found = std::any_of(r.errors.begin(), r.errors.end(), [](const auto& e) {
    return e.path == "/stages/0/body_materials/0/material" &&
           e.message.find("preconsolidation_pressure") != std::string::npos &&
           e.message.find("from the start") != std::string::npos;
  });
  std::string all;
  for (const auto& e : r.errors) all += "  " + e.path + ": " + e.message + "\n";
  EXPECT_TRUE(found) << all;
}

TEST(CamClayRandomField, ValuesOutsideTheRangeAreRefusedAtTheirPath) {
  json pc = field(0.3);
  pc["random_field"]["distribution"] = {{"normal", {{"mean", 1e5}, {"std", 1e5}}}};
  const hmpm::api::ParseResult r = hmpm::api::parse_job(oedometer(pc).dump());
  const bool found = std::any_of(r.errors.begin(), r.errors.end(), [](const auto& e) {
    return e.path == "/materials/clay/preconsolidation_pressure" &&
           e.message.find("must be > 0") != std::string::npos;
  });
  EXPECT_TRUE(found);
}

}  // namespace
