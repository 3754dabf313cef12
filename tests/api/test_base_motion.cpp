// test_base_motion.cpp — values of time as tables, boundary accelerations
// integrated to velocities, and `absorbing` boundaries: read from the spec
// with their defaults and errors, and a shaken layer posed in JSON (an
// acceleration on a compliant base) against the closed-form transfer
// function of an elastic layer.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"
#include "spec_support.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling
using std::numbers::pi;
using testing::issue_at;

template <class T>
json one(T v) {
  return json::array({v});
}

// A 1D column of 10 m along x, base at x = 0 (boundary 0).
json column(const json& base) {
  json spec;
  spec["dimension"] = 1;
  spec["grid"] = {{"min", one(0.0)}, {"max", one(10.0)}, {"cells", one(20)}};
  spec["materials"]["soil"] = {{"model", "linear_elastic"},
                               {"density", 1890.0},
                               {"youngs_modulus", 5e7},
                               {"poisson_ratio", 0.3}};
  spec["bodies"] =
      json::array({{{"material", "soil"}, {"box", {{"min", one(0.0)}, {"max", one(10.0)}}}}});
  json b = base;
  b["nodes"] = {{"box", {{"min", one(0.0)}, {"max", one(0.0)}}}};
  spec["boundaries"] = json::array({b});
  spec["time"] = {{"end", 1.0}};
  return spec;
}

// The velocity the solver will see at boundary 0, axis 0.
FieldOfTime base_velocity(const json& spec) {
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  if (!r.job || r.job->problem.boundaries.empty() || !r.job->problem.boundaries[0].velocity[0])
    return [](double) { return std::nan(""); };
  return *r.job->problem.boundaries[0].velocity[0];
}

