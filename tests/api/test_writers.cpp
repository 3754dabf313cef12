// test_writers.cpp — the result files from synthetic data with known values:
// series.json layout of the contract, series.csv header and rows, VTU and PVD
// read back by an independent reader (meshio, via check_results.py), atomic
// writes, run_job's summary on success and on failure, reactions.json and
// reactions.csv.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "results/writers.hpp"
#include "test_support.hpp"

namespace hmpm::api {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// 2D series: particles 4 and 9, displacement (2 comps), pore_pressure (1),
// strain (6); value = 1000 * row + 100 * particle slot + 10 * field + component.
Series synthetic_series() {
  Series s;
  s.dimension = 2;
  s.time = {0.0, 0.5, 1.0};
  s.particles = {4, 9};
  s.initial_positions = {Vec3{0.25, 0.5, 0}, Vec3{0.75, 0.125, 0}};
  s.fields = {Field::displacement, Field::pore_pressure, Field::strain};
  for (std::size_t f = 0; f < s.fields.size(); ++f) {
    const int nc = field_components(s.fields[f], 2);
    std::vector<double> v;
    for (std::size_t r = 0; r < s.time.size(); ++r)
      for (std::size_t p = 0; p < s.particles.size(); ++p)
        for (int c = 0; c < nc; ++c) v.push_back(1000.0 * r + 100.0 * p + 10.0 * f + c);
    s.values.push_back(v);
  }
  return s;
}

Snapshot synthetic_snapshot(int index, std::int64_t n) {
  Snapshot s;
  s.index = index;
  s.time = 0.25 * index;
  s.dimension = 2;
  s.particles = n;
  s.fields = {Field::position, Field::velocity, Field::pore_pressure, Field::effective_stress};
  for (std::int64_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i);
    s.position.insert(s.position.end(), {x, 2 * x, 0});
    s.velocity.insert(s.velocity.end(), {-x, 0.5, 0});
    s.pore_pressure.push_back(100 + x);
    for (int k = 0; k < 6; ++k) s.effective_stress.push_back(-x * (k + 1));
    s.volume.push_back(0.01);
    s.material.push_back(static_cast<int>(i % 2));
  }
  return s;
}

TEST(Writers, SeriesJsonHasTheContractLayout) {
  testing::TempDir dir;
  write_series_json(dir.path() / "series.json", synthetic_series());
  const json j = json::parse(testing::read_text(dir.path() / "series.json"));
  EXPECT_EQ(j["time"], json({0.0, 0.5, 1.0}));
  ASSERT_EQ(j["particles"].size(), 2u);
  const json& p1 = j["particles"][1];
  EXPECT_EQ(p1["index"], 9);
  EXPECT_EQ(p1["initial_position"], json({0.75, 0.125}));
  // Vectors: arrays of dim components; scalars: numbers; tensors: 6 (Voigt).
  EXPECT_EQ(p1["displacement"][2], json({2100.0, 2101.0}));
  EXPECT_EQ(p1["pore_pressure"], json({110.0, 1110.0, 2110.0}));
  ASSERT_EQ(p1["strain"][0].size(), 6u);
  EXPECT_EQ(p1["strain"][0][5], 125.0);
  EXPECT_FALSE(fs::exists(dir.path() / "series.json.tmp"));
}

TEST(Writers, OneDimensionalVectorsAreStillArrays) {
  Series s;
  s.dimension = 1;
  s.time = {0.0, 1.0};
  s.particles = {3};
  s.initial_positions = {Vec3{0.5, 0, 0}};
  s.fields = {Field::displacement, Field::pore_pressure};
  s.values = {{0.25, 0.5}, {7.0, 8.0}};
  testing::TempDir dir;
  write_series_json(dir.path() / "series.json", s);
  const json j = json::parse(testing::read_text(dir.path() / "series.json"));
  EXPECT_EQ(j["particles"][0]["displacement"],
            json::parse("[[0.25], [0.5]]"));  // contract: [[ux], ...]
  EXPECT_EQ(j["particles"][0]["pore_pressure"], json::parse("[7.0, 8.0]"));
  EXPECT_EQ(j["particles"][0]["initial_position"], json::parse("[0.5]"));
}

