// test_parse_job.cpp — a valid spec becomes exactly the Problem it describes:
// every field, the defaults of the contract, compiled expressions, resolved
// particle selections, the cost estimate and the known-key table.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <variant>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "spec_support.hpp"
#include "test_support.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling
using testing::read_text;
using testing::source_path;

ParsedJob parse_valid(const std::string& text) {
  ParseResult r = parse_job(text);
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  EXPECT_TRUE(r.job.has_value());
  return r.job ? std::move(*r.job) : ParsedJob{};
}

TEST(ParseJob, RoundTripOfEveryField) {
  const ParsedJob job = parse_valid(read_text(source_path("tests/api/data/valid-2d.json")));
  const Problem& p = job.problem;
  EXPECT_EQ(job.name, "valid-2d");
  EXPECT_EQ(p.dimension, 2);
  EXPECT_EQ(p.grid.min, (Vec3{0, 0, 0}));
  EXPECT_EQ(p.grid.max, (Vec3{1, 1, 0}));
  EXPECT_EQ(p.grid.cells[0], 4);
  EXPECT_EQ(p.grid.cells[1], 4);
  EXPECT_EQ(p.shape_function, ShapeFunction::linear);
  ASSERT_EQ(p.materials.size(), 2u);
  // Materials are held in key order; bodies refer to them by index.
  const Material& sand = p.materials[static_cast<std::size_t>(p.bodies.at(0).material)];
  const Material& other = p.materials[static_cast<std::size_t>(p.bodies.at(1).material)];
  EXPECT_EQ(sand.name, "sand");
  EXPECT_EQ(other.name, "a/b~c");
  EXPECT_DOUBLE_EQ(sand.density, 2650);
  EXPECT_DOUBLE_EQ(sand.youngs_modulus, 1e7);
  EXPECT_DOUBLE_EQ(sand.poisson_ratio, 0.3);
  ASSERT_TRUE(std::holds_alternative<MohrCoulomb>(sand.plasticity));
  const auto& mc = std::get<MohrCoulomb>(sand.plasticity);
  EXPECT_DOUBLE_EQ(mc.friction_angle_deg, 30);
  EXPECT_DOUBLE_EQ(mc.dilatancy_angle_deg, 5);
  EXPECT_DOUBLE_EQ(mc.cohesion, 1000);
  EXPECT_DOUBLE_EQ(mc.tensile_strength, 10);
  ASSERT_TRUE(sand.hydraulic.has_value());
  EXPECT_DOUBLE_EQ(sand.hydraulic->porosity, 0.3);
  EXPECT_DOUBLE_EQ(sand.hydraulic->hydraulic_conductivity, 1e-3);
  EXPECT_DOUBLE_EQ(sand.hydraulic->fluid_bulk_modulus, 2.2e9);
  EXPECT_DOUBLE_EQ(sand.hydraulic->fluid_density, 1000);        // default
  EXPECT_TRUE(std::isinf(sand.hydraulic->solid_bulk_modulus));  // default: incompressible grains
  EXPECT_TRUE(sand.hydraulic->darcy_inertia);                   // default: the paper's model
  EXPECT_TRUE(std::holds_alternative<LinearElastic>(other.plasticity));
  EXPECT_FALSE(other.hydraulic.has_value());

  ASSERT_EQ(p.bodies.size(), 2u);
  const Body& b0 = p.bodies[0];
  EXPECT_EQ(b0.box.max, (Vec3{1, 0.5, 0}));
  EXPECT_EQ(b0.particles_per_cell, 2);
  EXPECT_EQ(p.bodies[1].particles_per_cell, 2);  // default
  ASSERT_TRUE(b0.initial.velocity[0]);
  EXPECT_DOUBLE_EQ(b0.initial.velocity[0]({0.3, 0.2, 0}), 0.0);
  EXPECT_NEAR(b0.initial.velocity[1]({0.5, 0.2, 0}), 0.1, 1e-15);
  EXPECT_NEAR(b0.initial.pore_pressure({0.1, 0.25, 0}), 250.0, 1e-12);
  EXPECT_DOUBLE_EQ(b0.initial.effective_stress[0]({0, 0, 0}), -1000);
  EXPECT_NEAR(b0.initial.effective_stress[1]({0, 0.25, 0}), -500, 1e-12);
  EXPECT_FALSE(p.bodies[1].initial.pore_pressure);  // absent: zero

  EXPECT_EQ(p.gravity, (Vec3{0, -9.81, 0}));
  EXPECT_DOUBLE_EQ(p.gravity_constant, 9.81);
  EXPECT_DOUBLE_EQ(p.local_damping(0.0), 0.05);

  ASSERT_EQ(p.boundaries.size(), 3u);
  EXPECT_FALSE(p.boundaries[0].nodes.all);
  EXPECT_TRUE(p.boundaries[0].has_velocity);
  EXPECT_TRUE(p.boundaries[1].velocity[0].has_value());
  EXPECT_FALSE(p.boundaries[1].velocity[1].has_value());  // null: free
  EXPECT_FALSE(p.boundaries[2].has_velocity);
  ASSERT_TRUE(p.boundaries[2].pore_pressure.has_value());
  EXPECT_DOUBLE_EQ((*p.boundaries[2].pore_pressure)(2.0), 200.0);

  ASSERT_EQ(p.tractions.size(), 1u);
  EXPECT_EQ(p.tractions[0].axis, 1);
  EXPECT_EQ(p.tractions[0].side, +1);
  EXPECT_DOUBLE_EQ(p.tractions[0].traction[1](0.5), -500.0);
  EXPECT_DOUBLE_EQ(p.tractions[0].traction[1](3.0), -1000.0);

  EXPECT_DOUBLE_EQ(p.time.end, 0.01);
  EXPECT_FALSE(p.time.dt.has_value());
  EXPECT_DOUBLE_EQ(p.time.courant, 0.4);

  ASSERT_EQ(p.output.series_particles.size(), 2u);
  EXPECT_EQ(p.output.series_particles[0], 0);
  EXPECT_EQ(p.output.series_particles[1], nearest_particle(p, {0.5, 0.25, 0}));
  EXPECT_EQ(p.output.series_fields, (std::vector<Field>{Field::displacement, Field::pore_pressure,
                                                        Field::effective_stress}));
  EXPECT_DOUBLE_EQ(p.output.series_interval, 0.001);
  EXPECT_DOUBLE_EQ(p.output.snapshot_interval, 0.005);
  EXPECT_DOUBLE_EQ(p.output.reactions_interval, 0.002);
  // position is added: it is the VTU Points.
  EXPECT_EQ(p.output.snapshot_fields, (std::vector<Field>{Field::position, Field::velocity}));

  const CostEstimate& c = job.cost;
  EXPECT_EQ(c.particles, 48);  // 8 cells * 4 + 4 cells * 4
  EXPECT_EQ(c.cells, 16);
  EXPECT_EQ(c.nodes, 25);
  EXPECT_DOUBLE_EQ(c.dt, stable_step(p).chosen);
  EXPECT_EQ(c.steps, static_cast<std::int64_t>(std::ceil(0.01 / c.dt - 1e-9)));
  EXPECT_EQ(c.particle_steps, 48 * c.steps);
  EXPECT_EQ(c.series_rows, 11);
  EXPECT_EQ(c.snapshots, 3);
  EXPECT_GT(c.memory_bytes, 48 * 400);
  EXPECT_GT(c.output_bytes, 0);
}

