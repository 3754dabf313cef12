// test_shapes.cpp — shaped bodies in the job spec (issue 17): 3D prisms and
// their errors, points bodies, polygon selections, and the overlap warning
// that reaches ParsedJob::warnings (validate, the 201 and summary.json).
// The 2D errors are in test_malformed_specs.cpp's table.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"

namespace hmpm::api {
namespace {

using nlohmann::json;

json spec_3d() {
  return json::parse(R"json({
    "dimension": 3, "grid": {"min": [0, 0, 0], "max": [4, 4, 4], "cells": [8, 8, 8]},
    "materials": {"fill": {"model": "linear_elastic", "density": 1800, "youngs_modulus": 1e7,
                           "poisson_ratio": 0.3}},
    "bodies": [{"material": "fill", "particles_per_cell": 2,
                "prism": {"polygon": [[0.5, 0], [3.5, 0], [2.5, 1.5], [1.5, 1.5]],
                          "axis": "z", "from": 0.5, "to": 2.5}}],
    "time": {"end": 0.001}})json");
}

json spec_2d() {
  return json::parse(R"json({
    "dimension": 2, "grid": {"min": [0, 0], "max": [10, 4], "cells": [20, 8]},
    "materials": {"fill": {"model": "linear_elastic", "density": 1800, "youngs_modulus": 1e7,
                           "poisson_ratio": 0.3}},
    "bodies": [{"material": "fill", "box": {"min": [0, 0], "max": [10, 1]}},
               {"material": "fill", "polygon": [[1, 0], [9, 0], [7, 3], [3, 3]]}],
    "boundaries": [{"nodes": {"polygon": [[0, 0], [10, 0], [10, 0.5], [0, 0.5]]},
                    "velocity": [0, 0]}],
    "tractions": [{"particles": {"polygon": [[3, 2.5], [7, 2.5], [7, 3], [3, 3]]},
                   "face": "y+", "traction": [0, -1000]}],
    "time": {"end": 0.001}})json");
}

std::string listing(const ParseResult& r) {
  std::string s;
  for (const auto& e : r.errors) s += "  " + e.path + ": " + e.message + "\n";
  return s;
}

bool has_error(const ParseResult& r, const std::string& path, const std::string& part) {
  for (const auto& e : r.errors)
    if (e.path == path && e.message.find(part) != std::string::npos) return true;
  return false;
}

TEST(ShapesSpec, PrismParsesToTheSolverShape) {
  const ParseResult r = parse_job(spec_3d().dump());
  ASSERT_TRUE(r.ok()) << listing(r);
  const Problem& p = r.job->problem;
  ASSERT_TRUE(p.bodies[0].prism.has_value());
  EXPECT_EQ(p.bodies[0].prism->axis, 2);
  EXPECT_EQ(p.bodies[0].prism->polygon.vertices.size(), 4u);
  EXPECT_GT(count_particles(p), 0);
}

TEST(ShapesSpec, PrismErrorsNameTheirPointer) {
  struct Case {
    const char* pointer;
    const char* value;
    const char* path;
    const char* part;
  };
  const Case cases[] = {
      {"/bodies/0/prism/to", "0.5", "/bodies/0/prism/to", "greater than from"},
      {"/bodies/0/prism/axis", "\"w\"", "/bodies/0/prism/axis", "'x'"},
      {"/bodies/0/prism/from", "-1", "/bodies/0/prism/from", "outside the grid"},
      {"/bodies/0/prism/polygon/1", "[3.5, 5]", "/bodies/0/prism/polygon/1/1", "along y"},
      {"/bodies/0/prism/polygon", "[[0, 0], [1, 1]]", "/bodies/0/prism/polygon", "at least 3"},
      {"/bodies/0/prism/polygon", "[[0, 0], [3, 2], [3, 0], [0, 1]]", "/bodies/0/prism/polygon",
       "not a simple polygon"},
      {"/bodies/0/polygon", "[[0, 0], [1, 0], [1, 1]]", "/bodies/0", "give exactly one shape"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.pointer);
    json spec = spec_3d();
    spec[json::json_pointer(c.pointer)] = json::parse(c.value);
    const ParseResult r = parse_job(spec.dump());
    EXPECT_TRUE(has_error(r, c.path, c.part)) << listing(r);
  }
  // A polygon body and a polygon selection in 3D.
  json spec = spec_3d();
  spec["bodies"][0].erase("prism");
  spec["bodies"][0]["polygon"] = json::parse("[[0, 0], [1, 0], [1, 1]]");
  spec["boundaries"] = json::parse(R"([{"nodes": {"polygon": [[0, 0], [1, 0], [1, 1]]},
                                        "velocity": [0, 0, 0]}])");
  const ParseResult r = parse_job(spec.dump());
  EXPECT_TRUE(has_error(r, "/bodies/0/polygon", "'prism'")) << listing(r);
  EXPECT_TRUE(has_error(r, "/boundaries/0/nodes/polygon", "needs a 2D problem")) << listing(r);
}

