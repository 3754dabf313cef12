// test_hints.cpp — every "what to change" hint of the spec checks
// (api/src/parse/, solver/src/problem/, the schemes' *_rules.cpp, the
// geostatic checks) points the right way: the change it suggests, applied,
// removes the error or warning, and the opposite change does not.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "spec_support.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling

using testing::example;
using testing::issue_at;
using testing::number_after;

// ------------------------------------------------ the Darcy-inertia warning

// A fluid softer than the skeleton (darcy-flow with Kf = 1.5 MPa, 1.73 times
// the limit): the hint names the fluid modulus that ends the regime; it and
// anything stiffer remove the warning, 0.9 of it does not.
TEST(Hints, SoftFluidNeedsTheFluidModulusTheHintNames) {
  json spec = example("darcy-flow");
  json& h = spec["materials"]["soil"]["hydraulic"];
  h["fluid_bulk_modulus"] = 1.5e6;
  const std::string path = "/materials/soil/hydraulic";
  const std::string m = issue_at(spec, path, true);
  const double kf = number_after(m, "a stiffer fluid_bulk_modulus (at least ");
  ASSERT_FALSE(std::isnan(kf)) << m;
  EXPECT_GT(kf, 1.5e6);
  h["fluid_bulk_modulus"] = kf;
  EXPECT_EQ(issue_at(spec, path, true), "");
  h["fluid_bulk_modulus"] = 0.9 * kf;
  EXPECT_NE(issue_at(spec, path, true), "");
}

// Issue 17: E = 5e12 Pa (a unit slip) with water was told "a stiffer
// fluid_bulk_modulus", but no fluid stiffer than water exists: water's
// 2.2e9 Pa keeps the warning. The hint now says so and names the Young's
// modulus that ends the regime, which removes it.
TEST(Hints, StiffSkeletonIsNotToldToStiffenTheFluid) {
  json spec = example("darcy-flow");
  spec["materials"]["soil"]["youngs_modulus"] = 5e12;
  json& h = spec["materials"]["soil"]["hydraulic"];
  const std::string path = "/materials/soil/hydraulic";
  h["fluid_bulk_modulus"] = 2.2e9;
  const std::string m = issue_at(spec, path, true);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m.find("a stiffer fluid_bulk_modulus"), std::string::npos) << m;
  EXPECT_NE(m.find("no fluid_bulk_modulus up to water's"), std::string::npos) << m;
  const double e = number_after(m, "youngs_modulus at most ");
  ASSERT_FALSE(std::isnan(e)) << m;
  EXPECT_LT(e, 5e12);
  spec["materials"]["soil"]["youngs_modulus"] = e;
  EXPECT_EQ(issue_at(spec, path, true), "");
  spec["materials"]["soil"]["youngs_modulus"] = 1.2 * e;
  EXPECT_NE(issue_at(spec, path, true), "");
}

// ------------------------------------------------ time steps

// "use dt <= L": L runs, a larger dt does not, and omitting dt runs.
TEST(Hints, DtAboveTheStableLimitOfEachExplicitScheme) {
  for (const char* scheme : {"explicit", "semi_implicit"}) {
    json spec = example("terzaghi");
    spec["time"]["scheme"] = scheme;
    spec["time"]["dt"] = 1.0;
    const std::string m = issue_at(spec, "/time/dt");
    const double limit = number_after(m, "use dt <= ");
    ASSERT_FALSE(std::isnan(limit)) << scheme << ": " << m;
    spec["time"]["dt"] = limit;
    EXPECT_EQ(issue_at(spec, "/time/dt"), "") << scheme;
    spec["time"]["dt"] = 1.01 * limit;
    EXPECT_NE(issue_at(spec, "/time/dt"), "") << scheme;
    spec["time"].erase("dt");
    EXPECT_EQ(issue_at(spec, "/time/dt"), "") << scheme;
  }
}

// "shorten time.end or use a coarser grid": both cut the steps below the
// limit; a finer grid does not.
TEST(Hints, TooManyStepsShortenOrCoarsen) {
  json spec = example("bar-vibration");  // 2530 steps of 1 ms
  spec["time"].erase("dt");
  Limits limits;
  limits.max_steps = 100;
  const std::string m = issue_at(spec, "/time/end", false, limits);
  ASSERT_NE(m.find("shorten time.end or use a coarser grid"), std::string::npos) << m;
  json shorter = spec;
  shorter["time"]["end"] = spec["time"]["end"].get<double>() / 20;
  EXPECT_EQ(issue_at(shorter, "/time/end", false, limits), "");
  json coarser = spec;
  coarser["grid"]["cells"][0] = 1;
  coarser["grid"]["max"][0] = 1;
  EXPECT_EQ(issue_at(coarser, "/time/end", false, limits), "");
  json finer = spec;
  finer["grid"]["cells"][0] = 2 * spec["grid"]["cells"][0].get<int>();
  EXPECT_NE(issue_at(finer, "/time/end", false, limits), "");
}

// The step limit's scheme advice: the quasi-static plan it spells out runs
// within the limit.
TEST(Hints, TooManyStepsTheSuggestedSchemeAndPlanFit) {
  json spec = example("soft-clay");
  spec["time"] = {{"end", spec["time"]["end"]}};  // explicit, automatic dt
  Limits limits;
  limits.max_steps = 10000;
  const std::string m = issue_at(spec, "/time/end", false, limits);
  const std::size_t at = m.find("steps with dt ");
  ASSERT_NE(at, std::string::npos) << m;
  const std::size_t from = at + std::string("steps with dt ").size();
  const json plan = json::parse(m.substr(from, m.find('}', from) - from + 1));
  spec["time"]["scheme"] = "quasi_static";
  spec["time"]["dt"] = plan;
  const ParseResult r = parse_job(spec.dump(), limits);
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].message);
}

