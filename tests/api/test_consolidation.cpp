// test_consolidation.cpp — output.consolidation, the average degree of
// consolidation: read from the spec with its defaults and errors, and run
// against Terzaghi's degree of consolidation on a column under gravity
// loaded suddenly (the excess measured from the hydrostatic pressure of the
// geostatic water table, its default).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../solver/closed_form.hpp"
#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"
#include "spec_support.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling
using testing::issue_at;

// A 1D saturated clay column of height H along x under gravity, water
// table at its top, geostatic at t = 0; loaded suddenly at t = 0 by q on
// its top face; drained through its fixed base (p = gamma_w H there, the
// hydrostatic value: a pressure condition acts on grid nodes, and the
// loaded top moves away from its node plane as the layer settles), the
// top impermeable. Quasi-static steps growing 1.2x from T_v = 1e-4 to
// 1e-3. Clay: E = 50 MPa, nu = 0.3, n = 0.5, k = 1e-8 m/s, Kw = 2.2 GPa.
// Stiff enough that the settlement (m_v q H = 3.7 mm) barely moves the
// particles through the hydrostatic field: the excess is measured from the
// hydrostatic pressure at the particle's current position, which differs
// from Terzaghi's small-strain excess by up to gamma_w s / q = 0.07 % of q
// here (with E = 5 MPa, 0.7 %: U then converges to a curve 0.35 % above
// Terzaghi's, measured at 20, 40 and 80 cells — a finite-strain effect,
// not an error of the output).
struct Column {
  int cells = 40;
  double H = 5.0, q = 50e3, E = 50e6, nu = 0.3, n = 0.5, k = 1e-8, kw = 2.2e9;
  double m_v() const { return (1 + nu) * (1 - 2 * nu) / (E * (1 - nu)); }
  double cv() const { return k / (1000.0 * 9.81 * (m_v() + n / kw)); }
  double time_of(double tv) const { return tv * H * H / cv(); }
};

// A one-component vector (a braced single value would be a number).
template <class T>
json one(T v) {
  return json::array({v});
}

json column_spec(const Column& c) {
  const double h = c.H / c.cells;
  json spec;
  spec["name"] = "consolidation-under-gravity";
  spec["dimension"] = 1;
  spec["grid"] = {{"min", one(0.0)}, {"max", one(c.H + 2 * h)}, {"cells", one(c.cells + 2)}};
  json hydraulic = {
      {"porosity", c.n}, {"hydraulic_conductivity", c.k}, {"fluid_bulk_modulus", c.kw}};
  spec["materials"]["clay"] = {{"model", "linear_elastic"},
                               {"density", 2650.0},
                               {"youngs_modulus", c.E},
                               {"poisson_ratio", c.nu},
                               {"hydraulic", hydraulic}};
  json body = {{"material", "clay"},
               {"box", {{"min", one(0.0)}, {"max", one(c.H)}}},
               {"particles_per_cell", 2}};
  spec["bodies"] = json::array({body});
  spec["gravity"] = one(-9.81);
  spec["initial_state"]["geostatic"]["water_table"] = c.H;
  json base = {{"nodes", {{"box", {{"min", one(0.0)}, {"max", one(0.0)}}}}},
               {"velocity", one(0.0)},
               {"pore_pressure", 1000.0 * 9.81 * c.H}};
  spec["boundaries"] = json::array({base});
  json load = {{"particles", {{"box", {{"min", one(c.H - h / 2)}, {"max", one(c.H)}}}}},
               {"face", "x+"},
               {"traction", one(-c.q)}};
  spec["tractions"] = json::array({load});
  spec["time"] = {
      {"end", c.time_of(1.0)},
      {"scheme", "quasi_static"},
      {"dt", {{"initial", c.time_of(1e-4)}, {"max", c.time_of(1e-3)}, {"growth", 1.2}}}};
  spec["output"]["consolidation"] = {{"interval", c.time_of(0.01)}, {"from", c.time_of(1e-4)}};
  return spec;
}

struct Errors {
  double degree = 0;  // max |U - U_exact| over T_v in [0.02, 1]
  RunResult run;
};

