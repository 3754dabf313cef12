// test_malformed_specs.cpp — the acceptance table: each malformed spec is
// rejected with the exact JSON pointer of the problem (and, where it matters,
// a message that says what was expected), by parse_job and by
// `hmpm validate` (exit 2, a "/pointer: message" line on stderr). None crashes.
//
// Most cases are one mutation of tests/api/data/valid-2d.json: set the value
// at a pointer (or remove it when `value` is null).
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "test_support.hpp"

namespace hmpm::api {
namespace {

using nlohmann::json;
using testing::read_text;
using testing::source_path;

struct Mutation {
  const char* name;
  const char* pointer;            ///< where to change the valid spec
  const char* value;              ///< new JSON value; nullptr removes the key
  const char* expected_path;      ///< an error must have exactly this pointer
  const char* message_part = "";  ///< ... and its message must contain this
};

const Mutation mutations[] = {
    {"missing_time", "/time", nullptr, "/time", "is required"},
    {"unknown_top_key", "/dimensoin", "2", "/dimensoin", "did you mean 'dimension'?"},
    {"dimension_4", "/dimension", "4", "/dimension", "[1, 3]"},
    {"dimension_string", "/dimension", "\"2\"", "/dimension", "got string"},
    // Names that print as something else, or break a log line or a terminal.
    {"name_nul", "/name", "\"a\\u0000b\"", "/name", "holds U+0000 at character 2"},
    {"name_newline", "/name", "\"run\\nfake log line\"", "/name", "holds U+000A at character 4"},
    {"name_escape", "/name", "\"\\u001b[31mred\"", "/name", "holds U+001B at character 1"},
    {"name_c1", "/name", "\"a\\u009bb\"", "/name", "holds U+009B"},
    {"name_bidi_override", "/name", "\"invoice\\u202Efdp.exe\"", "/name",
     "holds U+202E at character 8; a job name may not contain"},
    {"name_bidi_isolate", "/name", "\"x\\u2067y\"", "/name", "holds U+2067"},
    {"grid_cells_zero", "/grid/cells/0", "0", "/grid/cells/0", "integer in [1,"},
    {"grid_cells_fraction", "/grid/cells/1", "2.5", "/grid/cells/1", "integer"},
    {"grid_max_below_min", "/grid/max/0", "0", "/grid/max/0", "greater than grid min"},
    {"grid_min_length", "/grid/min", "[0, 0, 0]", "/grid/min", "expected 2"},
    {"youngs_negative", "/materials/sand/youngs_modulus", "-1", "/materials/sand/youngs_modulus",
     "must be > 0"},
    {"youngs_typo", "/materials/sand/youngs_modulu", "1e7", "/materials/sand/youngs_modulu",
     "did you mean 'youngs_modulus'?"},
    {"poisson_half", "/materials/sand/poisson_ratio", "0.5", "/materials/sand/poisson_ratio",
     "(-1, 0.5)"},
    {"porosity_above_one", "/materials/sand/hydraulic/porosity", "1.2",
     "/materials/sand/hydraulic/porosity", "(0, 1)"},
    {"porosity_zero", "/materials/sand/hydraulic/porosity", "0",
     "/materials/sand/hydraulic/porosity", "(0, 1)"},
    {"unknown_model", "/materials/sand/model", "\"elastic\"", "/materials/sand/model",
     "'linear_elastic'"},
    {"missing_friction_angle", "/materials/sand/friction_angle", nullptr,
     "/materials/sand/friction_angle", "required for model 'mohr_coulomb'"},
    {"plastic_key_on_elastic", "/materials/a~1b~0c/cohesion", "5", "/materials/a~1b~0c/cohesion",
     "only to models"},
    {"escaped_material_name_type", "/materials/a~1b~0c/youngs_modulus", "\"big\"",
     "/materials/a~1b~0c/youngs_modulus", "got string"},
    {"dilatancy_above_friction", "/materials/sand/dilatancy_angle", "40",
     "/materials/sand/dilatancy_angle", "friction_angle"},
    {"density_boolean", "/materials/sand/density", "true", "/materials/sand/density",
     "got boolean"},
    {"missing_hydraulic_key", "/materials/sand/hydraulic/fluid_bulk_modulus", nullptr,
     "/materials/sand/hydraulic/fluid_bulk_modulus", "is required"},
    {"darcy_inertia_not_boolean", "/materials/sand/hydraulic/darcy_inertia", "\"no\"",
     "/materials/sand/hydraulic/darcy_inertia", "true or false"},
    {"materials_empty", "/materials", "{}", "/materials", "at least one material"},
    {"unknown_material", "/bodies/0/material", "\"clay\"", "/bodies/0/material",
     "unknown material 'clay'"},
    {"body_box_outside_grid", "/bodies/0/box/max/0", "2", "/bodies/0/box/max/0",
     "outside the grid"},
    {"body_box_length", "/bodies/0/box/min", "[0]", "/bodies/0/box/min", "expected 2"},
    {"bodies_empty", "/bodies", "[]", "/bodies", "at least one body"},
    {"body_box_without_whole_cell", "/bodies/1/box", R"({"min": [0, 0.5], "max": [0.1, 0.6]})",
     "/bodies/1/box", "no whole grid cell"},
    // Shaped bodies (issue 17): body 1 of the valid spec as a polygon or points.
    {"polygon_two_vertices", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5], [1, 0.5]]})", "/bodies/1/polygon",
     "at least 3"},
    {"polygon_self_intersecting", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5], [1, 0.9], [1, 0.5], [0, 0.7]]})",
     "/bodies/1/polygon", "edge 0 (vertex 0 to 1) and edge 2 (vertex 2 to 3) cross"},
    {"polygon_zero_area", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5], [0.5, 0.6], [1, 0.7]]})", "/bodies/1/polygon",
     "zero area"},
    {"polygon_repeated_vertex", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5], [1, 0.5], [1, 0.75], [0, 0.5]]})",
     "/bodies/1/polygon/3", "repeats vertex 0"},
    {"polygon_vertex_3d", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5, 0], [1, 0.5], [1, 0.75]]})",
     "/bodies/1/polygon/0", "two numbers"},
    {"polygon_vertex_outside_grid", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0, 0.5], [2, 0.5], [1, 0.75]]})",
     "/bodies/1/polygon/1/0", "outside the grid"},
    {"polygon_no_subcell_centre", "/bodies/1",
     R"({"material": "a/b~c", "polygon": [[0.01, 0.9], [0.02, 0.9], [0.02, 0.91]]})",
     "/bodies/1/polygon", "no sub-cell centre"},
    {"body_box_and_polygon", "/bodies/1/polygon", "[[0, 0.5], [1, 0.5], [1, 0.75]]", "/bodies/1",
     "give exactly one shape"},
    {"body_without_shape", "/bodies/1/box", nullptr, "/bodies/1", "needs a shape"},
    {"prism_in_2d", "/bodies/1",
     R"({"material": "a/b~c", "prism": {"polygon": [[0, 0], [1, 0], [1, 1]], "axis": "z", "from": 0, "to": 1}})",
     "/bodies/1/prism", "3D shape"},
    {"body_inside_earlier_body", "/bodies/1/box", R"({"min": [0, 0], "max": [1, 0.5]})",
     "/bodies/1", "lies inside an earlier body"},
    {"points_volume_count", "/bodies/1",
     R"({"material": "a/b~c", "points": {"positions": [[0.5, 0.9]], "volumes": [0.01, 0.02]}})",
     "/bodies/1/points/volumes", "one volume per position"},
    {"points_volume_zero", "/bodies/1",
     R"({"material": "a/b~c", "points": {"positions": [[0.5, 0.9]], "volumes": [0]}})",
     "/bodies/1/points/volumes/0", "> 0"},
    {"points_outside_grid", "/bodies/1",
     R"({"material": "a/b~c", "points": {"positions": [[0.5, 1.5]], "volumes": [0.01]}})",
     "/bodies/1/points/positions/0", "outside the grid"},
    {"points_position_length", "/bodies/1",
     R"({"material": "a/b~c", "points": {"positions": [[0.5]], "volumes": [0.01]}})",
     "/bodies/1/points/positions/0", "expected 2"},
    {"points_missing_volumes", "/bodies/1",
     R"({"material": "a/b~c", "points": {"positions": [[0.5, 0.9]]}})", "/bodies/1/points/volumes",
     "is required"},
    {"node_polygon_self_intersecting", "/boundaries/0/nodes",
     R"({"polygon": [[0, 0], [1, 1], [1, 0], [0, 0.5]]})", "/boundaries/0/nodes/polygon",
     "not a simple polygon"},
    {"node_polygon_selects_nothing", "/boundaries/0/nodes",
     R"({"polygon": [[0.1, 0.1], [0.2, 0.1], [0.2, 0.2]]})", "/boundaries/0/nodes/polygon",
     "selects no grid node"},
    {"node_selection_box_and_polygon", "/boundaries/0/nodes/polygon", "[[0, 0], [1, 0], [1, 1]]",
     "/boundaries/0/nodes", "give one"},
    {"traction_polygon_selects_nothing", "/tractions/0/particles",
     R"({"polygon": [[0.01, 0.01], [0.02, 0.01], [0.02, 0.02]]})", "/tractions/0/particles",
     "selects no particle"},
    {"particles_per_cell_zero", "/bodies/0/particles_per_cell", "0", "/bodies/0/particles_per_cell",
     "[1, 10]"},
    {"bad_expression", "/bodies/0/initial/velocity/1", "\"0.1*sin(\"",
     "/bodies/0/initial/velocity/1", "bad formula"},
    {"time_in_initial_field", "/bodies/0/initial/pore_pressure", "\"2*t\"",
     "/bodies/0/initial/pore_pressure", "x, y, z"},
    {"assignment_in_expression", "/bodies/0/initial/velocity/0", "\"x=1\"",
     "/bodies/0/initial/velocity/0", "assignment"},
    {"formula_not_finite_at_a_particle", "/bodies/0/initial/pore_pressure", "\"log(x - 0.5)\"",
     "/bodies/0/initial/pore_pressure",
     "the formula gives nan at a particle of body 0 (x = 0.0625, y = 0.0625)"},
    {"time_formula_not_finite", "/tractions/0/traction/1", "\"1/(t - 0.005)\"",
     "/tractions/0/traction/1", "the formula gives inf at t = 0.005 s"},
    {"initial_velocity_length", "/bodies/0/initial/velocity", "[0]", "/bodies/0/initial/velocity",
     "expected 2"},
    {"effective_stress_length", "/bodies/0/initial/effective_stress", "[0, 0, 0]",
     "/bodies/0/initial/effective_stress", "6"},
    {"pore_pressure_on_dry_material", "/bodies/1/initial", R"({"pore_pressure": 5})",
     "/bodies/1/initial/pore_pressure", "no 'hydraulic'"},
    // A velocity is a value of t (a pore pressure may use x, y, z too).
    {"boundary_time_expression_uses_x", "/boundaries/0/velocity/1", "\"x+1\"",
     "/boundaries/0/velocity/1", "bad formula"},
    {"boundary_velocity_length", "/boundaries/0/velocity", "[0, 0, 0]", "/boundaries/0/velocity",
     "expected 2"},
    {"boundary_nodes_word", "/boundaries/0/nodes", "\"everything\"", "/boundaries/0/nodes",
     "\"all\""},
    {"boundary_without_condition", "/boundaries/0/velocity", nullptr, "/boundaries/0", "velocity"},
    {"boundary_box_without_nodes", "/boundaries/0/nodes/box",
     R"({"min": [0.1, 0.1], "max": [0.2, 0.2]})", "/boundaries/0/nodes/box", "no grid node"},
    {"traction_face_unknown", "/tractions/0/face", "\"w+\"", "/tractions/0/face", "'x-'"},
    {"traction_face_z_in_2d", "/tractions/0/face", "\"z+\"", "/tractions/0/face", "no z axis"},
    {"traction_selects_nothing", "/tractions/0/particles/box",
     R"({"min": [0, 0.74], "max": [1, 0.75]})", "/tractions/0/particles", "no particle"},
    {"time_end_negative", "/time/end", "-1", "/time/end", "must be > 0"},
    {"time_dt_unstable", "/time/dt", "1", "/time/dt", "stable limit"},
    {"courant_above_one", "/time/courant", "1.5", "/time/courant", "(0, 1]"},
    {"series_particle_out_of_range", "/output/series/particles/0", "1000",
     "/output/series/particles/0", "48 particles"},
    {"series_particle_negative", "/output/series/particles/0", "-1", "/output/series/particles/0",
     "integer"},
    {"series_field_unknown", "/output/series/fields/1", "\"stress\"", "/output/series/fields/1",
     "'effective_stress'"},
    {"series_field_twice", "/output/series/fields/1", "\"displacement\"", "/output/series/fields/1",
     "twice"},
    {"near_wrong_length", "/output/series/particles/1/near", "[0.5]",
     "/output/series/particles/1/near", "expected 2"},
    {"output_key_typo", "/output/snapshot", "{}", "/output/snapshot", "did you mean 'snapshots'?"},
    {"reactions_interval_zero", "/output/reactions/interval", "0", "/output/reactions/interval",
     "must be > 0"},
    {"reactions_without_interval", "/output/reactions/interval", nullptr,
     "/output/reactions/interval", "is required"},
    {"reactions_key_typo", "/output/reactions/intervals", "1", "/output/reactions/intervals",
     "did you mean 'interval'?"},
    {"reactions_not_object", "/output/reactions", "0.1", "/output/reactions", "object"},
    {"name_not_string", "/name", "3", "/name", "expected a string"},
    {"gravity_length", "/gravity", "[-9.81]", "/gravity", "expected 2"},
    {"shape_function_unknown", "/shape_function", "\"quadratic\"", "/shape_function", "'bspline'"},
    {"local_damping_one", "/local_damping", "1", "/local_damping", "[0, 1)"},
    {"local_damping_formula_bad", "/local_damping", "\"0.1*(t<\"", "/local_damping", ""},
    {"local_damping_formula_out_of_range", "/local_damping", "\"0.2 + 1e6 * t\"", "/local_damping",
     "local damping must lie in [0, 1)"},
    {"local_damping_not_number", "/local_damping", "true", "/local_damping",
     "expected a number, a formula string in t or {\"table\""},
    {"geostatic_conflicts_with_initial_fields", "/initial_state",
     R"({"geostatic": {"water_table": 0.5}})", "/bodies/0/initial/pore_pressure",
     "conflicts with initial_state.geostatic"},
    {"geostatic_key_typo", "/initial_state", R"({"geostatic": {"water_tabel": 0.5}})",
     "/initial_state/geostatic/water_tabel", "did you mean 'water_table'?"},
    {"geostatic_k0_negative", "/initial_state", R"({"geostatic": {"k0": -0.5}})",
     "/initial_state/geostatic/k0", "must be"},
    {"geostatic_k0_unknown_material", "/initial_state", R"({"geostatic": {"k0": {"clay": 0.5}}})",
     "/initial_state/geostatic/k0/clay", "names no material"},
    {"rigid_not_boolean", "/boundaries/1/rigid", "[false, 1]", "/boundaries/1/rigid/1",
     "true or false"},
    {"rigid_on_prescribed_axis", "/boundaries/1/rigid", "[true, false]", "/boundaries/1/rigid/0",
     "prescribes that component"},
    {"limit_steps", "/time/end", "1e6", "/time/end", "the limit is 20000000"},
    {"limit_cells", "/grid/cells", "[3000, 3000]", "/grid/cells",
     "9000000 cells; the limit is 4000000"},
    {"limit_particles", "/bodies/0/particles_per_cell", "10", "/bodies", "the limit is 2000000"},
    {"limit_snapshots", "/output/snapshots/interval", "1e-6", "/output/snapshots/interval",
     "10001 snapshots; the limit is 1000"},
    {"limit_series_rows", "/output/series/interval", "1e-9", "/output/series/interval",
     "the limit is 1000000"},
    {"limit_reaction_rows", "/output/reactions/interval", "1e-9", "/output/reactions/interval",
     "the limit (that of the series) is 1000000"},
};