// Issue 22 item 7: the memory estimate counts a private copy of the
// grid's nodal sums per extra solver thread, and the series kept in memory.
TEST(CostEstimate, MemoryCountsThreadBuffersAndTheSeries) {
  const ParsedJob job = parse_valid(R"json({"dimension": 2,
      "grid": {"min": [0, 0], "max": [1, 1], "cells": [400, 400]},
      "materials": {"m": {"model": "linear_elastic", "density": 2000, "youngs_modulus": 1e7,
                          "poisson_ratio": 0.3}},
      "bodies": [{"material": "m", "box": {"min": [0, 0], "max": [1, 1]},
                  "particles_per_cell": 1}],
      "time": {"end": 1e-6, "dt": 1e-7}})json");
  Calibration one, eight;
  eight.threads = 8;
  const CostEstimate c1 = estimate_cost(job.problem, one);
  const CostEstimate c8 = estimate_cost(job.problem, eight);
  EXPECT_EQ(c1.threads, 1);
  EXPECT_EQ(c8.threads, 8);  // 160 000 particles: 20 000 per thread
  // Mass, momentum, force and remap per node: 8 * (1 + 3 * 2) bytes.
  EXPECT_EQ(c8.memory_bytes - c1.memory_bytes, 7 * c1.nodes * 8 * 7);

  ParsedJob series = job;
  series.problem.output.series_particles.assign(1000, 0);
  series.problem.output.series_fields = {Field::effective_stress};
  const CostEstimate cs = estimate_cost(series.problem, one);
  EXPECT_EQ(cs.series_rows, 11);
  // 11 rows of 1 + 1000 * 6 values, with room for the vectors' growth.
  EXPECT_GE(cs.memory_bytes - c1.memory_bytes, 11 * 6001 * 8);
}

// Issue 22 item 5: the formulas of a spec are bounded in count and length.
TEST(ParseJob, FormulaBudgetIsEnforced) {
  std::string f = "x";
  while (f.size() < 4000) f += "+x";
  std::string bodies;
  for (int b = 0; b < 20; ++b)
    bodies += std::string(b ? "," : "") +
              R"({"material": "m", "box": {"min": [0], "max": [1]}, "initial": {"velocity": [")" +
              f + R"("]}})";
  const std::string spec = R"({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [10]},
      "materials": {"m": {"model": "linear_elastic", "density": 2000, "youngs_modulus": 1e7,
                          "poisson_ratio": 0.3}},
      "bodies": [)" + bodies +
                           R"(], "time": {"end": 1e-3}})";
  const ParseResult r = parse_job(spec);
  ASSERT_FALSE(r.ok());
  ASSERT_EQ(r.errors.size(), 1u);  // reported once, at the formula that crosses it
  EXPECT_EQ(r.errors[0].path, "/bodies/16/initial/velocity/0");
  EXPECT_NE(r.errors[0].message.find("max_formula_characters"), std::string::npos);
  Limits few;
  few.max_formulas = 3;
  const ParseResult r3 = parse_job(spec, few);
  ASSERT_EQ(r3.errors.size(), 1u);
  EXPECT_EQ(r3.errors[0].path, "/bodies/3/initial/velocity/0");
  EXPECT_NE(r3.errors[0].message.find("max_formulas"), std::string::npos);
}