// The sample at `from` is the reference (U = 0 there), so the closed form
// to compare with is Terzaghi's measured from the same instant:
// (U(T) - U(T0)) / (1 - U(T0)), since the excess is (1 - U) of q.
Errors run_column(const Column& c) {
  const ParseResult r = parse_job(column_spec(c).dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  Errors out;
  if (!r.job) return out;
  out.run = run(r.job->problem);
  EXPECT_EQ(out.run.status, RunStatus::successful) << out.run.message;
  const RunResult::Consolidation& con = out.run.consolidation;
  EXPECT_EQ(con.time.size(), 100u);  // from T_v = 1e-4, then every 0.01 to 1
  const double u0 = closed_form::terzaghi_degree(1e-4);
  for (std::size_t i = 0; i < con.time.size(); ++i) {
    const double tv = con.time[i] / c.time_of(1.0);
    if (tv < 0.02 - 1e-9) continue;
    const double exact = (closed_form::terzaghi_degree(tv) - u0) / (1 - u0);
    out.degree = std::max(out.degree, std::abs(con.degree[i] - exact));
  }
  std::printf("consolidation under gravity, %d cells: max |U - U_exact| = %.4g over %zu samples\n",
              c.cells, out.degree, con.time.size());
  return out;
}

// Tolerance: U within 0.5 % (U integrates the excess, whose error in the
// interior is below 1 % of q, and the integral halves it: measured 0.28 %
// at 20 cells, 0.10 % at 40, 0.05 % at 80); it must not grow under
// refinement of the grid. Without the hydrostatic default the excess would
// include gamma_w (H - x) — on average 24.5 kPa against q = 50 kPa — and U
// would be off by far more than that.
TEST(Consolidation, SuddenLoadUnderGravityIsTerzaghisDegreeFromHydrostatic) {
  Column coarse;
  coarse.cells = 20;
  const Column fine;
  const Errors a = run_column(coarse), b = run_column(fine);
  EXPECT_LT(b.degree, 0.005);
  EXPECT_LE(b.degree, a.degree);
  // t50 from its interpolated samples: Terzaghi's T_v = 0.196731 measured
  // from T0 = 1e-4 (the reference instant moves it by less than 1e-4).
  EXPECT_NEAR(b.run.consolidation.t50 / fine.time_of(1.0), 0.196731, 0.196731 * 0.025);
}

// A selection counts only its particles: one holding the whole column
// gives what counting every particle gives, bit for bit; the lower half,
// next to the drained base, drains first (its U runs ahead of the
// column's, and the upper half's behind).
TEST(Consolidation, ASelectionCountsOnlyItsParticles) {
  Column c;
  c.cells = 20;
  auto run_with = [&](const json& particles) {
    json spec = column_spec(c);
    if (!particles.is_null()) spec["output"]["consolidation"]["particles"] = particles;
    const ParseResult r = parse_job(spec.dump());
    EXPECT_TRUE(r.job.has_value());
    return r.job ? hmpm::run(r.job->problem).consolidation : RunResult::Consolidation{};
  };
  auto box = [](double lo, double hi) {
    return json{{"box", {{"min", one(lo)}, {"max", one(hi)}}}};
  };
  const RunResult::Consolidation all = run_with(json());
  const RunResult::Consolidation whole = run_with(box(0.0, c.H));
  const RunResult::Consolidation lower = run_with(box(0.0, c.H / 2));
  const RunResult::Consolidation upper = run_with(box(c.H / 2, c.H));
  ASSERT_EQ(all.time.size(), 100u);
  EXPECT_EQ(whole.excess, all.excess);
  EXPECT_EQ(whole.degree, all.degree);
  ASSERT_EQ(lower.degree.size(), all.degree.size());
  ASSERT_EQ(upper.degree.size(), all.degree.size());
  EXPECT_NEAR(lower.volume.front() + upper.volume.front(), all.volume.front(),
              1e-12 * all.volume.front());
  const std::size_t k = 10;  // T_v = 0.1
  EXPECT_GT(lower.degree[k], all.degree[k] + 0.05);
  EXPECT_LT(upper.degree[k], all.degree[k] - 0.05);
}

// A load applied at t = 0 has no excess yet at t = 0: U is undefined, and
// the warning says to move `from` to the end of the loading; following it
// (the test above) defines U.
TEST(Consolidation, NoExcessAtFromWarnsToMoveFrom) {
  Column c;
  c.cells = 10;
  json spec = column_spec(c);
  spec["output"]["consolidation"].erase("from");
  spec["time"]["end"] = c.time_of(0.05);
  const ParseResult r = parse_job(spec.dump());
  ASSERT_TRUE(r.job.has_value());
  const RunResult run = hmpm::run(r.job->problem);
  EXPECT_EQ(run.status, RunStatus::successful) << run.message;
  ASSERT_FALSE(run.consolidation.time.empty());
  EXPECT_EQ(run.consolidation.time.front(), 0.0);
  for (double u : run.consolidation.degree) EXPECT_TRUE(std::isnan(u));
  bool warned = false;
  for (const std::string& w : run.warnings)
    warned = warned || (w.find("output.consolidation") != std::string::npos &&
                        w.find("set output.consolidation.from to the end of the loading") !=
                            std::string::npos);
  EXPECT_TRUE(warned);
}

TEST(Consolidation, ReadsItsKeysAndDefaults) {
  const Column c;
  json spec = column_spec(c);
  spec["output"]["consolidation"]["particles"] = {{"box", {{"min", one(0.0)}, {"max", one(2.5)}}}};
  ParseResult r = parse_job(spec.dump());
  ASSERT_TRUE(r.job.has_value());
  const ConsolidationRequest& con = r.job->problem.output.consolidation;
  EXPECT_DOUBLE_EQ(con.interval, c.time_of(0.01));
  EXPECT_DOUBLE_EQ(con.from, c.time_of(1e-4));
  EXPECT_FALSE(con.all);
  EXPECT_DOUBLE_EQ(con.particles.max[0], 2.5);
  // The default steady pressure: hydrostatic under the water table.
  ASSERT_TRUE(static_cast<bool>(con.steady_pore_pressure));
  EXPECT_NEAR(con.steady_pore_pressure(Vec3{1.0, 0, 0}), 1000 * 9.81 * (c.H - 1.0), 1e-9);
  // A given steady pressure (a number or a formula in x, y, z) replaces it.
  spec["output"]["consolidation"]["steady_pore_pressure"] = "1000*x";
  r = parse_job(spec.dump());
  ASSERT_TRUE(r.job.has_value());
  EXPECT_NEAR(r.job->problem.output.consolidation.steady_pore_pressure(Vec3{2.0, 0, 0}), 2000,
              1e-9);
}

TEST(Consolidation, MistakesAreReportedAtTheirPaths) {
  const Column c;
  json spec = column_spec(c);
  spec["output"]["consolidation"]["interval"] = 0;
  EXPECT_NE(issue_at(spec, "/output/consolidation/interval"), "");
  spec = column_spec(c);
  spec["output"]["consolidation"]["from"] = c.time_of(2.0);
  EXPECT_NE(issue_at(spec, "/output/consolidation/from").find("inside the run"), std::string::npos);
  spec = column_spec(c);
  spec["output"]["consolidation"]["particles"] = {
      {"box", {{"min", one(c.H + 0.05)}, {"max", one(c.H + 0.1)}}}};
  EXPECT_NE(issue_at(spec, "/output/consolidation/particles").find("selects no particle"),
            std::string::npos);
  spec = column_spec(c);
  spec["output"]["consolidation"]["steady"] = 0;
  EXPECT_NE(issue_at(spec, "/output/consolidation/steady"), "");
  // Dry: nothing to consolidate.
  spec = column_spec(c);
  spec["materials"]["clay"].erase("hydraulic");
  spec["initial_state"]["geostatic"].erase("water_table");
  spec["boundaries"][0].erase("pore_pressure");
  EXPECT_NE(issue_at(spec, "/output/consolidation").find("needs pore water"), std::string::npos);
}

// In a job of several stages `from` may lie in any stage: it is checked
// against the job's end, not against the end of each stage in force.
TEST(Consolidation, FromInALaterStageOfAStagedJobIsAccepted) {
  const Column c;
  json spec = column_spec(c);
  const double end = c.time_of(1.0);
  spec["time"]["end"] = end / 4;
  spec["stages"] = json::array(
      {json{{"name", "second"}, {"end", end / 2}}, json{{"name", "third"}, {"end", end}}});
  spec["output"]["consolidation"]["from"] = 0.75 * end;
  EXPECT_EQ(issue_at(spec, "/output/consolidation/from"), "");
  EXPECT_EQ(issue_at(spec, "/stages/0"), "");
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  // Past the job's end it is still refused, once, at its path.
  spec["output"]["consolidation"]["from"] = 1.5 * end;
  EXPECT_NE(issue_at(spec, "/output/consolidation/from").find("inside the run"), std::string::npos);
  EXPECT_EQ(issue_at(spec, "/stages/0"), "");
}

// Gravity on the pore water and no water table to take the hydrostatic
// pressure from: a warning whose advice gives the formula to write.
TEST(Consolidation, NoSteadyPressureUnderGravityWarnsWithTheFormula) {
  const Column c;
  json spec = column_spec(c);
  spec.erase("initial_state");
  const std::string w = issue_at(spec, "/output/consolidation", true);
  EXPECT_NE(w.find("steady_pore_pressure"), std::string::npos) << w;
  EXPECT_NE(w.find("9810*(WT - x)"), std::string::npos) << w;
  // Following it silences it.
  spec["output"]["consolidation"]["steady_pore_pressure"] = "9810*(5 - x)";
  EXPECT_EQ(issue_at(spec, "/output/consolidation", true), "");
}

// The output field excess_pore_pressure: the pore pressure minus the
// steady one at the particle's current position, with output.consolidation's
// reference (here its default, the hydrostatic pressure under the geostatic
// water table), asked for without output.consolidation. In the column
// loaded suddenly it is Terzaghi's excess, while the pore pressure itself
// carries the hydrostatic part (up to gamma_w H = 49 kPa against q = 50 kPa).
// Tolerance: 2 % of q (the interior error of the excess is below 1 % of q
// at 40 cells, see SuddenLoadUnderGravityIsTerzaghisDegreeFromHydrostatic,
// plus the finite-strain shift gamma_w s / q = 0.07 %). The definition
// itself, p - gamma_w (H - x) at the current x, holds to round-off.
TEST(ExcessPorePressure, IsTerzaghisExcessInAColumnWithAHydrostaticPart) {
  const Column c;
  json spec = column_spec(c);
  spec["output"].erase("consolidation");
  spec["time"]["end"] = c.time_of(0.3);
  spec["output"]["series"] = {
      {"particles",
       json::array({json{{"near", one(1.0)}}, json{{"near", one(2.5)}}, json{{"near", one(4.0)}}})},
      {"fields", {"position", "pore_pressure", "excess_pore_pressure"}},
      {"interval", c.time_of(0.1)}};
  spec["output"]["snapshots"] = {{"interval", c.time_of(0.1)},
                                 {"fields", {"pore_pressure", "excess_pore_pressure"}}};
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job.has_value());
  for (const SpecError& w : r.job->warnings) ADD_FAILURE() << w.path << ": " << w.message;
  const double gamma_w = 1000.0 * 9.81;
  double worst_definition = 0.0;
  std::size_t snapshots = 0;
  RunOptions options;
  options.on_snapshot = [&](const Snapshot& s) {
    ++snapshots;
    ASSERT_EQ(s.excess_pore_pressure.size(), static_cast<std::size_t>(s.particles));
    for (std::size_t p = 0; p < s.excess_pore_pressure.size(); ++p)
      worst_definition = std::max(
          worst_definition, std::abs(s.excess_pore_pressure[p] -
                                     (s.pore_pressure[p] - gamma_w * (c.H - s.position[3 * p]))));
  };
  const RunResult run = hmpm::run(r.job->problem, options);
  ASSERT_EQ(run.status, RunStatus::successful) << run.message;
  EXPECT_EQ(snapshots, 4u);  // t = 0 and T_v = 0.1, 0.2, 0.3
  EXPECT_LT(worst_definition, 1e-9 * c.q);
  const Series& s = run.series;
  ASSERT_EQ(s.time.size(), 4u);
  ASSERT_EQ(s.fields.size(), 3u);
  double worst = 0.0, hydrostatic = 0.0;
  for (std::size_t k = 1; k < s.time.size(); ++k) {
    const double tv = s.time[k] / c.time_of(1.0);
    for (std::size_t i = 0; i < s.particles.size(); ++i) {
      const double x = s.values[0][k * 3 + i], p = s.values[1][k * 3 + i];
      const double excess = s.values[2][k * 3 + i];
      EXPECT_NEAR(excess, p - gamma_w * (c.H - x), 1e-9 * c.q);
      const double exact = closed_form::terzaghi_pressure(s.initial_positions[i][0], tv, c.H, c.q);
      worst = std::max(worst, std::abs(excess - exact));
      hydrostatic = std::max(hydrostatic, p - excess);
    }
  }
  std::printf("excess pore pressure, 40 cells: max |u - u_Terzaghi| = %.4g q\n", worst / c.q);
  EXPECT_LT(worst, 0.02 * c.q);
  EXPECT_GT(hydrostatic, 0.5 * gamma_w * c.H);  // the pressure's hydrostatic part is not small
}

