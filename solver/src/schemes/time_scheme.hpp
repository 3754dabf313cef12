// schemes/time_scheme.hpp — the seam between the time loop and a time
// integration scheme (internal).
//
// A scheme owns what differs between integrators: how one step t -> t + dt
// composes the phases of the Simulation (TimeScheme::step), which dt is
// stable for it (its stable-step rule) and which user dt it refuses (its
// checks). The time loop (time_loop.hpp) sees only TimeScheme: one virtual
// call per step, never inside a particle or node loop. Problem-level rules
// that need no Simulation (the public stable_step() and check_problem())
// reach the scheme through SchemeRules.
//
// Schemes: explicit_scheme.hpp (forward Euler u-p, MUSL). A semi-implicit or
// quasi-static scheme is a peer file here with its own rules, added to
// scheme_rules() and to the instantiation in time_loop.hpp.
#pragma once

#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// One time step of a run, as the time loop calls it.
class TimeScheme {
 public:
  virtual ~TimeScheme() = default;
  /// The stable step of `problem` under this scheme, and the dt chosen.
  virtual StableStep stable_step(const Problem& problem) const = 0;
  /// Advances the simulation from t to t + dt; failures are recorded in the
  /// simulation (the loop reads them after the step).
  virtual void step(double t, double dt) = 0;
};

/// The rules of a scheme that need only the Problem.
struct SchemeRules {
  const char* name;
  /// Stable step and the dt the run will use (StableStep::chosen).
  StableStep (*stable_step)(const Problem& problem);
  /// Appends the issues that make `problem` unrunnable under the scheme
  /// (e.g. a user dt above its stable limit). `step` is stable_step(problem).
  void (*check)(const Problem& problem, const StableStep& step, std::vector<ProblemIssue>& issues);
};

/// The rules of the explicit scheme (schemes/explicit_rules.cpp).
const SchemeRules& explicit_scheme_rules();

/// The scheme `problem` runs with: today always the explicit one.
inline const SchemeRules& scheme_rules(const Problem&) {
  return explicit_scheme_rules();
}

}  // namespace hmpm