TEST(ParseJob, DefaultsOfTheContract) {
  const ParsedJob job =
      parse_valid(R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [10]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0}},
    "bodies": [{"material": "m", "box": {"min": [0], "max": [1]}}], "time": {"end": 1}})json");
  const Problem& p = job.problem;
  EXPECT_EQ(job.name, "job");
  EXPECT_EQ(p.shape_function, ShapeFunction::linear);
  EXPECT_EQ(p.bodies[0].particles_per_cell, 2);
  EXPECT_EQ(p.gravity, (Vec3{0, 0, 0}));
  EXPECT_TRUE(p.boundaries.empty());
  EXPECT_TRUE(p.tractions.empty());
  EXPECT_DOUBLE_EQ(p.time.courant, 0.5);
  EXPECT_FALSE(p.time.dt.has_value());
  EXPECT_DOUBLE_EQ(p.gravity_constant, 9.81);
  EXPECT_FALSE(p.local_damping);
  EXPECT_TRUE(p.output.series_particles.empty());
  EXPECT_DOUBLE_EQ(p.output.snapshot_interval, 0.0);
  EXPECT_DOUBLE_EQ(p.output.reactions_interval, 0.0);  // no reactions unless asked
  EXPECT_EQ(job.cost.particles, 20);
  EXPECT_EQ(job.cost.snapshots, 0);
  EXPECT_EQ(job.cost.series_rows, 0);
}

// strength_reduction.max_iterations: the trials' own Newton ceiling
// (default 100, not time.implicit.max_iterations), range-checked at its path.
TEST(ParseJob, StrengthReductionIterationCeiling) {
  json spec = testing::example("slope-safety");
  EXPECT_EQ(parse_valid(spec.dump()).problem.strength_reduction->max_iterations, 100);
  spec["strength_reduction"]["max_iterations"] = 40;
  EXPECT_EQ(parse_valid(spec.dump()).problem.strength_reduction->max_iterations, 40);
  spec["strength_reduction"]["max_iterations"] = 0;
  testing::expect_error(spec, "/strength_reduction/max_iterations", "an integer in [1, 1000]");
  spec["strength_reduction"]["max_iterations"] = 2.5;
  testing::expect_error(spec, "/strength_reduction/max_iterations", "integer");
}

// strength_reduction.displacement_limit: unset by default (the solver then
// takes 0.5 % of the soil's height), a positive length when given.
TEST(ParseJob, StrengthReductionSlideLimit) {
  json spec = testing::example("slope-safety");
  EXPECT_FALSE(parse_valid(spec.dump()).problem.strength_reduction->displacement_limit);
  spec["strength_reduction"]["displacement_limit"] = 0.1;
  EXPECT_EQ(parse_valid(spec.dump()).problem.strength_reduction->displacement_limit, 0.1);
  spec["strength_reduction"]["displacement_limit"] = 0;
  testing::expect_error(spec, "/strength_reduction/displacement_limit", "");
}

TEST(ParseJob, LocalDampingFormulaOfTime) {
  const ParsedJob job =
      parse_valid(R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [10]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0}},
    "bodies": [{"material": "m", "box": {"min": [0], "max": [1]}}], "local_damping": "t < 0.5 ? 0.2 : 0",
    "time": {"end": 1}})json");
  ASSERT_TRUE(job.problem.local_damping);
  EXPECT_DOUBLE_EQ(job.problem.local_damping(0.25), 0.2);
  EXPECT_DOUBLE_EQ(job.problem.local_damping(0.75), 0.0);
}

TEST(ParseJob, ShapeFunctionsModelsAndAllSelections) {
  const ParsedJob job = parse_valid(R"json({"dimension": 3, "shape_function": "bspline",
    "grid": {"min": [0, 0, 0], "max": [1, 1, 1], "cells": [2, 2, 2]},
    "materials": {"m": {"model": "drucker_prager", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0,
                        "friction_angle": 0, "dilatancy_angle": 0, "cohesion": 5}},
    "bodies": [{"material": "m", "box": {"min": [0, 0, 0], "max": [1, 1, 1]}, "particles_per_cell": 1}],
    "boundaries": [{"nodes": "all", "velocity": [null, null, "sin(t)"]}],
    "tractions": [{"particles": "all", "face": "z-", "traction": [1, 2, 3]}],
    "time": {"end": 1, "dt": 0.01}})json");
  const Problem& p = job.problem;
  EXPECT_EQ(p.shape_function, ShapeFunction::bspline);
  ASSERT_TRUE(std::holds_alternative<DruckerPrager>(p.materials[0].plasticity));
  EXPECT_DOUBLE_EQ(std::get<DruckerPrager>(p.materials[0].plasticity).cohesion, 5);
  EXPECT_TRUE(p.boundaries[0].nodes.all);
  EXPECT_TRUE(p.boundaries[0].has_velocity);
  EXPECT_NEAR((*p.boundaries[0].velocity[2])(0.5), std::sin(0.5), 1e-15);
  EXPECT_EQ(p.tractions[0].axis, 2);
  EXPECT_EQ(p.tractions[0].side, -1);
  EXPECT_EQ(p.tractions[0].particles.max, (Vec3{1, 1, 1}));
  ASSERT_TRUE(p.time.dt.has_value());
  EXPECT_DOUBLE_EQ(*p.time.dt, 0.01);
  EXPECT_EQ(job.cost.steps, 100);
}

TEST(ParseJob, EveryExampleIsValid) {
  for (const char* name : {"bar-vibration", "darcy-flow", "terzaghi"}) {
    SCOPED_TRACE(name);
    const ParseResult r =
        parse_job(read_text(source_path(std::string("examples/") + name + ".json")));
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    ASSERT_TRUE(r.job.has_value());
    EXPECT_EQ(r.job->name, name);
  }
}