// A column at rest under its hydrostatic pressure: the excess is zero to
// round-off everywhere while the pore pressure is not. At t = 0 (the
// geostatic state) and after one long quasi-static step (T_v = 1): short
// steps on coarse cells leave the quasi-static scheme's known offset from
// hydrostatic of order h^3/dt (docs/schemes.md), which this field shows as
// it is (measured 889 Pa at the base with 10 cells and steps of T_v = 1e-4).
TEST(ExcessPorePressure, IsZeroInAHydrostaticColumnAtRest) {
  Column c;
  c.cells = 10;
  json spec = column_spec(c);
  spec.erase("tractions");
  spec["output"].erase("consolidation");
  spec["time"] = {{"end", c.time_of(1.0)}, {"scheme", "quasi_static"}, {"dt", c.time_of(1.0)}};
  spec["output"]["profiles"] = {
      {"interval", c.time_of(1.0)},
      {"lines", json::array({json{{"from", one(0.0)},
                                  {"to", one(c.H)},
                                  {"points", 11},
                                  {"fields", {"pore_pressure", "excess_pore_pressure"}}}})}};
  const ParseResult r = parse_job(spec.dump());
  ASSERT_TRUE(r.job.has_value());
  const RunResult run = hmpm::run(r.job->problem);
  ASSERT_EQ(run.status, RunStatus::successful) << run.message;
  ASSERT_EQ(run.profiles.size(), 1u);
  const Series& s = run.profiles[0];
  ASSERT_EQ(s.time.size(), 2u);
  // Row 0: the geostatic state, zero to round-off. Row 1: after the long
  // step, the scheme's offset from hydrostatic (measured 2.7 Pa, 5.6e-5 of
  // the largest pressure), bounded at 1e-4.
  const std::size_t np = s.particles.size();
  double largest_p = 0.0, excess0 = 0.0, excess1 = 0.0;
  for (double p : s.values[0]) largest_p = std::max(largest_p, std::abs(p));
  for (std::size_t i = 0; i < np; ++i) {
    excess0 = std::max(excess0, std::abs(s.values[1][i]));
    excess1 = std::max(excess1, std::abs(s.values[1][np + i]));
  }
  EXPECT_GT(largest_p, 0.8 * 1000.0 * 9.81 * c.H);
  EXPECT_LT(excess0, 1e-9 * largest_p);
  EXPECT_LT(excess1, 1e-4 * largest_p);
}

