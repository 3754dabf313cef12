// test_softening_spec.cpp — a Mohr-Coulomb material's "softening" in a job
// spec: the Problem it becomes, each refusal at its JSON path with its
// advice (eta <= 0, residual above peak, a model that does not soften,
// unknown keys), and the warning for softening without regularisation.
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

json spec_with(const json& softening, const std::string& model = "mohr_coulomb") {
  json spec = json::parse(R"json({"dimension": 2,
    "grid": {"min": [0, 0], "max": [2, 1], "cells": [4, 2]},
    "materials": {"clay": {"model": "mohr_coulomb", "density": 2000, "youngs_modulus": 2e7,
                           "poisson_ratio": 0.3, "friction_angle": 25, "dilatancy_angle": 5,
                           "cohesion": 20000}},
    "bodies": [{"material": "clay", "box": {"min": [0, 0], "max": [2, 1]}}],
    "time": {"end": 1, "scheme": "quasi_static", "dt": 0.5}})json");
  spec["materials"]["clay"]["model"] = model;
  if (!softening.is_null()) spec["materials"]["clay"]["softening"] = softening;
  return spec;
}

json brittle() {
  return {{"residual_cohesion", 2000},
          {"residual_friction_angle", 18},
          {"residual_dilatancy_angle", 0},
          {"shape_factor", 30}};
}

using testing::expect_error;

TEST(SofteningSpec, BecomesTheMaterialsSoftening) {
  json s = brittle();
  s["reference_cell_size"] = 0.5;
  const ParseResult r = parse_job(spec_with(s).dump());
  for (const auto& e : r.errors) ADD_FAILURE() << e.path << ": " << e.message;
  ASSERT_TRUE(r.job);
  const auto* mc = std::get_if<MohrCoulomb>(&r.job->problem.materials[0].plasticity);
  ASSERT_NE(mc, nullptr);
  ASSERT_TRUE(mc->softening);
  EXPECT_DOUBLE_EQ(mc->softening->residual_cohesion, 2000);
  EXPECT_DOUBLE_EQ(mc->softening->residual_friction_angle_deg, 18);
  EXPECT_DOUBLE_EQ(mc->softening->residual_dilatancy_angle_deg, 0);
  EXPECT_DOUBLE_EQ(mc->softening->shape_factor, 30);
  EXPECT_DOUBLE_EQ(mc->softening->reference_cell_size, 0.5);
  EXPECT_FALSE(mc->softening->regularised);
  // Regularised, no warning about the grid.
  for (const auto& w : r.job->warnings)
    EXPECT_EQ(w.message.find("reference_cell_size"), std::string::npos) << w.message;
}

TEST(SofteningSpec, WithoutRegularisationWarnsThatTheGridDecides) {
  const ParseResult r = parse_job(spec_with(brittle()).dump());
  ASSERT_TRUE(r.job);
  const bool warned =
      std::any_of(r.job->warnings.begin(), r.job->warnings.end(), [](const auto& w) {
        return w.path == "/materials/clay/softening" &&
               w.message.find("set reference_cell_size") != std::string::npos &&
               w.message.find("0.5 m") != std::string::npos;  // this grid's cell size
      });
  EXPECT_TRUE(warned);
}

TEST(SofteningSpec, RefusalsAtTheirPathsWithAdvice) {
  const std::string m = "/materials/clay/softening";
  json s = brittle();
  s["shape_factor"] = 0;
  expect_error(spec_with(s), m + "/shape_factor", "3/shape_factor");
  s["shape_factor"] = -5;
  expect_error(spec_with(s), m + "/shape_factor", "must be > 0");
  s = brittle();
  s["residual_cohesion"] = 30000;
  expect_error(spec_with(s), m + "/residual_cohesion", "above the peak cohesion 20000");
  s = brittle();
  s["residual_friction_angle"] = 30;
  expect_error(spec_with(s), m + "/residual_friction_angle", "above the peak friction_angle 25");
  s = brittle();
  s["residual_dilatancy_angle"] = 8;
  expect_error(spec_with(s), m + "/residual_dilatancy_angle", "above the peak dilatancy_angle");
  s = brittle();
  s["residual_friction_angle"] = 0;
  s["residual_cohesion"] = 0;
  expect_error(spec_with(s), m + "/residual_cohesion", "no strength");
  s = brittle();
  s.erase("shape_factor");
  expect_error(spec_with(s), m + "/shape_factor", "is required");
  s = brittle();
  s["residual_cohesion_kpa"] = 2;
  expect_error(spec_with(s), m + "/residual_cohesion_kpa", "");
  s = brittle();
  s["reference_cell_size"] = 0;
  expect_error(spec_with(s), m + "/reference_cell_size", "> 0");
  expect_error(spec_with(brittle(), "drucker_prager"), m, "applies only to model 'mohr_coulomb'");
  expect_error(spec_with(json::array(), "mohr_coulomb"), m, "");
}

}  // namespace
}  // namespace hmpm::api
