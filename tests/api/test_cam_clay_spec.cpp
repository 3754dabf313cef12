// test_cam_clay_spec.cpp — "model": "modified_cam_clay" in a job spec: the
// Problem it becomes (parameters, p'c as a number, a formula of position or
// from the OCR, the reference Young's modulus), each refusal at its JSON
// path with its advice, and the output fields void_ratio and
// preconsolidation_pressure.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

#include "hmpm/api/job.hpp"
#include "spec_support.hpp"

namespace hmpm::api {
namespace {

using json = nlohmann::json;  // NOLINT(readability-identifier-naming): nlohmann's own spelling

json clay_spec(const json& clay) {
  json spec = json::parse(R"json({"dimension": 2,
    "grid": {"min": [0, 0], "max": [1, 1], "cells": [2, 2]},
    "materials": {},
    "bodies": [{"material": "clay", "box": {"min": [0, 0], "max": [1, 1]}, "particles_per_cell": 1}],
    "time": {"end": 1, "scheme": "quasi_static", "dt": 0.5},
    "output": {"series": {"particles": [0], "fields": ["void_ratio", "preconsolidation_pressure"]}}})json");
  json material = {{"model", "modified_cam_clay"},
                   {"density", 2000},
                   {"poisson_ratio", 0.25},
                   {"lambda", 0.1},
                   {"kappa", 0.03},
                   {"critical_state_ratio", 1.2},
                   {"initial_void_ratio", 1.0}};
  for (const auto& [k, v] : clay.items()) {
    if (v.is_null())
      material.erase(k);
    else
      material[k] = v;
  }
  spec["materials"]["clay"] = material;
  return spec;
}

using testing::expect_error;

const ModifiedCamClay& cam_clay_of(const ParseResult& r) {
  static const ModifiedCamClay none;
  if (!r.job) return none;
  const auto* cc = std::get_if<ModifiedCamClay>(&r.job->problem.materials[0].plasticity);
  return cc ? *cc : none;
}

TEST(CamClaySpec, ParametersAndPreconsolidationPressure) {
  {
    const ParseResult r = parse_job(clay_spec({{"preconsolidation_pressure", 2e5}}).dump());
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    ASSERT_TRUE(r.job);
    const Material& m = r.job->problem.materials[0];
    ASSERT_TRUE(std::holds_alternative<ModifiedCamClay>(m.plasticity));
    const ModifiedCamClay& cc = cam_clay_of(r);
    EXPECT_DOUBLE_EQ(cc.lambda, 0.1);
    EXPECT_DOUBLE_EQ(cc.kappa, 0.03);
    EXPECT_DOUBLE_EQ(cc.critical_state_ratio, 1.2);
    EXPECT_DOUBLE_EQ(cc.initial_void_ratio, 1.0);
    ASSERT_TRUE(cc.preconsolidation_pressure);
    EXPECT_DOUBLE_EQ(cc.preconsolidation_pressure({0.3, 0.4, 0.0}), 2e5);
    // The reference E at p' = p'c: 3 (1 - 2 nu) (1 + e0) p'c / kappa.
    EXPECT_NEAR(m.youngs_modulus, 3 * 0.5 * 2 * 2e5 / 0.03, 1e-6);
  }
  {
    const ParseResult r =
        parse_job(clay_spec({{"preconsolidation_pressure", "1e5 + 2e4 * (1 - y)"}}).dump());
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    const ModifiedCamClay& cc = cam_clay_of(r);
    ASSERT_TRUE(cc.preconsolidation_pressure);
    EXPECT_DOUBLE_EQ(cc.preconsolidation_pressure({0.0, 0.25, 0.0}), 1.15e5);
  }
  {
    const ParseResult r =
        parse_job(clay_spec({{"overconsolidation_ratio", 2}, {"youngs_modulus", 3e7}}).dump());
    for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
    const ModifiedCamClay& cc = cam_clay_of(r);
    EXPECT_FALSE(cc.preconsolidation_pressure);
    EXPECT_DOUBLE_EQ(cc.overconsolidation_ratio, 2);
    ASSERT_TRUE(r.job);
    EXPECT_DOUBLE_EQ(r.job->problem.materials[0].youngs_modulus, 3e7);  // given: kept
  }
}

TEST(CamClaySpec, RefusalsAtTheirPathsWithAdvice) {
  const std::string m = "/materials/clay";
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"kappa", 0.1}}), m + "/kappa",
               "not below lambda");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"kappa", 0.2}}), m + "/kappa",
               "flatter than the normal compression line");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"initial_void_ratio", 0}}),
               m + "/initial_void_ratio", "> 0");
  expect_error(clay_spec({{"overconsolidation_ratio", 0.5}}), m + "/overconsolidation_ratio",
               ">= 1");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"critical_state_ratio", 0}}),
               m + "/critical_state_ratio", "> 0");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"critical_state_ratio", 4}}),
               m + "/critical_state_ratio", "at most 3");
  expect_error(clay_spec({{"preconsolidation_pressure", -1}}), m + "/preconsolidation_pressure",
               "> 0");
  expect_error(clay_spec({{"preconsolidation_pressure", "1e5 +* y"}}),
               m + "/preconsolidation_pressure", "");
  expect_error(clay_spec({}), m + "/preconsolidation_pressure",
               "or overconsolidation_ratio is required");
  expect_error(clay_spec({{"preconsolidation_pressure", 1e5}, {"overconsolidation_ratio", 2}}),
               m + "/preconsolidation_pressure", "give one of them");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"lambda", nullptr}}), m + "/lambda",
               "is required");
  expect_error(clay_spec({{"overconsolidation_ratio", 1}, {"cohesion", 5}}), m + "/cohesion",
               "applies only to");
  // The others still need their Young's modulus.
  json elastic = clay_spec({{"overconsolidation_ratio", 1}});
  elastic["materials"]["clay"] = {
      {"model", "linear_elastic"}, {"density", 1}, {"poisson_ratio", 0}};
  expect_error(elastic, m + "/youngs_modulus", "is required");
  json other = clay_spec({{"overconsolidation_ratio", 1}});
  other["materials"]["clay"] = {{"model", "linear_elastic"},
                                {"density", 1},
                                {"poisson_ratio", 0},
                                {"youngs_modulus", 1},
                                {"lambda", 0.1}};
  expect_error(other, m + "/lambda", "applies only to model 'modified_cam_clay'");
}

TEST(CamClaySpec, OutputFieldsAreKnown) {
  const ParseResult r = parse_job(clay_spec({{"overconsolidation_ratio", 1.5}}).dump());
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job);
  const auto& fields = r.job->problem.output.series_fields;
  EXPECT_NE(std::find(fields.begin(), fields.end(), Field::void_ratio), fields.end());
  EXPECT_NE(std::find(fields.begin(), fields.end(), Field::preconsolidation_pressure),
            fields.end());
}

}  // namespace
}  // namespace hmpm::api