TEST(Writers, SeriesCsvMatchesJson) {
  testing::TempDir dir;
  write_series_csv(dir.path() / "series.csv", synthetic_series());
  const std::string csv = testing::read_text(dir.path() / "series.csv");
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(
      header.rfind("time,p4_displacement_x,p4_displacement_y,p4_pore_pressure,p4_strain_xx,", 0),
      0u)
      << header;
  EXPECT_NE(header.find(",p9_strain_zx"), std::string::npos);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);  // header + 3 rows
  EXPECT_NE(csv.find("\n0.5,1000,1001,1010,1020,"), std::string::npos) << csv;
}

TEST(Writers, NonFiniteValuesStayReadable) {
  Series s = synthetic_series();
  s.values[1][0] = std::nan("");
  s.values[1][1] = std::numeric_limits<double>::infinity();
  testing::TempDir dir;
  write_series_json(dir.path() / "series.json", s);
  write_series_csv(dir.path() / "series.csv", s);
  const json j = json::parse(testing::read_text(dir.path() / "series.json"));  // null, still JSON
  EXPECT_TRUE(j["particles"][0]["pore_pressure"][0].is_null());
  EXPECT_NE(testing::read_text(dir.path() / "series.csv").find(",nan,"), std::string::npos);
}

// Reactions of 3 boundaries in 2D at 2 times: value = 100 * row + 10 * boundary + component.
Reactions synthetic_reactions() {
  Reactions r;
  r.dimension = 2;
  r.time = {0.25, 0.5};
  r.force.resize(3);
  for (std::size_t row = 0; row < r.time.size(); ++row)
    for (std::size_t b = 0; b < r.force.size(); ++b)
      for (int c = 0; c < 2; ++c) r.force[b].push_back(100.0 * row + 10.0 * b + c);
  return r;
}

TEST(Writers, ReactionsJsonHasTheContractLayoutAndCsvTheSameNumbers) {
  testing::TempDir dir;
  const Reactions r = synthetic_reactions();
  write_reactions_json(dir.path() / "reactions.json", r);
  write_reactions_csv(dir.path() / "reactions.csv", r);
  const json j = json::parse(testing::read_text(dir.path() / "reactions.json"));
  EXPECT_EQ(j["time"], json({0.25, 0.5}));
  ASSERT_EQ(j["boundaries"].size(), 3u);
  EXPECT_EQ(j["boundaries"][2]["index"], 2);
  EXPECT_EQ(j["boundaries"][2]["force"], json::parse("[[20, 21], [120, 121]]"));
  const std::string csv = testing::read_text(dir.path() / "reactions.csv");
  EXPECT_EQ(csv,
            "time,b0_force_x,b0_force_y,b1_force_x,b1_force_y,b2_force_x,b2_force_y\n"
            "0.25,0,1,10,11,20,21\n"
            "0.5,100,101,110,111,120,121\n");
}