// limit_particles needs a grid fine enough: 1000 x 1000 cells, 10 x 10 each.
json mutated(const Mutation& m) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  const json::json_pointer ptr(m.pointer);
  if (m.value == nullptr) {
    spec.at(ptr.parent_pointer()).erase(ptr.back());
  } else {
    spec[ptr] = json::parse(m.value);
  }
  if (std::string(m.name) == "limit_particles") spec["grid"]["cells"] = {1000, 1000};
  if (std::string(m.name) == "limit_series_rows" || std::string(m.name) == "limit_reaction_rows")
    spec["time"]["end"] = 20.0;
  return spec;
}

struct RawCase {
  const char* name;
  std::string text;
  const char* expected_path;
  const char* message_part;
};

std::vector<RawCase> raw_cases() {
  const std::string valid = read_text(source_path("tests/api/data/valid-2d.json"));
  std::string overflow = valid;
  overflow.replace(overflow.find("\"end\": 0.01"), 11, "\"end\": 1e999");
  return {
      {"not_json", "this is not JSON", "", "not valid JSON"},
      {"empty_text", "", "", "not valid JSON"},
      {"truncated", valid.substr(0, valid.size() / 2), "", "not valid JSON"},
      {"root_is_array", "[1, 2]", "", "expected an object"},
      {"deep_nesting", std::string(100000, '['), "", "nested deeper than 64"},
      {"deep_objects",
       [] {
         std::string s;
         for (int i = 0; i < 100000; ++i) s += "{\"a\":";
         return s;
       }(),
       "", "nested deeper"},
      {"non_finite_number", overflow, "/time/end", "finite"},
      {"trailing_garbage", valid + "}", "", "not valid JSON"},
      {"duplicate_key", "{\"time\": {\"end\": 1, \"end\": 2}}", "/time/end", "duplicate key 'end'"},
  };
}