// "use a larger interval" for series rows and snapshots.
TEST(Hints, TooManyRowsOrSnapshotsUseALargerInterval) {
  json spec = example("terzaghi");
  Limits limits;
  limits.max_series_rows = 50;
  limits.max_snapshots = 5;
  spec["output"]["series"]["interval"] = 0.1;
  spec["output"]["snapshots"] = {{"interval", 1.0}};
  ASSERT_NE(issue_at(spec, "/output/series/interval", false, limits).find("use a larger interval"),
            std::string::npos);
  ASSERT_NE(
      issue_at(spec, "/output/snapshots/interval", false, limits).find("use a larger interval"),
      std::string::npos);
  spec["output"]["series"]["interval"] = 10.0;
  spec["output"]["snapshots"]["interval"] = 20.0;
  EXPECT_EQ(issue_at(spec, "/output/series/interval", false, limits), "");
  EXPECT_EQ(issue_at(spec, "/output/snapshots/interval", false, limits), "");
}

// ------------------------------------------------ bodies

/// A 2D body of a regular polygon with `vertices` corners (radius 4 m) on
/// a 100 x 100 grid of 0.1 m cells.
json round_body(int vertices, int particles_per_cell) {
  json spec = json::parse(R"json({"dimension": 2,
    "grid": {"min": [0, 0], "max": [10, 10], "cells": [100, 100]},
    "materials": {"m": {"model": "linear_elastic", "density": 2000, "youngs_modulus": 1e7,
                        "poisson_ratio": 0.3}},
    "bodies": [{"material": "m", "polygon": []}], "time": {"end": 0.001}})json");
  json& poly = spec["bodies"][0]["polygon"];
  for (int k = 0; k < vertices; ++k) {
    const double a = 2 * std::numbers::pi * k / vertices;
    poly.push_back({5 + 4 * std::cos(a), 5 + 4 * std::sin(a)});
  }
  spec["bodies"][0]["particles_per_cell"] = particles_per_cell;
  return spec;
}

// "use fewer vertices, fewer particles per cell or a coarser grid": 2.5e8
// tests (81 x 81 cells x 25 sub-cells x 1500 edges) above the 2e8 bound;
// each of the three suggested changes brings it below.
TEST(Hints, PolygonFillTooMuchWorkEachSuggestedChangeHelps) {
  const std::string path = "/bodies/0/polygon";
  ASSERT_NE(issue_at(round_body(1500, 5), path).find("use fewer vertices"), std::string::npos);
  EXPECT_EQ(issue_at(round_body(1000, 5), path), "");
  EXPECT_EQ(issue_at(round_body(1500, 4), path), "");
  json coarser = round_body(1500, 5);
  coarser["grid"]["cells"] = {80, 80};
  EXPECT_EQ(issue_at(coarser, path), "");
}

// "enlarge the shape or refine the grid" for a polygon between sub-cell centres.
TEST(Hints, PolygonWithoutParticlesEnlargeOrRefine) {
  json spec = round_body(8, 1);
  spec["grid"]["cells"] = {10, 10};  // 1 m cells: centres at x.5
  spec["bodies"][0]["polygon"] = {{5.1, 5.1}, {5.4, 5.1}, {5.4, 5.4}, {5.1, 5.4}};
  const std::string path = "/bodies/0/polygon";
  ASSERT_NE(issue_at(spec, path).find("enlarge the shape or refine the grid"), std::string::npos);
  json refined = spec;
  refined["grid"]["cells"] = {40, 40};  // centres every 0.25 m: 5.125, 5.375
  EXPECT_EQ(issue_at(refined, path), "");
  json enlarged = spec;
  enlarged["bodies"][0]["polygon"] = {{5.1, 5.1}, {5.6, 5.1}, {5.6, 5.6}, {5.1, 5.6}};
  EXPECT_EQ(issue_at(enlarged, path), "");
}

// The overlap warning: shrinking the later body ends it; listing it first
// moves the shared places to it, and the warning to the other body (as the
// hint says).
TEST(Hints, OverlappingBodiesShrinkOrReorder) {
  json spec = example("geostatic");
  spec["bodies"][1]["box"]["min"][1] = 0.8;  // sand reaches into the clay
  const std::string m = issue_at(spec, "/bodies/1", true);
  ASSERT_NE(m.find("shrink body 1"), std::string::npos) << m;
  json shrunk = spec;
  shrunk["bodies"][1]["box"]["min"][1] = 1.0;
  EXPECT_EQ(issue_at(shrunk, "/bodies/1", true), "");
  json reordered = spec;
  std::swap(reordered["bodies"][0], reordered["bodies"][1]);
  EXPECT_EQ(issue_at(reordered, "/bodies/0", true), "");
  EXPECT_NE(issue_at(reordered, "/bodies/1", true).find("overlaps body 0"), std::string::npos);
}

// ------------------------------------------------ geostatic

// "lower the table to the surface": the surface is accepted, above it not.
TEST(Hints, WaterTableAboveTheGroundLowerIt) {
  json spec = example("geostatic");
  spec["bodies"].erase(2);  // no dry crust: the ground ends at y = 1.6
  spec["initial_state"]["geostatic"]["water_table"] = 1.8;
  const std::string path = "/initial_state/geostatic/water_table";
  ASSERT_NE(issue_at(spec, path).find("lower the table to the surface"), std::string::npos);
  spec["initial_state"]["geostatic"]["water_table"] = 1.6;
  EXPECT_EQ(issue_at(spec, path), "");
}

}  // namespace
}  // namespace hmpm::api