// profiles.json and profiles.csv: two lines with different fields, two
// times; the CSV's columns are the union, empty where a line lacks one.
TEST(Writers, ProfilesHaveTheirPointsDistancesAndRows) {
  testing::TempDir dir;
  std::vector<Series> profiles(2);
  std::vector<ProfileGeometry> geometry(2);
  for (std::size_t l = 0; l < 2; ++l) {
    Series& s = profiles[l];
    s.dimension = 2;
    s.time = {0.0, 0.5};
    s.particles = {static_cast<std::int64_t>(10 * l), static_cast<std::int64_t>(10 * l + 1)};
    s.initial_positions = {{0.0, 0.0, 0}, {0.0, 1.0, 0}};
    geometry[l].from = {0.0, 0.0, 0};
    geometry[l].to = {0.0, 2.0, 0};
    geometry[l].points = {{0.0, 0.0, 0}, {0.0, 2.0, 0}};
  }
  profiles[0].fields = {Field::pore_pressure};
  profiles[0].values = {{1, 2, 3, 4}};  // rows: time, then point
  profiles[1].fields = {Field::displacement};
  profiles[1].values = {{1, 2, 3, 4, 5, 6, 7, 8}};
  write_profiles_json(dir.path() / "profiles.json", profiles, geometry);
  write_profiles_csv(dir.path() / "profiles.csv", profiles, geometry);
  const json j = json::parse(testing::read_text(dir.path() / "profiles.json"));
  EXPECT_EQ(j["time"], json({0.0, 0.5}));
  ASSERT_EQ(j["profiles"].size(), 2u);
  EXPECT_EQ(j["profiles"][0]["distance"], json({0.0, 2.0}));
  EXPECT_EQ(j["profiles"][0]["pore_pressure"], json::parse("[[1, 2], [3, 4]]"));
  EXPECT_EQ(j["profiles"][1]["displacement"], json::parse("[[[1, 2], [3, 4]], [[5, 6], [7, 8]]]"));
  EXPECT_EQ(j["profiles"][1]["particles"], json({10, 11}));
  EXPECT_EQ(testing::read_text(dir.path() / "profiles.csv"),
            "time,profile,point,distance,pore_pressure,displacement_x,displacement_y\n"
            "0,0,0,0,1,,\n"
            "0,0,1,2,2,,\n"
            "0,1,0,0,,1,2\n"
            "0,1,1,2,,3,4\n"
            "0.5,0,0,0,3,,\n"
            "0.5,0,1,2,4,,\n"
            "0.5,1,0,0,,5,6\n"
            "0.5,1,1,2,,7,8\n");
}

// consolidation.json and consolidation.csv: the degree, the average excess
// (E / V), t50 and t90 (null when not reached).
TEST(Writers, ConsolidationHasDegreeAverageExcessAndItsTimes) {
  testing::TempDir dir;
  RunResult::Consolidation c;
  c.time = {10.0, 20.0, 30.0};
  c.excess = {100.0, 40.0, 20.0};
  c.volume = {2.0, 2.0, 2.0};
  c.degree = {0.0, 0.6, 0.8};
  c.t50 = 18.0;  // t90 stays NaN: not reached
  write_consolidation_json(dir.path() / "consolidation.json", c, 10.0);
  write_consolidation_csv(dir.path() / "consolidation.csv", c);
  const json j = json::parse(testing::read_text(dir.path() / "consolidation.json"));
  EXPECT_EQ(j["from"], 10.0);
  EXPECT_EQ(j["t50"], 18.0);
  EXPECT_TRUE(j["t90"].is_null());
  EXPECT_EQ(j["time"], json({10.0, 20.0, 30.0}));
  EXPECT_EQ(j["degree"], json({0.0, 0.6, 0.8}));
  EXPECT_EQ(j["average_excess_pore_pressure"], json({50.0, 20.0, 10.0}));
  EXPECT_EQ(j["volume"], json({2.0, 2.0, 2.0}));
  EXPECT_EQ(testing::read_text(dir.path() / "consolidation.csv"),
            "time,degree,average_excess_pore_pressure,volume\n"
            "10,0,50,2\n"
            "20,0.6,20,2\n"
            "30,0.8,10,2\n");
}