bool has_error(const ParseResult& r, const std::string& path, const std::string& part) {
  for (const auto& e : r.errors)
    if (e.path == path && e.message.find(part) != std::string::npos) return true;
  return false;
}

std::string listing(const ParseResult& r) {
  std::string s;
  for (const auto& e : r.errors) s += "  " + e.path + ": " + e.message + "\n";
  return s;
}

// Each case must be the cause of the error it expects: the spec it mutates
// is valid, its mutation changes that spec, and its name is its own.
TEST(MalformedSpecs, EachCaseMutatesTheValidSpec) {
  const std::string valid_text = read_text(source_path("tests/api/data/valid-2d.json"));
  const ParseResult base = parse_job(valid_text);
  EXPECT_TRUE(base.ok()) << listing(base);
  const json valid = json::parse(valid_text);
  std::set<std::string> names;
  for (const Mutation& m : mutations) {
    EXPECT_TRUE(names.insert(m.name).second) << "two cases are named " << m.name;
    EXPECT_NE(mutated(m), valid) << m.name << " does not change the valid spec";
  }
  for (const RawCase& c : raw_cases()) {
    EXPECT_TRUE(names.insert(c.name).second) << "two cases are named " << c.name;
    EXPECT_NE(c.text, valid_text) << c.name << " is the valid spec";
  }
}

