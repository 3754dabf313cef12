// schemes/quasi_static_plan.hpp — the quasi-static step plan shared by its
// rules (quasi_static_rules.cpp) and the scheme (internal).
#pragma once

#include <cstdint>

#include "hmpm/problem.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

/// The growth the run uses: time.growth, or the automatic plan
/// (quasi_static_rules.cpp) when time.dt and time.growth are both absent.
StepGrowth quasi_static_growth(const Problem& problem);

/// Steps of the geometric plan g to reach `end` (ignoring output landings).
std::int64_t growth_step_count(const StepGrowth& g, double end);

}  // namespace hmpm