TEST(Writers, SnapshotsReadBackWithMeshio) {
  testing::TempDir dir;
  std::vector<std::pair<double, std::string>> entries;
  for (int i = 0; i < 3; ++i) {
    const Snapshot s = synthetic_snapshot(i, 7);
    write_snapshot_vtu(dir.path() / snapshot_file_name(i), s);
    entries.emplace_back(s.time, snapshot_file_name(i));
  }
  write_pvd(dir.path() / "snapshots.pvd", entries);
  RunResult run;
  run.status = RunStatus::successful;
  run.particles = 7;
  write_summary(dir.path() / "summary.json", "synthetic", run, CostEstimate{}, {});
  EXPECT_EQ(snapshot_file_name(12), "snapshot_0012.vtu");
  const std::string py = testing::python_exe(dir.path());
  const auto r =
      testing::run_command("bash -c " + std::string("\"") + py + " '" +
                               testing::source_path("tests/api/check_results.py").string() + "' '" +
                               dir.path().string() + "' --hmpm '" + HMPM_EXE +
                               "' --particles 7 --require-snapshots --snapshot-fields "
                               "velocity,pore_pressure,effective_stress\"",
                           dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  // Exact values through meshio.
  const std::string probe =
      py + " -c \"import meshio; m = meshio.read('" + (dir.path() / "snapshot_0002.vtu").string() +
      "'); print(m.points[3].tolist(), m.point_data['effective_stress'][3].tolist(), "
      "m.point_data['material'].tolist(), m.point_data['pore_pressure'][6])\"";
  const auto v = testing::run_command(probe, dir.path());
  EXPECT_EQ(v.out,
            "[3.0, 6.0, 0.0] [-3.0, -6.0, -9.0, -12.0, -15.0, -18.0] [0, 1, 0, 1, 0, 1, 0] 106.0\n")
      << v.err;
}

// VTK's own reader (Debian's python3-vtk9, what ParaView is built on) sees
// the component names of vectors and tensors, the material names in the
// field data (one array per material, named after it: a name with XML's
// special characters survives), and a plastic_strain array. meshio reads
// the same files in SnapshotsReadBackWithMeshio and the examples' checks.
TEST(Writers, SnapshotsCarryComponentAndMaterialNamesForVtk) {
  testing::TempDir dir;
  Snapshot s = synthetic_snapshot(1, 5);
  s.fields.push_back(Field::plastic_strain);
  for (int i = 0; i < 5; ++i) s.plastic_strain.push_back(0.125 * i);
  s.id = {7, 3, 12, 0, 40};  // the job's numbering, not the run's order
  write_snapshot_vtu(dir.path() / "snapshot_0001.vtu", s, {"clay", "sand & \"fill\""});
  const std::string script = (dir.path() / "probe.py").string();
  std::ofstream(script) << "import sys, vtk\n"
                           "r = vtk.vtkXMLUnstructuredGridReader()\n"
                           "r.SetFileName(sys.argv[1]); r.Update()\n"
                           "g = r.GetOutput(); pd = g.GetPointData()\n"
                           "for name in ('velocity', 'effective_stress'):\n"
                           "    a = pd.GetArray(name)\n"
                           "    print(name, [a.GetComponentName(c) for c in "
                           "range(a.GetNumberOfComponents())])\n"
                           "fd = g.GetFieldData()\n"
                           "print(sorted((fd.GetArrayName(i), fd.GetArray(i).GetValue(0)) "
                           "for i in range(fd.GetNumberOfArrays())))\n"
                           "e = pd.GetArray('plastic_strain')\n"
                           "print([e.GetValue(i) for i in range(e.GetNumberOfTuples())])\n"
                           "i = pd.GetArray('particle_id')\n"
                           "print(i.GetDataTypeAsString(), "
                           "[i.GetValue(k) for k in range(i.GetNumberOfTuples())])\n";
  const auto v = testing::run_command(
      "/usr/bin/python3 '" + script + "' '" + (dir.path() / "snapshot_0001.vtu").string() + "'",
      dir.path());
  EXPECT_EQ(v.exit_code, 0) << v.err;
  EXPECT_EQ(v.out,
            "velocity ['x', 'y', 'z']\n"
            "effective_stress ['xx', 'yy', 'zz', 'xy', 'yz', 'zx']\n"
            "[('TimeValue', 0.25), ('material clay', 0), ('material sand & \"fill\"', 1)]\n"
            "[0.0, 0.125, 0.25, 0.375, 0.5]\n"
            "long long [7, 3, 12, 0, 40]\n")
      << v.err;
}

TEST(Writers, SummaryNamesTheSchemeAndTheImplicitIterations) {
  testing::TempDir dir;
  RunResult run;
  run.status = RunStatus::successful;
  run.scheme = "quasi_static";
  run.reports_iterations = true;  // what the quasi-static and semi-implicit schemes set
  run.iterations.nonlinear = 123;
  run.iterations.linear = 4567;
  run.iterations.solves = 130;
  run.iterations.cutbacks = 2;
  run.iterations.max_nonlinear = 9;
  run.iterations.worst_residuals = {0.5, 1e-3, 1e-9};
  write_summary(dir.path() / "summary.json", "q", run, CostEstimate{}, {});
  const json s = json::parse(testing::read_text(dir.path() / "summary.json"));
  EXPECT_EQ(s["scheme"], "quasi_static");
  EXPECT_EQ(s["iterations"], (json{{"nonlinear", 123},
                                   {"linear", 4567},
                                   {"solves", 130},
                                   {"cutbacks", 2},
                                   {"max_nonlinear", 9},
                                   {"worst_residuals", {0.5, 1e-3, 1e-9}}}));
  // The explicit scheme has no iterations to report.
  RunResult plain;
  plain.status = RunStatus::successful;
  write_summary(dir.path() / "summary.json", "e", plain, CostEstimate{}, {});
  const json e = json::parse(testing::read_text(dir.path() / "summary.json"));
  EXPECT_EQ(e["scheme"], "explicit");
  EXPECT_FALSE(e.contains("iterations"));
}

TEST(Writers, EmptySnapshotIsStillAValidFile) {
  testing::TempDir dir;
  write_snapshot_vtu(dir.path() / "snapshot_0000.vtu", synthetic_snapshot(0, 0));
  const std::string text = testing::read_text(dir.path() / "snapshot_0000.vtu");
  EXPECT_NE(text.find("NumberOfPoints=\"0\""), std::string::npos);
}

TEST(Writers, UnwritableDirectoryThrows) {
  EXPECT_THROW(write_pvd("/nonexistent-dir/x/snapshots.pvd", {}), std::runtime_error);
}

TEST(RunJob, WritesEveryRequestedFileAndASummary) {
  const ParseResult parsed =
      parse_job(testing::read_text(testing::source_path("tests/api/data/valid-2d.json")));
  ASSERT_TRUE(parsed.job);
  testing::TempDir dir;
  const JobOutcome out = run_job(*parsed.job, dir.path() / "results");
  for (const std::string& f : out.files) EXPECT_TRUE(fs::exists(dir.path() / "results" / f)) << f;
  EXPECT_NE(std::find(out.files.begin(), out.files.end(), "summary.json"), out.files.end());
  const json summary = json::parse(testing::read_text(dir.path() / "results" / "summary.json"));
  for (const char* key :
       {"status", "message", "steps", "end_time", "dt", "particles", "nodes", "solve_seconds",
        "particle_steps_per_second", "warnings", "cost", "name", "hmpm_version", "scheme"})
    EXPECT_TRUE(summary.contains(key)) << key;
  EXPECT_EQ(summary["name"], "valid-2d");
  EXPECT_EQ(summary["cost"]["particles"], 48);
  EXPECT_EQ(summary["status"], "successful") << summary["message"];
  // The automatic fixed step: every step but a last shortened one is dt.
  EXPECT_EQ(summary["time_step"]["rule"], "stable");
  EXPECT_EQ(summary["time_step"]["min"], summary["dt"]);
  EXPECT_EQ(summary["time_step"]["max"], summary["dt"]);
  EXPECT_NE(std::find(out.files.begin(), out.files.end(), "series.json"), out.files.end());
  EXPECT_NE(std::find(out.files.begin(), out.files.end(), "snapshots.pvd"), out.files.end());
}

TEST(RunJob, FailedWriteLeavesOnlyASummaryAndSaysWhy) {
  const ParseResult parsed =
      parse_job(testing::read_text(testing::source_path("examples/bar-vibration.json")));
  ASSERT_TRUE(parsed.job);
  testing::TempDir dir;
  // A directory where the second snapshot file should go makes its rename
  // fail after the first snapshot and the .pvd were written.
  fs::create_directories(dir.path() / "snapshot_0001.vtu" / "blocker");
  const JobOutcome out = run_job(*parsed.job, dir.path());
  EXPECT_NE(out.write_error.find("snapshot_0001"), std::string::npos) << out.write_error;
  EXPECT_EQ(out.run.status, RunStatus::failed);
  EXPECT_EQ(out.files, std::vector<std::string>{"summary.json"});
  // The snapshot and collection written before the failure are gone.
  EXPECT_FALSE(fs::exists(dir.path() / "snapshot_0000.vtu"));
  EXPECT_FALSE(fs::exists(dir.path() / "snapshots.pvd"));
  const json summary = json::parse(testing::read_text(dir.path() / "summary.json"));
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["message"].get<std::string>().find("could not write"), std::string::npos);
  EXPECT_NE(summary["message"].get<std::string>().find("removed"), std::string::npos);
}