TEST(MalformedSpecs, ParseJobReportsTheExactPointer) {
  for (const Mutation& m : mutations) {
    SCOPED_TRACE(m.name);
    const ParseResult r = parse_job(mutated(m).dump());
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.job.has_value());
    EXPECT_TRUE(has_error(r, m.expected_path, m.message_part))
        << "want " << m.expected_path << " with '" << m.message_part << "', got\n"
        << listing(r);
  }
  for (const RawCase& c : raw_cases()) {
    SCOPED_TRACE(c.name);
    const ParseResult r = parse_job(c.text);
    EXPECT_TRUE(has_error(r, c.expected_path, c.message_part))
        << "want '" << c.expected_path << "' with '" << c.message_part << "', got\n"
        << listing(r);
  }
}

TEST(MalformedSpecs, EveryErrorIsCollectedNotJustTheFirst) {
  json spec = json::parse(read_text(source_path("tests/api/data/valid-2d.json")));
  spec["materials"]["sand"]["youngs_modulus"] = -1;
  spec["materials"]["sand"]["hydraulic"]["porosity"] = 2;
  spec["bodies"][0]["particles_per_cell"] = 0;
  spec["time"]["end"] = "soon";
  spec["output"]["series"]["fields"][0] = "speed";
  const ParseResult r = parse_job(spec.dump());
  EXPECT_EQ(r.errors.size(), 5u) << listing(r);
}