// A fluid softer than the skeleton: E_oed Q past the stability limit of the
// u-p equations with Darcy's rho_f a, (rho - rho_f)/rho_f (docs/verification.md).
// darcy-flow.json with Kf = 1.5 MPa: rho = 0.7*2650 + 300 = 2155 kg/m3, limit
// 1.155, E_oed Q = 1e7 * 0.3 / 1.5e6 = 2: 1.73 times the limit. The spec is
// valid and runnable; the warning names the material by JSON pointer. Dropping
// the term (darcy_inertia: false) or a stiff fluid (the example's 300 MPa:
// 0.012 times) removes it.
TEST(ParseJob, CompressibleFluidIsAWarningNotAnError) {
  json spec = json::parse(read_text(source_path("examples/darcy-flow.json")));
  const auto warnings_of = [](const json& s) {
    const ParseResult r = parse_job(s.dump());
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    return r.job ? r.job->warnings : std::vector<SpecError>{};
  };
  EXPECT_TRUE(warnings_of(spec).empty());
  spec["materials"]["soil"]["hydraulic"]["fluid_bulk_modulus"] = 1.5e6;
  const auto w = warnings_of(spec);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].path, "/materials/soil/hydraulic");
  EXPECT_NE(w[0].message.find("is 1.732 times"), std::string::npos) << w[0].message;
  EXPECT_NE(w[0].message.find("What to change"), std::string::npos) << w[0].message;
  spec["materials"]["soil"]["hydraulic"]["darcy_inertia"] = false;
  EXPECT_TRUE(warnings_of(spec).empty());
}

// A material's pointer is built from its name as one token: "a/b" is
// "/materials/a~1b", never confused with a material "a" beside it (whose
// name is a prefix of the other's followed by '/').
TEST(ParseJob, SolverIssuesOfANestedMaterialNameGetItsOwnPointer) {
  json spec = json::parse(read_text(source_path("examples/darcy-flow.json")));
  json soil = spec["materials"]["soil"];
  spec["materials"] = {{"a", soil}, {"a/b", soil}};
  spec["materials"]["a/b"]["hydraulic"]["fluid_bulk_modulus"] = 1.5e6;
  for (json& body : spec["bodies"]) body["material"] = "a/b";
  const ParseResult r = parse_job(spec.dump());
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job.has_value());
  ASSERT_EQ(r.job->warnings.size(), 1u);
  EXPECT_EQ(r.job->warnings[0].path, "/materials/a~1b/hydraulic");
  // The same for an error found by the solver's checks (geostatic: one pore fluid).
  json geo = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  geo["bodies"][0]["initial"].erase("pore_pressure");
  geo["bodies"][0]["initial"].erase("effective_stress");
  geo["initial_state"] = {{"geostatic", {{"water_table", 0.75}}}};
  json sand = geo["materials"]["sand"];
  geo["materials"] = {{"a", sand}, {"a/b", sand}};
  geo["materials"]["a/b"]["hydraulic"]["fluid_density"] = 1100;
  geo["bodies"][0]["material"] = "a";
  geo["bodies"][1]["material"] = "a/b";
  const ParseResult g = parse_job(geo.dump());
  ASSERT_FALSE(g.errors.empty());
  const bool found = std::any_of(g.errors.begin(), g.errors.end(), [](const SpecError& e) {
    return e.path == "/materials/a~1b/hydraulic/fluid_density";
  });
  std::string all;
  for (const auto& e : g.errors) all += "  " + e.path + ": " + e.message + "\n";
  EXPECT_TRUE(found) << all;
}

TEST(ParseJob, BarVibrationMatchesTheContract) {
  const ParsedJob job = parse_valid(read_text(source_path("examples/bar-vibration.json")));
  EXPECT_EQ(job.cost.particles, 13);
  EXPECT_EQ(job.cost.nodes, 14);
  EXPECT_EQ(job.cost.steps, 2530);
  EXPECT_EQ(job.problem.output.series_particles, (std::vector<std::int64_t>{0, 3, 6, 12}));
  const Vec3 x{0.5, 0, 0};
  EXPECT_NEAR(job.problem.bodies[0].initial.velocity[0](x), 0.1 * std::sin(M_PI / 4), 1e-15);
}

TEST(ParseJob, KnownKeysTableCoversTheTopLevel) {
  const auto& table = spec_object_keys();
  ASSERT_FALSE(table.empty());
  EXPECT_EQ(table.front().location, "");
  const auto& top = table.front().keys;
  for (const char* key :
       {"name", "dimension", "grid", "materials", "bodies", "time", "output", "description"})
    EXPECT_NE(std::find(top.begin(), top.end(), key), top.end()) << key;
}

TEST(ParseJob, MediaTypes) {
  EXPECT_EQ(media_type_for("summary.json"), "application/json");
  EXPECT_EQ(media_type_for("series.csv"), "text/csv");
  EXPECT_EQ(media_type_for("snapshots.pvd"), "application/xml");
  EXPECT_EQ(media_type_for("snapshot_0001.vtu"), "application/xml");
  EXPECT_EQ(media_type_for("x.bin"), "application/octet-stream");
}

// The geostatic block: valid-2d's saturated sand (y in [0, 0.5]) under a dry
// layer (to y = 0.75), with the table at the sand's top.
json geostatic_spec(const json& block) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["bodies"][0]["initial"].erase("pore_pressure");
  spec["bodies"][0]["initial"].erase("effective_stress");
  spec["initial_state"] = {{"geostatic", block}};
  return spec;
}