/// The numbers of a CSV file: its header's names and its rows.
std::pair<std::vector<std::string>, std::vector<std::vector<double>>> read_csv(
    const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::getline(in, line);
  std::istringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  while (std::getline(in, line)) {
    std::istringstream l(line);
    rows.emplace_back();
    for (std::string cell; std::getline(l, cell, ',');) rows.back().push_back(std::stod(cell));
  }
  return {header, rows};
}

// A 2D column at rest (geostatic, dry: rho = 2000 kg/m^3, H = 1 m, W = 0.4
// m) on a fixed base between rollers: reactions.json and reactions.csv are
// listed, parse back, hold the same numbers, and the base carries the
// column's weight rho g H W = 7848 N/m (to round-off, test_reactions.cpp
// says why; 1e-9 here for the 17 significant digits of the text).
TEST(RunJob, WritesReactionsThatParseBackAndAgree) {
  const std::string spec = R"({
    "name": "column", "dimension": 2,
    "grid": {"min": [0, 0], "max": [0.4, 1.2], "cells": [4, 12]},
    "materials": {"soil": {"model": "linear_elastic", "density": 2000, "youngs_modulus": 1e7,
                           "poisson_ratio": 0.3}},
    "bodies": [{"material": "soil", "box": {"min": [0, 0], "max": [0.4, 1.0]}}],
    "gravity": [0, -9.81],
    "initial_state": {"geostatic": {"k0": 0.5}},
    "boundaries": [
      {"nodes": {"box": {"min": [0, 0], "max": [0.4, 0]}}, "velocity": [0, 0]},
      {"nodes": {"box": {"min": [0, 0], "max": [0, 1.2]}}, "velocity": [0, null]},
      {"nodes": {"box": {"min": [0.4, 0], "max": [0.4, 1.2]}}, "velocity": [0, null]}],
    "time": {"end": 0.05},
    "output": {"reactions": {"interval": 0.01}}})";
  const ParseResult parsed = parse_job(spec);
  ASSERT_TRUE(parsed.job) << (parsed.errors.empty() ? "" : parsed.errors[0].message);
  testing::TempDir dir;
  const JobOutcome out = run_job(*parsed.job, dir.path());
  ASSERT_EQ(out.run.status, RunStatus::successful) << out.run.message;
  for (const char* f : {"reactions.json", "reactions.csv"}) {
    EXPECT_NE(std::find(out.files.begin(), out.files.end(), f), out.files.end()) << f;
  }
  EXPECT_EQ(media_type_for("reactions.json"), "application/json");
  EXPECT_EQ(media_type_for("reactions.csv"), "text/csv");
  const json j = json::parse(testing::read_text(dir.path() / "reactions.json"));
  const auto [header, rows] = read_csv(testing::read_text(dir.path() / "reactions.csv"));
  ASSERT_EQ(j["boundaries"].size(), 3u);
  ASSERT_EQ(header.size(), 1u + 3 * 2);
  EXPECT_EQ(header[4], "b1_force_y");
  ASSERT_EQ(rows.size(), j["time"].size());
  ASSERT_GE(rows.size(), 5u);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), header.size());
    EXPECT_EQ(rows[k][0], j["time"][k].get<double>());
    for (std::size_t b = 0; b < 3; ++b) {
      EXPECT_EQ(j["boundaries"][b]["index"], b);
      for (std::size_t c = 0; c < 2; ++c)
        EXPECT_EQ(rows[k][1 + 2 * b + c], j["boundaries"][b]["force"][k][c].get<double>());
    }
    const double weight = 2000 * 9.81 * 1.0 * 0.4;
    EXPECT_NEAR(rows[k][2], weight, 1e-9 * weight);  // the base, vertical
    EXPECT_EQ(rows[k][4], 0.0);                      // the rollers, vertical
    EXPECT_EQ(rows[k][6], 0.0);
  }
}

