// test_cli.cpp — the `hmpm` executable as a black box: help and version,
// exit codes 0 / 1 (usage) / 2 (invalid spec) / 3 (run failed, summary.json
// says why), stdin as "-", and results written by `run`.
#include <filesystem>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace hmpm::api {
namespace {

using nlohmann::json;
using testing::hmpm_exe;
using testing::run_command;
using testing::source_path;
namespace fs = std::filesystem;

TEST(Cli, HelpAndVersion) {
  testing::TempDir dir;
  auto r = run_command(hmpm_exe() + " --help", dir.path());
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("hmpm run SPEC.json --out DIR"), std::string::npos);
  r = run_command(hmpm_exe() + " --version", dir.path());
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.rfind("hmpm ", 0), 0u);
}

TEST(Cli, UsageErrorsExitOne) {
  testing::TempDir dir;
  EXPECT_EQ(run_command(hmpm_exe(), dir.path()).exit_code, 1);
  EXPECT_EQ(run_command(hmpm_exe() + " frobnicate", dir.path()).exit_code, 1);
  EXPECT_EQ(run_command(hmpm_exe() + " run x.json", dir.path()).exit_code, 1);  // no --out
  EXPECT_EQ(run_command(hmpm_exe() + " run x.json --out o --threads zero", dir.path()).exit_code,
            1);
  const auto r = run_command(hmpm_exe() + " validate /nonexistent/spec.json", dir.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cannot read"), std::string::npos);
}

/// stderr holds the two plausibility warnings of the non-dimensional bar
/// (E = 10 Pa, 1 kg/m3; documented in docs/job-spec.md) and nothing else.
/// `root` is "/" for validate (JSON pointers), "" for run (the solver's paths).
void expect_only_bar_warnings(const std::string& err, const std::string& root) {
  std::istringstream lines(err);
  std::vector<std::string> paths;
  for (std::string line; std::getline(lines, line);) {
    const std::string prefix = "hmpm: warning: " + root + "materials/bar/";
    ASSERT_EQ(line.rfind(prefix, 0), 0u) << line;
    paths.push_back(line.substr(prefix.size(), line.find(':', prefix.size()) - prefix.size()));
  }
  EXPECT_EQ(paths, (std::vector<std::string>{"youngs_modulus", "density"})) << err;
}

TEST(Cli, ValidateExamplesExitZero) {
  testing::TempDir dir;
  for (const char* name : {"bar-vibration", "darcy-flow", "terzaghi"}) {
    const auto r =
        run_command(hmpm_exe() + " validate '" +
                        source_path(std::string("examples/") + name + ".json").string() + "'",
                    dir.path());
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    // The bar is a non-dimensional benchmark (E = 10 Pa, 1 kg/m3): its two
    // plausibility warnings are documented (docs/job-spec.md); nothing else.
    if (std::string(name) == "bar-vibration")
      expect_only_bar_warnings(r.err, "/");
    else
      EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_NE(r.out.find("particles"), std::string::npos);
  }
}

TEST(Cli, SpecFromStandardInput) {
  testing::TempDir dir;
  const std::string spec = source_path("examples/bar-vibration.json").string();
  EXPECT_EQ(run_command(hmpm_exe() + " validate - < '" + spec + "'", dir.path()).exit_code, 0);
  const auto r =
      run_command("echo '{\"dimension\": 9}' | " + hmpm_exe() + " validate -", dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/dimension: "), std::string::npos);
  EXPECT_NE(r.err.find("/time: is required"), std::string::npos);
}

TEST(Cli, RunWithInvalidSpecExitsTwoAndWritesNothing) {
  testing::TempDir dir;
  const auto spec = dir.path() / "bad.json";
  testing::write_text(spec, R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [4]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": -1, "poisson_ratio": 0}},
    "bodies": [{"material": "m", "box": {"min": [0], "max": [1]}}], "time": {"end": 1}})json");
  const auto r = run_command(
      hmpm_exe() + " run '" + spec.string() + "' --out '" + (dir.path() / "out").string() + "'",
      dir.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "/materials/m/youngs_modulus: is -1; must be > 0\n");
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

TEST(Cli, RunWritesResultsAndExitsZero) {
  testing::TempDir dir;
  const auto out = dir.path() / "out";
  const auto r =
      run_command(hmpm_exe() + " run '" + source_path("examples/bar-vibration.json").string() +
                      "' --out '" + out.string() + "' --threads 1",
                  dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // No progress bar when stderr is not a terminal: only the bar's two
  // documented plausibility warnings (a non-dimensional benchmark).
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  expect_only_bar_warnings(r.err, "");
  for (const char* f :
       {"summary.json", "series.json", "series.csv", "snapshots.pvd", "snapshot_0000.vtu"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const json summary = json::parse(testing::read_text(out / "summary.json"));
  EXPECT_EQ(summary["status"], "successful");
  EXPECT_EQ(summary["particles"], 13);
  EXPECT_EQ(summary["nodes"], 14);
}

// A spec that is valid but whose run cannot succeed: particles fly out of the
// grid within a few steps. Exit 3, the reason on stderr and in summary.json.
TEST(Cli, FailedRunExitsThreeWithTheReason) {
  testing::TempDir dir;
  const auto spec = dir.path() / "flies-away.json";
  testing::write_text(spec, R"json({"dimension": 1, "grid": {"min": [0], "max": [1], "cells": [10]},
    "materials": {"m": {"model": "linear_elastic", "density": 1, "youngs_modulus": 1, "poisson_ratio": 0}},
    "bodies": [{"material": "m", "box": {"min": [0], "max": [1]}, "particles_per_cell": 1,
                "initial": {"velocity": [1e4]}}],
    "time": {"end": 1, "dt": 0.01}})json");
  const auto out = dir.path() / "out";
  const auto r = run_command(
      hmpm_exe() + " run '" + spec.string() + "' --out '" + out.string() + "'", dir.path());
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  ASSERT_TRUE(fs::exists(out / "summary.json"));
  const json summary = json::parse(testing::read_text(out / "summary.json"));
  EXPECT_EQ(summary["status"], "failed");
  const std::string message = summary["message"];
  EXPECT_FALSE(message.empty());
  EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
}

}  // namespace
}  // namespace hmpm::api