TEST(ParseJob, GeostaticBlockBecomesTypedValues) {
  {
    const ParsedJob job = parse_valid(
        geostatic_spec(json::parse(R"({"water_table": 0.5, "k0": {"sand": 0.45}})")).dump());
    const Problem& p = job.problem;
    ASSERT_TRUE(p.initial_state.geostatic.has_value());
    const Geostatic& g = *p.initial_state.geostatic;
    ASSERT_TRUE(g.water_table.has_value());
    EXPECT_DOUBLE_EQ(*g.water_table, 0.5);
    EXPECT_FALSE(g.k0.has_value());
    ASSERT_EQ(g.material_k0.size(), p.materials.size());
    const auto sand = static_cast<std::size_t>(p.bodies.at(0).material);
    const auto other = static_cast<std::size_t>(p.bodies.at(1).material);
    ASSERT_TRUE(g.material_k0[sand].has_value());
    EXPECT_DOUBLE_EQ(*g.material_k0[sand], 0.45);
    EXPECT_FALSE(g.material_k0[other].has_value());
  }
  {
    const ParsedJob job =
        parse_valid(geostatic_spec(json::parse(R"({"water_table": 0.5, "k0": 0.6})")).dump());
    const Geostatic& g = job.problem.initial_state.geostatic.value();
    ASSERT_TRUE(g.k0.has_value());
    EXPECT_DOUBLE_EQ(*g.k0, 0.6);
    EXPECT_TRUE(g.material_k0.empty());
  }
  // Absent block: no geostatic state.
  EXPECT_FALSE(parse_valid(read_text(source_path("tests/api/data/valid-2d.json")))
                   .problem.initial_state.geostatic.has_value());
}

TEST(ParseJob, GeostaticPhysicalChecksReportTheirPointers) {
  auto errors_of = [](const json& spec) {
    const ParseResult r = parse_job(spec.dump());
    std::vector<std::string> out;
    for (const auto& e : r.errors) out.push_back(e.path + ": " + e.message);
    return out;
  };
  auto expect_error = [&](const json& spec, const std::string& path, const std::string& part) {
    const auto errors = errors_of(spec);
    const bool found = std::any_of(errors.begin(), errors.end(), [&](const std::string& e) {
      return e.rfind(path + ": ", 0) == 0 && e.find(part) != std::string::npos;
    });
    std::string all;
    for (const auto& e : errors) all += "  " + e + "\n";
    EXPECT_TRUE(found) << "wanted " << path << " (" << part << "), got:\n" << all;
  };
  // Below the top of the saturated sand: sand would lie above the table.
  expect_error(geostatic_spec({{"water_table", 0.4}}), "/initial_state/geostatic/water_table",
               "fully saturated");
  // Above the ground surface (0.75): free water is not modelled.
  expect_error(geostatic_spec({{"water_table", 0.9}}), "/initial_state/geostatic/water_table",
               "above the ground surface");
  // A saturated material needs a table.
  expect_error(geostatic_spec(json::object()), "/initial_state/geostatic", "needs 'water_table'");
  // The ground is layered across gravity.
  json tilted = geostatic_spec({{"water_table", 0.5}});
  tilted["gravity"] = {-1.0, -9.81};
  expect_error(tilted, "/gravity", "exactly one non-zero component");
  // The water table is a number.
  expect_error(geostatic_spec({{"water_table", "high"}}), "/initial_state/geostatic/water_table",
               "got string");
}

TEST(ParseJob, RigidBoundaryAxes) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["boundaries"].push_back(json::parse(
      R"({"nodes": {"box": {"min": [0, 0.75], "max": [1, 0.75]}}, "rigid": [false, true]})"));
  const ParsedJob job = parse_valid(spec.dump());
  const Boundary& b = job.problem.boundaries.back();
  EXPECT_FALSE(b.rigid[0]);
  EXPECT_TRUE(b.rigid[1]);
  EXPECT_FALSE(b.has_velocity);
  EXPECT_FALSE(b.pore_pressure.has_value());
}

TEST(ParseJob, FrictionOfAWall) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["boundaries"].push_back(json::parse(
      R"({"nodes": {"box": {"min": [0, 0], "max": [1, 0]}}, "velocity": [null, 0], "friction": 0.5})"));
  spec["boundaries"].push_back(json::parse(
      R"({"nodes": {"box": {"min": [0, 0], "max": [1, 0]}}, "velocity": [null, 0], "friction": "rough"})"));
  const ParsedJob job = parse_valid(spec.dump());
  const auto& bs = job.problem.boundaries;
  ASSERT_GE(bs.size(), 2u);
  EXPECT_EQ(bs[bs.size() - 2].friction, 0.5);
  EXPECT_TRUE(std::isinf(*bs.back().friction));
}