// A run stopped after a checkpoint and resumed from it in the same folder
// writes the files of an uninterrupted run: the snapshots before the
// checkpoint stay (and are listed in the .pvd again), the series comes from
// the checkpoint; summary.json differs in its wall-time fields only.
TEST(RunJob, ResumedFromACheckpointWritesTheFilesOfAnUninterruptedRun) {
  ParseResult parsed =
      parse_job(testing::read_text(testing::source_path("examples/bar-vibration.json")));
  ASSERT_TRUE(parsed.job);
  parsed.job->problem.output.reactions_interval = 0.05;  // a history in the checkpoint too
  testing::TempDir dir;
  const JobOutcome whole = run_job(*parsed.job, dir.path() / "whole");
  EXPECT_NE(std::find(whole.files.begin(), whole.files.end(), "reactions.csv"), whole.files.end());
  ASSERT_EQ(whole.run.status, RunStatus::successful) << whole.run.message;
  const std::int64_t k = whole.run.steps / 2;
  std::string bytes;
  std::atomic<bool> stop{false};
  RunOptions first;
  first.checkpoint_interval_s = 1e-12;  // every step
  first.checkpoint_key = "bar";
  first.cancel = &stop;
  first.on_checkpoint = [&](const Checkpoint& c) {
    if (c.step == k) {
      bytes = c.bytes;
      stop = true;
    }
  };
  const JobOutcome stopped = run_job(*parsed.job, dir.path() / "resumed", first);
  ASSERT_EQ(stopped.run.status, RunStatus::cancelled);
  ASSERT_FALSE(bytes.empty());
  RunOptions again;
  again.checkpoint_key = "bar";
  again.resume = &bytes;
  const JobOutcome resumed = run_job(*parsed.job, dir.path() / "resumed", again);
  ASSERT_EQ(resumed.run.status, RunStatus::successful) << resumed.run.message;
  EXPECT_EQ(resumed.files, whole.files);
  for (const std::string& f : whole.files) {
    std::string a = testing::read_text(dir.path() / "whole" / f);
    std::string b = testing::read_text(dir.path() / "resumed" / f);
    if (f == "summary.json") {
      json ja = json::parse(a), jb = json::parse(b);
      for (const char* wall : {"solve_seconds", "particle_steps_per_second"}) {
        ja.erase(wall);
        jb.erase(wall);
      }
      EXPECT_EQ(ja, jb);
    } else {
      EXPECT_EQ(a, b) << f;
    }
  }
}

}  // namespace
}  // namespace hmpm::api