// Listed by name without a reference under gravity: the warning of
// output.consolidation, at the field's path, with the formula to write.
TEST(ExcessPorePressure, NoReferenceUnderGravityWarnsAtTheFieldsPath) {
  const Column c;
  json spec = column_spec(c);
  spec.erase("initial_state");
  spec["output"].erase("consolidation");
  spec["output"]["series"] = {{"particles", {0}},
                              {"fields", {"pore_pressure", "excess_pore_pressure"}}};
  const std::string w = issue_at(spec, "/output/series/fields/1", true);
  EXPECT_NE(w.find("9810*(WT - x)"), std::string::npos) << w;
  EXPECT_NE(w.find("water_table"), std::string::npos) << w;
}

// Profiles at listed times (isochrones): the quasi-static scheme's growing
// steps land on each listed time exactly (it shortens the step before),
// and each isochrone of the excess is Terzaghi's at its time (2 % of q, as
// above). T_v = 0.013, 0.07, 0.41: not multiples of anything the steps or
// the other outputs do.
TEST(ProfileTimes, QuasiStaticStepsLandOnTheListedTimes) {
  const Column c;
  json spec = column_spec(c);
  spec["output"].erase("consolidation");
  spec["time"]["end"] = c.time_of(0.5);
  const std::vector<double> tv = {0.013, 0.07, 0.41};
  json times = json::array();
  for (double v : tv) times.push_back(c.time_of(v));
  spec["output"]["profiles"] = {
      {"times", times},
      {"lines", json::array({json{{"from", one(0.0)},
                                  {"to", one(c.H)},
                                  {"points", 21},
                                  {"fields", {"excess_pore_pressure"}}}})}};
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job.has_value());
  EXPECT_EQ(r.job->problem.output.profile_times.size(), 3u);
  const RunResult run = hmpm::run(r.job->problem);
  ASSERT_EQ(run.status, RunStatus::successful) << run.message;
  ASSERT_EQ(run.profiles.size(), 1u);
  const Series& s = run.profiles[0];
  ASSERT_EQ(s.time.size(), 4u);  // t = 0 and the three listed
  EXPECT_EQ(s.time[0], 0.0);
  const std::size_t np = s.particles.size();
  double worst = 0.0;
  for (std::size_t k = 1; k < s.time.size(); ++k) {
    EXPECT_NEAR(s.time[k], times[k - 1].get<double>(), 1e-12 * s.time[k]);
    for (std::size_t i = 0; i < np; ++i) {
      const double exact =
          closed_form::terzaghi_pressure(s.initial_positions[i][0], tv[k - 1], c.H, c.q);
      worst = std::max(worst, std::abs(s.values[0][k * np + i] - exact));
    }
  }
  std::printf("isochrones at listed times: max |u - u_Terzaghi| = %.4g q\n", worst / c.q);
  EXPECT_LT(worst, 0.02 * c.q);
}