TEST(ParseJob, FrictionNeedsExactlyOneNormalComponent) {
  const auto errors_of = [](const std::string& boundary) {
    json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
    spec["boundaries"] = json::array({json::parse(boundary)});
    return parse_job(spec.dump()).errors;
  };
  const auto has = [](const std::vector<SpecError>& errors, const std::string& path,
                      const std::string& words) {
    for (const SpecError& e : errors)
      if (e.path == path && e.message.find(words) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has(errors_of(R"({"nodes": "all", "velocity": [0, 0], "friction": 0.3})"),
                  "/boundaries/0/friction", "exactly one prescribed velocity component"));
  EXPECT_TRUE(has(errors_of(R"({"nodes": "all", "pore_pressure": 0, "friction": 0.3})"),
                  "/boundaries/0/friction", "needs 'velocity'"));
  EXPECT_TRUE(has(errors_of(R"({"nodes": "all", "velocity": [null, 0], "friction": -1})"),
                  "/boundaries/0/friction", ">= 0"));
  EXPECT_TRUE(has(errors_of(R"({"nodes": "all", "velocity": [null, 0], "friction": "sticky"})"),
                  "/boundaries/0/friction", "\"rough\""));
}

// stages[i].body_materials: a body's new material by name, read into the
// stage (materials are numbered in name order); mistakes at their paths.
TEST(ParseJob, AStageGivesABodyANewMaterial) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["materials"]["a/b~c-mc"] = spec["materials"]["a/b~c"];
  spec["materials"]["a/b~c-mc"]["model"] = "mohr_coulomb";
  spec["materials"]["a/b~c-mc"]["friction_angle"] = 30;
  spec["materials"]["a/b~c-mc"]["cohesion"] = 1000;
  spec["materials"]["a/b~c-mc"]["dilatancy_angle"] = 0;
  const double end = spec["time"]["end"].get<double>();
  spec["stages"] = json::array(
      {json{{"end", 2 * end},
            {"body_materials", json::array({json{{"body", 1}, {"material", "a/b~c-mc"}}})}}});
  const ParsedJob job = parse_valid(spec.dump());
  ASSERT_EQ(job.problem.stages.size(), 1u);
  ASSERT_EQ(job.problem.stages[0].body_materials.size(), 1u);
  EXPECT_EQ(job.problem.stages[0].body_materials[0].body, 1);
  EXPECT_EQ(
      job.problem
          .materials[static_cast<std::size_t>(job.problem.stages[0].body_materials[0].material)]
          .name,
      "a/b~c-mc");
  auto at = [&](const json& entry, const std::string& path) {
    json s = spec;
    s["stages"][0]["body_materials"] = json::array({entry});
    return testing::issue_at(s, path);
  };
  EXPECT_NE(at(json{{"body", 1}, {"material", "clay"}}, "/stages/0/body_materials/0/material")
                .find("unknown material 'clay'"),
            std::string::npos);
  EXPECT_NE(at(json{{"body", 7}, {"material", "a/b~c-mc"}}, "/stages/0/body_materials/0/body")
                .find("does not exist"),
            std::string::npos);
  EXPECT_NE(at(json{{"body", 1}, {"material", "sand"}}, "/stages/0/body_materials/0/material")
                .find("same density"),
            std::string::npos);
}

// The quasi-static scheme has no Coulomb slip: a friction wall (finite or
// rough) is refused at its path with the reason and the remedies, instead
// of running as a frictionless wall; in a stage that switches to the
// scheme with the wall in force from before, at the stage.
TEST(ParseJob, FrictionWallsAreRefusedByTheQuasiStaticScheme) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  const json wall = json::parse(
      R"({"nodes": {"box": {"min": [0, 0], "max": [1, 0]}}, "velocity": [null, 0], "friction": 0.5})");
  spec["boundaries"].push_back(wall);
  const std::string at =
      "/boundaries/" + std::to_string(spec["boundaries"].size() - 1) + "/friction";
  EXPECT_EQ(testing::issue_at(spec, at), "");  // the explicit scheme has Coulomb slip
  json qs = spec;
  qs["time"]["scheme"] = "quasi_static";
  for (const json& friction : {json(0.5), json("rough")}) {
    qs["boundaries"].back()["friction"] = friction;
    const std::string m = testing::issue_at(qs, at);
    EXPECT_NE(m.find("not supported by the quasi-static scheme"), std::string::npos) << m;
    EXPECT_NE(m.find("frictionless"), std::string::npos) << m;
    EXPECT_NE(m.find("\"velocity\": [0, 0]"), std::string::npos) << m;
    EXPECT_NE(m.find("explicit or semi_implicit"), std::string::npos) << m;
  }
  // A stage switching to the quasi-static scheme with the wall in force.
  json staged = spec;
  const double end = spec["time"]["end"].get<double>();
  staged["stages"] = json::array({json{
      {"name", "static"}, {"end", 2 * end}, {"time", {{"scheme", "quasi_static"}, {"dt", end}}}}});
  const ParseResult r = parse_job(staged.dump());
  bool found = false;
  for (const SpecError& e : r.errors)
    found = found || (e.path == "/stages/0" && e.message.find(at.substr(1)) != std::string::npos &&
                      e.message.find("quasi-static") != std::string::npos);
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace hmpm::api