// A table is piecewise linear between its rows and holds its end values.
TEST(BaseMotion, VelocityTableInterpolatesAndHoldsItsEnds) {
  const FieldOfTime v = base_velocity(
      column({{"velocity", json::array({{{"table", {{0.1, 1.0}, {0.3, -1.0}, {0.5, 0.0}}}}})}}));
  EXPECT_DOUBLE_EQ(v(0.0), 1.0);
  EXPECT_NEAR(v(0.2), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(v(0.25), -0.5);
  EXPECT_DOUBLE_EQ(v(0.4), -0.5);
  EXPECT_DOUBLE_EQ(v(0.9), 0.0);
}

// Accelerations integrate from rest at t = 0: a number to a t, a table
// exactly (piecewise quadratic), a formula by Simpson's rule on 2^16 panels
// of the job's time (error ~ (w dt)^4 / 2880 of the amplitude: 1e-16 here,
// asserted at 1e-9).
TEST(BaseMotion, AccelerationIntegratesToVelocity) {
  const FieldOfTime constant = base_velocity(column({{"acceleration", one(2.0)}}));
  EXPECT_DOUBLE_EQ(constant(0.75), 1.5);
  // a = 4 t on [0, 0.5] then 2 - 4 (t - 0.5) ... to 0 at t = 1: v = 2 t^2 first.
  const FieldOfTime table = base_velocity(
      column({{"acceleration", json::array({{{"table", {{0.0, 0.0}, {0.5, 2.0}, {1.0, 0.0}}}}})}}));
  EXPECT_NEAR(table(0.25), 2 * 0.25 * 0.25, 1e-15);
  EXPECT_NEAR(table(0.75), 0.5 + (2.0 * 0.25 - 2.0 * 0.25 * 0.25), 1e-15);
  EXPECT_NEAR(table(1.5), 1.0, 1e-15);  // past the record: a = 0 holds
  const double w = 2 * pi * 5;
  const FieldOfTime formula = base_velocity(column({{"acceleration", one("3*cos(10*_pi*t)")}}));
  for (double t : {0.0, 0.013, 0.31, 0.777, 1.0})
    EXPECT_NEAR(formula(t), 3 * std::sin(w * t) / w, 1e-9) << t;
}

TEST(BaseMotion, BadTablesAndAccelerationsSayWhere) {
  EXPECT_NE(issue_at(column({{"velocity", json::array({{{"table", {{0.2, 1.0}, {0.1, 0.0}}}}})}}),
                     "/boundaries/0/velocity/0/table/1/0")
                .find("times must increase"),
            std::string::npos);
  EXPECT_NE(issue_at(column({{"velocity", json::array({{{"table", {{0.2, 1.0, 3.0}}}}})}}),
                     "/boundaries/0/velocity/0/table/0")
                .find("[t, value]"),
            std::string::npos);
  EXPECT_NE(issue_at(column({{"velocity", json::array({{{"rows", {{0.2, 1.0}}}}})}}),
                     "/boundaries/0/velocity/0/rows"),
            "");
  EXPECT_NE(issue_at(column({{"velocity", one(0.0)}, {"acceleration", one(1.0)}}),
                     "/boundaries/0/acceleration/0")
                .find("give one"),
            std::string::npos);
}

TEST(BaseMotion, AbsorbingDefaultsAndErrors) {
  {
    const ParseResult r = parse_job(column({{"absorbing", true}}).dump());
    ASSERT_TRUE(r.job) << (r.errors.empty() ? "" : r.errors[0].message);
    const Boundary& b = r.job->problem.boundaries[0];
    ASSERT_TRUE(b.absorbing);
    EXPECT_EQ(b.absorbing->normal, 0);
    EXPECT_EQ(b.absorbing->material, 0u);
  }
  // Two materials: which one is beyond the boundary must be said.
  json two = column({{"absorbing", true}});
  two["materials"]["rock"] = two["materials"]["soil"];
  EXPECT_NE(issue_at(two, "/boundaries/0/absorbing").find("needs 'material'"), std::string::npos);
  two["boundaries"][0]["absorbing"] = {{"material", "granite"}};
  EXPECT_NE(issue_at(two, "/boundaries/0/absorbing/material"), "");
  // The explicit scheme only.
  json qs = column({{"absorbing", true}});
  qs["time"]["scheme"] = "quasi_static";
  EXPECT_NE(issue_at(qs, "/boundaries/0/absorbing").find("needs time.scheme 'explicit'"),
            std::string::npos);
  // 2D: the normal from a flat box, or said.
  json flat = column({{"absorbing", true}});
  flat["dimension"] = 2;
  flat["grid"] = {{"min", {0.0, 0.0}}, {"max", {1.0, 10.0}}, {"cells", {1, 20}}};
  flat["bodies"][0]["box"] = {{"min", {0.0, 0.0}}, {"max", {1.0, 10.0}}};
  flat["boundaries"][0]["nodes"] = {{"box", {{"min", {0.0, 0.0}}, {"max", {1.0, 0.0}}}}};
  {
    const ParseResult r = parse_job(flat.dump());
    ASSERT_TRUE(r.job) << (r.errors.empty() ? "" : r.errors[0].message);
    EXPECT_EQ(r.job->problem.boundaries[0].absorbing->normal, 1);
  }
  flat["boundaries"][0]["nodes"] = "all";
  EXPECT_NE(issue_at(flat, "/boundaries/0/absorbing").find("needs 'normal'"), std::string::npos);
  flat["boundaries"][0]["absorbing"] = {{"normal", "w"}};
  EXPECT_NE(issue_at(flat, "/boundaries/0/absorbing/normal"), "");
}

// A base shaken sideways further than the room between the soil and the
// grid's edges: a warning that says how far, and by how much to widen the
// grid. 1 m/s^2 for 2 s moves the base 2 m; the soil's outermost particles
// sit a quarter cell (0.25 m) from the edges.
TEST(BaseMotion, ShakingFurtherThanTheGridHasRoomForIsWarned) {
  json spec = column({{"velocity", one(0.0)}});
  spec["dimension"] = 2;
  spec["grid"] = {{"min", {0.0, 0.0}}, {"max", {4.0, 10.0}}, {"cells", {4, 10}}};
  spec["bodies"][0]["box"] = {{"min", {0.0, 0.0}}, {"max", {4.0, 10.0}}};
  spec["boundaries"][0] = {{"nodes", {{"box", {{"min", {0.0, 0.0}}, {"max", {4.0, 0.0}}}}}},
                           {"acceleration", {"t < 2 ? 1 : 0", 0.0}}};
  spec["time"]["end"] = 3.0;
  const std::string w = issue_at(spec, "/boundaries/0/acceleration/0", true);
  EXPECT_NE(w.find("up to 4 m along x sideways"), std::string::npos) << w;
  EXPECT_NE(w.find("by at least 3.75 m"), std::string::npos) << w;
  spec["grid"] = {{"min", {-5.0, 0.0}}, {"max", {9.0, 10.0}}, {"cells", {14, 10}}};
  EXPECT_EQ(issue_at(spec, "/boundaries/0/acceleration/0", true), "");
}

// The shaken layer of tests/solver/test_absorbing.cpp posed as a user
// would: a 2D column one cell wide, every node held vertically, a compliant
// base of rock (the second material, 4x the soil's shear impedance) driven
// by the outcrop acceleration V w cos(w t) at the layer's first resonance.
// The steady amplitude at the top particle is the closed form's
// V cos(k d) / alpha... within 5 % (measured 2.8 % at 20 cells with the
// velocity given directly: the integral adds nothing measurable).
TEST(BaseMotion, ShakenLayerFromAnAccelerationOnACompliantBase) {
  constexpr double H = 10.0, E = 5e7, nu = 0.3, rho = 1890.0, V = 0.1, alpha = 0.25;
  constexpr int cells = 20;
  const double g = E / (2 * (1 + nu)), cs = std::sqrt(g / rho);
  const double rho_rock = 2400.0, cs_rock = std::sqrt(rho * g) / alpha / rho_rock;
  const double omega = 2 * pi * cs / (4 * H), period = 2 * pi / omega;
  json spec;
  spec["dimension"] = 2;
  spec["grid"] = {{"min", {0.0, 0.0}}, {"max", {H / cells, H}}, {"cells", {1, cells}}};
  spec["materials"]["soil"] = {
      {"model", "linear_elastic"}, {"density", rho}, {"youngs_modulus", E}, {"poisson_ratio", nu}};
  spec["materials"]["rock"] = {{"model", "linear_elastic"},
                               {"density", rho_rock},
                               {"youngs_modulus", 2 * (1 + nu) * rho_rock * cs_rock * cs_rock},
                               {"poisson_ratio", nu}};
  spec["bodies"] = json::array(
      {{{"material", "soil"}, {"box", {{"min", {0.0, 0.0}}, {"max", {H / cells, H}}}}}});
  spec["gravity"] = {0.0, 0.0};
  const std::string a = std::to_string(V * omega) + "*cos(" + std::to_string(omega) + "*t)";
  spec["boundaries"] =
      json::array({{{"nodes", "all"}, {"velocity", {nullptr, 0.0}}},
                   {{"nodes", {{"box", {{"min", {0.0, 0.0}}, {"max", {H / cells, 0.0}}}}}},
                    {"absorbing", {{"material", "rock"}}},
                    {"acceleration", {a, nullptr}}}});
  spec["time"] = {{"end", 14 * period}};
  const int top = 4 * cells - 1;
  spec["output"]["series"] = {
      {"particles", one(top)}, {"fields", one("velocity")}, {"interval", period / 200}};
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job);
  const RunResult run = hmpm::run(r.job->problem);
  ASSERT_EQ(run.status, RunStatus::successful) << run.message;
  double amplitude = 0;
  for (std::size_t k = 0; k < run.series.time.size(); ++k)
    if (run.series.time[k] > 12 * period)
      amplitude = std::max(amplitude, std::abs(run.series.values[0][2 * k]));
  const double depth = H - run.series.initial_positions[0][1];
  const double expected = V * std::cos(omega / cs * depth) / alpha;  // cos(k H) = 0
  std::printf("[ base motion ] amplitude %.5f m/s, closed form %.5f (ratio %.4f)\n", amplitude,
              expected, amplitude / expected);
  EXPECT_NEAR(amplitude / expected, 1.0, 0.05);
}

}  // namespace
}  // namespace hmpm::api