// Fixed steps cannot land on a listed time: the sample is the end of the
// first step that reaches it, and profiles say that step's time (at most
// one step late), never the listed one. With an interval as well, both
// schedules are sampled, each once.
TEST(ProfileTimes, FixedStepsSampleTheFirstStepReachingEachTimeAndSayWhen) {
  Column c;
  c.cells = 10;
  json spec = column_spec(c);
  spec["output"].erase("consolidation");
  const double end = c.time_of(0.1), dt = end / 40;
  spec["time"] = {{"end", end}, {"scheme", "quasi_static"}, {"dt", dt}};
  const std::vector<double> listed = {0.33 * dt, 7.5 * dt, 20 * dt};
  spec["output"]["profiles"] = {
      {"times", listed},
      {"interval", 10 * dt},
      {"lines",
       json::array({json{
           {"from", one(0.0)}, {"to", one(c.H)}, {"points", 3}, {"fields", {"pore_pressure"}}}})}};
  const ParseResult r = parse_job(spec.dump());
  for (const SpecError& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job.has_value());
  const RunResult run = hmpm::run(r.job->problem);
  ASSERT_EQ(run.status, RunStatus::successful) << run.message;
  ASSERT_EQ(run.profiles.size(), 1u);
  const std::vector<double>& t = run.profiles[0].time;
  // 0; dt (for 0.33 dt); 8 dt (for 7.5 dt); 10, 20 (listed and interval: once), 30, 40 dt.
  const std::vector<double> expected = {0, 1, 8, 10, 20, 30, 40};
  ASSERT_EQ(t.size(), expected.size());
  for (std::size_t k = 0; k < t.size(); ++k) EXPECT_NEAR(t[k], expected[k] * dt, 1e-9 * dt) << k;
}