namespace hmpm::api {
namespace {

// fluxes: a number or a formula in x, y, z, t (rate_varies_in_space says
// which); boundaries[*].seepage; each mistake with its JSON pointer.
TEST(ParseJob, FluxesAndSeepageFaces) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["fluxes"] = json::parse(R"J([
    {"particles": {"box": {"min": [0, 0.375], "max": [1, 0.5]}}, "face": "y+", "rate": 1e-5},
    {"particles": {"polygon": [[0, 0.3], [1, 0.3], [1, 0.5], [0, 0.5]]}, "face": "x-",
     "rate": "2e-6 * (1 + y) * min(t, 1)"}])J");
  spec["boundaries"].push_back(
      json::parse(R"({"nodes": {"box": {"min": [1, 0], "max": [1, 0.5]}}, "seepage": true})"));
  const ParsedJob job = parse_valid(spec.dump());
  const auto& f = job.problem.fluxes;
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].axis, 1);
  EXPECT_EQ(f[0].side, +1);
  EXPECT_FALSE(f[0].rate_varies_in_space);
  EXPECT_DOUBLE_EQ(f[0].rate(Vec3{0.3, 0.4, 0}, 7.0), 1e-5);
  EXPECT_EQ(f[1].axis, 0);
  EXPECT_EQ(f[1].side, -1);
  EXPECT_TRUE(f[1].polygon.has_value());
  EXPECT_TRUE(f[1].rate_varies_in_space);
  EXPECT_DOUBLE_EQ(f[1].rate(Vec3{0, 0.5, 0}, 0.5), 2e-6 * 1.5 * 0.5);
  EXPECT_TRUE(job.problem.boundaries.back().seepage);
  // pore_pressure in x, y, z, t: a reservoir; in t alone: no field.
  EXPECT_FALSE(job.problem.boundaries[2].pore_pressure_field);
  spec["boundaries"][2]["pore_pressure"] = "9810 * max(0, 0.5 + t - y)";
  const ParsedJob reservoir = parse_valid(spec.dump());
  const Boundary& rb = reservoir.problem.boundaries[2];
  ASSERT_TRUE(rb.pore_pressure_field);
  EXPECT_DOUBLE_EQ(rb.pore_pressure_field(Vec3{0.3, 0.25, 0}, 0.25), 9810 * 0.5);
  EXPECT_DOUBLE_EQ(rb.pore_pressure_field(Vec3{0.3, 0.9, 0}, 0.25), 0.0);
  // tractions in x, y, z, t: a load growing along x; in t alone: no field.
  ASSERT_FALSE(reservoir.problem.tractions.empty());
  EXPECT_FALSE(reservoir.problem.tractions[0].traction_field[1]);
  spec["tractions"][0]["traction"] = json::array({0, "-1000 * (1 + x) * min(t, 1)"});
  const ParsedJob varying = parse_valid(spec.dump());
  const Traction& vt = varying.problem.tractions[0];
  EXPECT_FALSE(vt.traction_field[0]);
  ASSERT_TRUE(vt.traction_field[1]);
  EXPECT_DOUBLE_EQ(vt.traction_field[1](Vec3{0.5, 0.9, 0}, 0.5), -1000 * 1.5 * 0.5);
  ASSERT_TRUE(vt.traction[1]);
  EXPECT_DOUBLE_EQ(vt.traction[1](2.0), -1000.0) << "the value at the origin";
  spec["tractions"][0]["traction"] = json::array({0, "-1000*min(t, 1)"});

  spec["fluxes"] = json::parse(R"J([
    {"particles": "all", "face": "z+", "rate": 1e-5},
    {"particles": "all", "face": "y+", "rate": "k * t"},
    {"particles": "all", "face": "y+"},
    {"particles": {"box": {"min": [0, 0.9], "max": [1, 1]}}, "face": "y+", "rate": 1e-5}])J");
  spec["boundaries"].back()["seepage"] = "yes";
  const ParseResult bad = parse_job(spec.dump());
  std::map<std::string, std::string> at;
  for (const SpecError& e : bad.errors) at[e.path] = e.message;
  EXPECT_NE(at["/fluxes/0/face"].find("no z axis"), std::string::npos) << at["/fluxes/0/face"];
  EXPECT_NE(at["/fluxes/1/rate"].find("x, y, z, t"), std::string::npos) << at["/fluxes/1/rate"];
  EXPECT_NE(at["/fluxes/2/rate"].find("required"), std::string::npos) << "a flux without a rate";
  EXPECT_NE(at["/boundaries/3/seepage"].find("true or false"), std::string::npos);
  EXPECT_FALSE(bad.job.has_value());

  // A flux on a dry problem, and a seepage face with the semi-implicit scheme.
  json dry = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  dry["materials"]["sand"].erase("hydraulic");
  dry["bodies"][0]["initial"].erase("pore_pressure");
  dry["boundaries"].erase(2);
  dry["fluxes"] = json::parse(R"J([{"particles": "all", "face": "y+", "rate": 1e-5}])J");
  const ParseResult dry_r = parse_job(dry.dump());
  bool named = false;
  for (const SpecError& e : dry_r.errors)
    named |= e.path == "/fluxes/0" && e.message.find("hydraulic") != std::string::npos;
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace hmpm::api