TEST(MalformedSpecs, ErrorListIsCappedAtAThousand) {
  std::string spec = "{";
  for (int i = 0; i < 5000; ++i) spec += "\"k" + std::to_string(i) + "\": 0, ";
  spec += "\"dimension\": 1}";
  const ParseResult r = parse_job(spec);
  ASSERT_EQ(r.errors.size(), 1001u);
  EXPECT_EQ(r.errors.back().path, "");
  EXPECT_NE(r.errors.back().message.find("more errors not shown"), std::string::npos);
}

TEST(MalformedSpecs, ValidationWorkIsBounded) {
  // 13 bodies on a 1D grid of 4 million cells: laying them out is refused
  // before any per-cell loop runs.
  json spec =
      json::parse(R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [4000000]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0}},
    "bodies": [], "time": {"end": 1}})json");
  for (int i = 0; i < 13; ++i)
    spec["bodies"].push_back({{"material", "m"}, {"box", {{"min", {0.0}}, {"max", {1e-6}}}}});
  const ParseResult r = parse_job(spec.dump());
  EXPECT_TRUE(has_error(r, "/bodies", "too much work to lay out (52000000 > 50000000)"))
      << listing(r);
}

TEST(MalformedSpecs, LimitsAreConfigurable) {
  Limits tight;
  tight.max_particles = 10;
  tight.max_json_depth = 3;
  const std::string valid = read_text(source_path("tests/api/data/valid-2d.json"));
  ParseResult r = parse_job(valid, tight);
  EXPECT_TRUE(has_error(r, "", "nested deeper than 3")) << listing(r);
  tight.max_json_depth = 64;
  r = parse_job(valid, tight);
  EXPECT_TRUE(has_error(r, "/bodies", "48 particles; the limit is 10")) << listing(r);
  tight.max_body_bytes = 100;
  r = parse_job(valid, tight);
  EXPECT_TRUE(has_error(r, "", "the limit is 100 bytes")) << listing(r);
}

// The command line: exit 2 and one "/pointer: message" line per error.
TEST(MalformedSpecs, CommandLineExitsTwoWithPointerLines) {
  testing::TempDir dir;
  auto check = [&](const std::string& name, const std::string& text, const std::string& path) {
    SCOPED_TRACE(name);
    const auto spec = dir.path() / (name + ".json");
    testing::write_text(spec, text);
    const auto r =
        testing::run_command(testing::hmpm_exe() + " validate '" + spec.string() + "'", dir.path());
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(("\n" + r.err).find("\n" + path + ": "), std::string::npos) << r.err;
  };
  for (const Mutation& m : mutations) check(m.name, mutated(m).dump(), m.expected_path);
  for (const RawCase& c : raw_cases()) check(c.name, c.text, c.expected_path);
}

}  // namespace
}  // namespace hmpm::api
