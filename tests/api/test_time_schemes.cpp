// test_time_schemes.cpp — the api side of the time schemes: time.scheme,
// time.dt as a number or a step growth, time.implicit with its defaults and
// bounds, the warning when implicit controls meet the explicit scheme, and
// the tables `hmpm spec-keys` prints for them.
#include <algorithm>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling

json base_spec() {
  return json::parse(R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [10]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0}},
    "bodies": [{"material": "m", "box": {"min": [0], "max": [1]}}], "time": {"end": 1}})json");
}

std::string listing(const ParseResult& r) {
  std::string s;
  for (const auto& e : r.errors) s += e.path + ": " + e.message + "\n";
  return s;
}

/// The message of the one error at `path` ("" when there is none).
std::string error_at(const ParseResult& r, const std::string& path) {
  for (const auto& e : r.errors)
    if (e.path == path) return e.message;
  return "";
}

ParseResult parse_time(const json& time) {
  json spec = base_spec();
  spec["time"] = time;
  return parse_job(spec.dump());
}

TEST(TimeSchemes, ExplicitIsTheDefaultAndImplicitControlsHaveTheirDefaults) {
  const ParseResult r = parse_time({{"end", 1}});
  ASSERT_TRUE(r.ok()) << listing(r);
  const TimeControl& t = r.job->problem.time;
  EXPECT_EQ(t.scheme, Scheme::explicit_scheme);
  EXPECT_FALSE(t.growth.has_value());
  const ImplicitControl defaults;
  EXPECT_DOUBLE_EQ(t.implicit.tolerance, defaults.tolerance);
  EXPECT_EQ(t.implicit.max_iterations, defaults.max_iterations);
  EXPECT_EQ(t.implicit.max_cutbacks, defaults.max_cutbacks);
  EXPECT_EQ(t.implicit.linear_solver, LinearSolver::automatic);
  EXPECT_DOUBLE_EQ(t.implicit.linear_tolerance, defaults.linear_tolerance);
  EXPECT_TRUE(r.job->warnings.empty());
}

TEST(TimeSchemes, EachSchemeNameReadsBack) {
  for (Scheme s : {Scheme::explicit_scheme, Scheme::semi_implicit, Scheme::quasi_static}) {
    const ParseResult r = parse_time({{"end", 1}, {"scheme", scheme_name(s)}});
    ASSERT_TRUE(r.ok()) << listing(r);
    EXPECT_EQ(r.job->problem.time.scheme, s);
  }
}

TEST(TimeSchemes, UnknownSchemeListsTheAcceptedNames) {
  const ParseResult r = parse_time({{"end", 1}, {"scheme", "implicit"}});
  const std::string m = error_at(r, "/time/scheme");
  EXPECT_NE(m.find("unknown value 'implicit'"), std::string::npos) << listing(r);
  for (const char* name : {"'explicit'", "'semi_implicit'", "'quasi_static'"})
    EXPECT_NE(m.find(name), std::string::npos) << m;
  EXPECT_FALSE(error_at(parse_time({{"end", 1}, {"scheme", 3}}), "/time/scheme").empty());
}

TEST(TimeSchemes, StepGrowthWithQuasiStatic) {
  const ParseResult r =
      parse_time({{"end", 100},
                  {"scheme", "quasi_static"},
                  {"dt", {{"initial", 0.5}, {"max", 10}, {"growth", 1.5}}}});
  ASSERT_TRUE(r.ok()) << listing(r);
  const TimeControl& t = r.job->problem.time;
  EXPECT_FALSE(t.dt.has_value());
  ASSERT_TRUE(t.growth.has_value());
  EXPECT_DOUBLE_EQ(t.growth->initial, 0.5);
  EXPECT_DOUBLE_EQ(t.growth->max, 10);
  EXPECT_DOUBLE_EQ(t.growth->growth, 1.5);
  // A number still is a fixed step; absent lets the solver choose. (Below
  // the explicit limit 0.1 s: until the quasi-static scheme lands, the
  // solver checks every dt against the explicit rule.)
  const ParseResult fixed = parse_time({{"end", 1}, {"scheme", "quasi_static"}, {"dt", 0.05}});
  ASSERT_TRUE(fixed.ok()) << listing(fixed);
  EXPECT_DOUBLE_EQ(*fixed.job->problem.time.dt, 0.05);
  EXPECT_FALSE(fixed.job->problem.time.growth.has_value());
}

TEST(TimeSchemes, StepGrowthBoundsNameTheirPaths) {
  const auto growth = [](double initial, double max, double factor) {
    return parse_time({{"end", 100},
                       {"scheme", "quasi_static"},
                       {"dt", {{"initial", initial}, {"max", max}, {"growth", factor}}}});
  };
  ParseResult r = growth(0, 10, 1.5);
  EXPECT_NE(error_at(r, "/time/dt/initial").find("> 0"), std::string::npos) << listing(r);
  r = growth(1, 0.5, 1.5);
  EXPECT_NE(error_at(r, "/time/dt/max").find("below initial 1 s"), std::string::npos)
      << listing(r);
  r = growth(1, 10, 0.9);
  EXPECT_NE(error_at(r, "/time/dt/growth").find(">= 1"), std::string::npos) << listing(r);
  // growth = 1 and max = initial are a fixed step, accepted.
  EXPECT_TRUE(growth(1, 1, 1).ok());
  r = parse_time({{"end", 1}, {"scheme", "quasi_static"}, {"dt", {{"initial", 1}, {"max", 2}}}});
  EXPECT_NE(error_at(r, "/time/dt/growth").find("required"), std::string::npos) << listing(r);
  r = parse_time({{"end", 1},
                  {"scheme", "quasi_static"},
                  {"dt", {{"initial", 1}, {"max", 2}, {"growth", 2}, {"grow", 1}}}});
  EXPECT_NE(error_at(r, "/time/dt/grow").find("growth"), std::string::npos) << listing(r);
}