namespace hmpm::api {
namespace {

// output.profiles: the particles nearest to equally spaced points of each
// line (by initial position), the geometry kept for the writers; each
// mistake with its JSON pointer, and a point outside the bodies refused.
TEST(ParseJob, ProfilesPickTheParticlesNearestToTheirPoints) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["output"]["profiles"] = json::parse(R"J({"interval": 0.002, "lines": [
    {"from": [0.0625, 0.0625], "to": [0.0625, 0.6875], "points": 6, "fields": ["pore_pressure"]},
    {"from": [0.1, 0.3], "to": [0.9, 0.3], "points": 2, "fields": ["strain", "plastic_strain"]}]})J");
  const ParsedJob job = parse_valid(spec.dump());
  const OutputRequest& out = job.problem.output;
  EXPECT_EQ(out.profile_interval, 0.002);
  ASSERT_EQ(out.profiles.size(), 2u);
  // Rows of 8 particles (4 cells x 2); the second body starts at 32.
  EXPECT_EQ(out.profiles[0].particles, (std::vector<std::int64_t>{0, 8, 16, 24, 32, 40}));
  EXPECT_EQ(out.profiles[0].fields, std::vector<Field>{Field::pore_pressure});
  EXPECT_EQ(out.profiles[1].particles, (std::vector<std::int64_t>{16, 23}));
  ASSERT_EQ(job.profiles.size(), 2u);
  ASSERT_EQ(job.profiles[0].points.size(), 6u);
  EXPECT_DOUBLE_EQ(job.profiles[0].points[3][1], 0.0625 + 3 * 0.125);
  EXPECT_EQ(job.profiles[1].to[0], 0.9);
  EXPECT_GT(job.cost.output_bytes,
            parse_valid(read_text(source_path("tests/api/data/valid-2d.json"))).cost.output_bytes);

  spec["output"]["profiles"] = json::parse(R"J({"lines": [
    {"from": [0.5, 0.5], "to": [0.5, 1.4], "points": 4, "fields": ["pore_pressure"]},
    {"from": [0.5, 0.5, 0], "to": [0.5, 0.6], "points": 1, "fields": ["pressure"]}]})J");
  const ParseResult bad = parse_job(spec.dump());
  std::map<std::string, std::string> at;
  for (const SpecError& e : bad.errors) at[e.path] += e.message;
  EXPECT_NE(at["/output/profiles/interval"].find("required"), std::string::npos);
  EXPECT_FALSE(at["/output/profiles/lines/1/from"].empty()) << "three components in 2D";
  EXPECT_FALSE(at["/output/profiles/lines/1/points"].empty()) << "one point is no line";
  EXPECT_NE(at["/output/profiles/lines/1/fields/0"].find("pore_pressure"), std::string::npos)
      << at["/output/profiles/lines/1/fields/0"];
  EXPECT_FALSE(bad.job.has_value());

  // A line leaving the bodies (checked with the whole problem, once every
  // section is valid).
  spec["output"]["profiles"] = json::parse(R"J({"interval": 0.002, "lines": [
    {"from": [0.5, 0.5], "to": [0.5, 1.4], "points": 4, "fields": ["pore_pressure"]}]})J");
  spec["grid"]["max"] = json::array({1, 1.5});
  spec["grid"]["cells"] = json::array({4, 6});
  const ParseResult outside = parse_job(spec.dump());
  ASSERT_FALSE(outside.errors.empty());
  EXPECT_EQ(outside.errors[0].path, "/output/profiles/lines/0");
  EXPECT_NE(outside.errors[0].message.find("point 2 at (0.5, 1.1) is more than a cell from every "
                                           "particle"),
            std::string::npos)
      << outside.errors[0].message;
}

// Stages (docs/job-spec.md, stages[i]): each entry's lists are read by the
// top level's readers into the stage, leaving the top level's as they were;
// `time` replaces the whole time control (defaults for what it omits);
// mistakes are reported at the stage's own paths.
TEST(ParseJob, StagesAreReadIntoTheirStageAndCheckedAtTheirPaths) {
  json spec = json::parse(read_text(source_path("examples/staged-excavation.json")));
  const ParsedJob job = parse_valid(spec.dump());
  const Problem& p = job.problem;
  ASSERT_EQ(p.stages.size(), 1u);
  const Stage& s = p.stages[0];
  EXPECT_EQ(s.name, "excavation");
  EXPECT_DOUBLE_EQ(s.end, 1728001.0);
  EXPECT_EQ(s.remove_bodies, std::vector<int>{0});
  EXPECT_TRUE(s.add_bodies.empty());
  EXPECT_EQ(p.boundaries.size(), 4u);  // the top level's list is untouched
  ASSERT_TRUE(s.boundaries.has_value());
  EXPECT_EQ(s.boundaries->size(), 6u);
  EXPECT_FALSE(s.tractions.has_value());  // not given: the list in force stays
  ASSERT_TRUE(s.time.has_value());
  EXPECT_EQ(s.time->scheme, Scheme::quasi_static);
  ASSERT_TRUE(s.time->growth.has_value());
  EXPECT_DOUBLE_EQ(s.time->growth->initial, 100.0);
  EXPECT_DOUBLE_EQ(s.time->courant, 0.5);  // a default, not the stage before's
  EXPECT_FALSE(s.reset_displacement);
  // The estimate counts the steps of both stages (1 + the growing plan).
  EXPECT_GT(job.cost.steps, 30);

  spec["stages"][0]["remove_bodies"] = json::array({0, 9});
  spec["stages"][0]["time"]["end"] = 5;
  spec["stages"][0]["boundaries"][3]["nodes"]["bx"] = 1;
  spec["stages"][0]["reset_displacement"] = "yes";
  spec["stages"].push_back(json{{"end", 10.0}, {"gravity", json::array({0.0})}});
  spec["stages"].push_back(json{{"ends", 10.0}});
  const ParseResult r = parse_job(spec.dump());
  std::vector<std::string> paths;
  for (const auto& e : r.errors) paths.push_back(e.path);
  for (const char* want :
       {"/stages/0/time/end", "/stages/0/boundaries/3/nodes/bx", "/stages/0/reset_displacement",
        "/stages/1/gravity", "/stages/2/ends", "/stages/2/end"}) {
    EXPECT_NE(std::find(paths.begin(), paths.end(), want), paths.end()) << want;
  }
  // The solver's checks once the reading is clean: a body that does not
  // exist, an end before the stage before's.
  json order = json::parse(read_text(source_path("examples/staged-excavation.json")));
  order["stages"][0]["remove_bodies"] = json::array({0, 9});
  order["stages"].push_back(json{{"end", 10.0}});
  const ParseResult r2 = parse_job(order.dump());
  paths.clear();
  for (const auto& e : r2.errors) paths.push_back(e.path);
  for (const char* want : {"/stages/0/remove_bodies/1", "/stages/1/end"})
    EXPECT_NE(std::find(paths.begin(), paths.end(), want), paths.end()) << want;
}

}  // namespace
}  // namespace hmpm::api