TEST(ProfileTimes, MistakesAreReportedAtTheirPaths) {
  const Column c;
  json spec = column_spec(c);
  const json line =
      json{{"from", one(0.0)}, {"to", one(c.H)}, {"points", 3}, {"fields", {"pore_pressure"}}};
  const double end = spec["time"]["end"].get<double>();
  auto with_times = [&](const json& times) {
    json s = spec;
    s["output"]["profiles"] = {{"times", times}, {"lines", json::array({line})}};
    return s;
  };
  EXPECT_EQ(issue_at(with_times(json::array({0.0, end / 2, end})), "/output/profiles"), "");
  EXPECT_NE(issue_at(with_times(json::array({end / 2, end / 4})), "/output/profiles/times/1")
                .find("increasing order"),
            std::string::npos);
  EXPECT_NE(issue_at(with_times(json::array({end / 2, end / 2})), "/output/profiles/times/1")
                .find("increasing order"),
            std::string::npos);
  EXPECT_NE(issue_at(with_times(json::array({-1.0})), "/output/profiles/times/0").find("[0, "),
            std::string::npos);
  EXPECT_NE(issue_at(with_times(json::array({end / 2, 2 * end})), "/output/profiles/times/1")
                .find("inside the run"),
            std::string::npos);
  EXPECT_NE(issue_at(with_times(json::array()), "/output/profiles/times"), "");
  EXPECT_NE(issue_at(with_times("soon"), "/output/profiles/times"), "");
  EXPECT_NE(issue_at(with_times(json::array({"soon"})), "/output/profiles/times/0"), "");
  // Neither an interval nor times: said at the interval's path.
  json none = spec;
  none["output"]["profiles"] = {{"lines", json::array({line})}};
  EXPECT_NE(issue_at(none, "/output/profiles/interval").find("times"), std::string::npos);
}

}  // namespace
}  // namespace hmpm::api
