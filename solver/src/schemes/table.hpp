// schemes/table.hpp — the time schemes, one row each (internal).
//
// A row: the enum value (hmpm::Scheme, problem.hpp), the contract name
// (scheme_name), the rules that need only the Problem (stable step, checks;
// <scheme>_rules.cpp) and whether the scheme reports iteration counts
// (RunResult::reports_iterations, summary.json's "iterations"). The
// constructor of each, over a StepContext, is make_scheme below, in the same
// order. A new scheme: its enum value, its row and its case here, its
// <scheme>.hpp and <scheme>_rules.cpp (solver/CMakeLists.txt).
#pragma once

#include <memory>

#include "hmpm/problem.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

struct SchemeRow {
  Scheme scheme;
  const char* name;  ///< the contract name (job spec, summary.json)
  const SchemeRules& (*rules)();
  bool reports_iterations;  ///< RunResult::iterations are the scheme's
};

inline constexpr SchemeRow scheme_table[] = {
    {Scheme::explicit_scheme, "explicit", explicit_scheme_rules, false},
    {Scheme::semi_implicit, "semi_implicit", semi_implicit_scheme_rules, true},
    {Scheme::quasi_static, "quasi_static", quasi_static_scheme_rules, true},
};

/// The row of scheme s (schemes/table.cpp).
const SchemeRow& scheme_row(Scheme s);

template <int Dim, class Shape>
struct StepContext;

/// The scheme s over the parts of a run (the constructors, in the table's
/// order; defined in schemes/make_scheme.hpp, which includes the schemes).
template <int Dim, class Shape>
std::unique_ptr<TimeScheme> make_scheme(StepContext<Dim, Shape> context, Scheme s);

}  // namespace hmpm