TEST(TimeSchemes, StepGrowthWithAnotherSchemeSaysWhatToChange) {
  for (const char* scheme : {"explicit", "semi_implicit"}) {
    const ParseResult r = parse_time(
        {{"end", 1}, {"scheme", scheme}, {"dt", {{"initial", 1}, {"max", 2}, {"growth", 2}}}});
    const std::string m = error_at(r, "/time/dt");
    EXPECT_NE(m.find("only with time.scheme 'quasi_static'"), std::string::npos) << listing(r);
    EXPECT_NE(m.find("as a number"), std::string::npos) << m;
    EXPECT_NE(m.find(scheme), std::string::npos) << m;
  }
  // The same without a scheme key (explicit by default).
  const ParseResult r = parse_time({{"end", 1}, {"dt", {{"initial", 1}, {"max", 2}, {"growth", 2}}}});
  EXPECT_FALSE(error_at(r, "/time/dt").empty()) << listing(r);
  // Neither a number nor an object.
  const ParseResult s = parse_time({{"end", 1}, {"scheme", "quasi_static"}, {"dt", "1"}});
  EXPECT_NE(error_at(s, "/time/dt").find("or an object"), std::string::npos) << listing(s);
}

TEST(TimeSchemes, ImplicitControlsReadBackWithTheirBounds) {
  const ParseResult r = parse_time({{"end", 1},
                                    {"scheme", "semi_implicit"},
                                    {"implicit",
                                     {{"tolerance", 1e-6},
                                      {"max_iterations", 40},
                                      {"max_cutbacks", 3},
                                      {"linear_solver", "iterative"},
                                      {"linear_tolerance", 1e-10}}}});
  ASSERT_TRUE(r.ok()) << listing(r);
  const ImplicitControl& ic = r.job->problem.time.implicit;
  EXPECT_DOUBLE_EQ(ic.tolerance, 1e-6);
  EXPECT_EQ(ic.max_iterations, 40);
  EXPECT_EQ(ic.max_cutbacks, 3);
  EXPECT_EQ(ic.linear_solver, LinearSolver::iterative);
  EXPECT_DOUBLE_EQ(ic.linear_tolerance, 1e-10);
  EXPECT_TRUE(r.job->warnings.empty());
  for (const auto& [solver, value] :
       {std::pair{"auto", LinearSolver::automatic}, std::pair{"direct", LinearSolver::direct}}) {
    const ParseResult d = parse_time(
        {{"end", 1}, {"scheme", "quasi_static"}, {"implicit", {{"linear_solver", solver}}}});
    ASSERT_TRUE(d.ok()) << listing(d);
    EXPECT_EQ(d.job->problem.time.implicit.linear_solver, value);
  }

  const ParseResult bad = parse_time({{"end", 1},
                                      {"scheme", "quasi_static"},
                                      {"implicit",
                                       {{"tolerance", 0},
                                        {"max_iterations", 0},
                                        {"max_cutbacks", 2.5},
                                        {"linear_solver", "cholesky"},
                                        {"linear_tolerance", 1}}}});
  for (const char* key : {"tolerance", "max_iterations", "max_cutbacks", "linear_solver",
                          "linear_tolerance"})
    EXPECT_FALSE(error_at(bad, std::string("/time/implicit/") + key).empty())
        << key << "\n"
        << listing(bad);
  EXPECT_NE(error_at(bad, "/time/implicit/linear_solver").find("'iterative'"), std::string::npos);
}

TEST(TimeSchemes, ImplicitControlsWithTheExplicitSchemeAreAWarning) {
  for (const json& time : {json{{"end", 1}, {"implicit", {{"tolerance", 1e-6}}}},
                           json{{"end", 1}, {"scheme", "explicit"}, {"implicit", json::object()}}}) {
    const ParseResult r = parse_time(time);
    ASSERT_TRUE(r.ok()) << listing(r);
    ASSERT_EQ(r.job->warnings.size(), 1u);
    EXPECT_EQ(r.job->warnings[0].path, "/time/implicit");
    EXPECT_NE(r.job->warnings[0].message.find("ignored by the explicit scheme"), std::string::npos);
  }
}

TEST(TimeSchemes, SpecTablesListTheSchemeKeysAndValues) {
  const json tables = json::parse(spec_tables_json());
  EXPECT_EQ(tables["values"]["/time/scheme"],
            (json{"explicit", "semi_implicit", "quasi_static"}));
  EXPECT_EQ(tables["values"]["/time/implicit/linear_solver"],
            (json{"auto", "direct", "iterative"}));
  EXPECT_EQ(tables["objects"]["/time/dt"], (json{"initial", "max", "growth"}));
  EXPECT_EQ(tables["objects"]["/time/implicit"].size(), 5u);
  const json time_keys = tables["objects"]["/time"];
  EXPECT_NE(std::find(time_keys.begin(), time_keys.end(), "scheme"), time_keys.end());
  EXPECT_NE(std::find(time_keys.begin(), time_keys.end(), "implicit"), time_keys.end());
}

}  // namespace
}  // namespace hmpm::api
