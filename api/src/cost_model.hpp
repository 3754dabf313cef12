// cost_model.hpp — the api's model of what each time scheme costs: its
// number of steps and its wall time (cost.cpp). The constants of the
// wall-time model live in cost.cpp and nowhere else; docs/performance.md
// ("Wall-time estimate") states them and their error over the examples.
#pragma once

#include <cstdint>
#include <string>

#include "hmpm/api/job.hpp"

namespace hmpm::api::cost {

/// Steps and wall time of `problem` run with `scheme`: with the problem's
/// own dt (or step growth) when `scheme` is its scheme, else with that
/// scheme's automatic step.
SchemeCost scheme_cost(const Problem& problem, Scheme scheme, const Calibration& calibration);

/// Steps of a geometric growth to `end` (dt_0 = initial, dt_{n+1} =
/// min(max, growth dt_n), the last step shortened to end at `end`).
double growth_step_count(double end, const StepGrowth& growth);

/// When `problem` needs more than `max_steps` steps with its scheme: the
/// sentence naming the scheme that would run it, why, and its estimated
/// steps; "" when no other scheme would.
std::string scheme_advice(const Problem& problem, std::int64_t max_steps,
                          const Calibration& calibration);

}  // namespace hmpm::api::cost