TEST(ShapesSpec, OverlapIsAWarningWithBothBodiesAndTheCount) {
  const ParseResult r = parse_job(spec_2d().dump());
  ASSERT_TRUE(r.ok()) << listing(r);
  bool found = false;
  for (const SpecError& w : r.job->warnings)
    if (w.path == "/bodies/1" && w.message.find("overlaps body 0: ") != std::string::npos &&
        w.message.find("of its particle positions lie inside body 0") != std::string::npos)
      found = true;
  EXPECT_TRUE(found);
  // Polygon selections reach the Problem.
  const Problem& p = r.job->problem;
  ASSERT_TRUE(p.boundaries[0].nodes.polygon.has_value());
  ASSERT_TRUE(p.tractions[0].polygon.has_value());
  // The traction's polygon holds the embankment's top row (y = 2.875).
  std::size_t loaded = 0;
  for (const Vec3& x : initial_positions(p)) loaded += particle_selected(p, p.tractions[0], x);
  EXPECT_GT(loaded, 0u);
}

TEST(ShapesSpec, PointsBodyKeepsItsPositionsAndVolumes) {
  json spec = spec_2d();
  spec["bodies"] = json::parse(R"([{"material": "fill",
      "points": {"positions": [[1.1, 0.3], [2.05, 0.7]], "volumes": [0.02, 0.03]}}])");
  spec.erase("tractions");
  const ParseResult r = parse_job(spec.dump());
  ASSERT_TRUE(r.ok()) << listing(r);
  const auto x = initial_positions(r.job->problem);
  ASSERT_EQ(x.size(), 2u);
  EXPECT_DOUBLE_EQ(x[1][0], 2.05);
  EXPECT_DOUBLE_EQ(x[1][1], 0.7);
  EXPECT_EQ(r.job->problem.bodies[0].points->volumes, (std::vector<double>{0.02, 0.03}));
}

TEST(ShapesSpec, SeriesPolygonStandsForTheParticlesInsideIt) {
  json spec = spec_2d();
  // The embankment's top row: y = 2.875, where the 2:3 slopes are at
  // x = 2.917 and 7.083, so the sub-cell centres x = 3.125 ... 6.875 (16),
  // between indices 0 and 1.
  spec["output"] = json::parse(R"({"series": {"particles": [0,
      {"polygon": [[2, 2.75], [8, 2.75], [8, 3], [2, 3]]}, 1], "fields": ["displacement"]}})");
  const ParseResult r = parse_job(spec.dump());
  ASSERT_TRUE(r.ok()) << listing(r);
  const std::vector<std::int64_t>& parts = r.job->problem.output.series_particles;
  ASSERT_EQ(parts.size(), 18u);
  EXPECT_EQ(parts.front(), 0);
  EXPECT_EQ(parts.back(), 1);
  const auto x = initial_positions(r.job->problem);
  for (std::size_t k = 1; k + 1 < parts.size(); ++k)
    EXPECT_DOUBLE_EQ(x[static_cast<std::size_t>(parts[k])][1], 2.875);
  // Errors: a bowtie, and a polygon that selects nothing.
  spec["output"]["series"]["particles"][1]["polygon"] =
      json::parse("[[2, 2.75], [8, 3], [8, 2.75], [2, 2.9]]");
  EXPECT_TRUE(has_error(parse_job(spec.dump()), "/output/series/particles/1/polygon",
                        "not a simple polygon"));
  spec["output"]["series"]["particles"][1]["polygon"] =
      json::parse("[[0.01, 3.9], [0.02, 3.9], [0.02, 3.91]]");
  EXPECT_TRUE(has_error(parse_job(spec.dump()), "/output/series/particles/1/polygon",
                        "selects no particle"));
}

}  // namespace
}  // namespace hmpm::api
