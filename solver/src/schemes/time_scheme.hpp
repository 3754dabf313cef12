// schemes/time_scheme.hpp — the seam between the time loop and a time
// integration scheme (internal).
//
// A scheme owns what differs between integrators: how one step t -> t + dt
// composes the phases of the Simulation (TimeScheme::step), which dt is
// stable for it (its stable-step rule), how long each step is when it picks
// them (next_dt), which user input it refuses (its checks) and the
// iteration counts it reports. The time loop (time_loop.hpp) sees only
// TimeScheme: a few virtual calls per step, never inside a particle or node
// loop. Problem-level rules that need no Simulation (the public
// stable_step() and check_problem()) reach the scheme through SchemeRules.
//
// Schemes, one peer file each with its rules beside it:
//   explicit_scheme.hpp      + explicit_rules.cpp       forward Euler u-p, MUSL
//   semi_implicit_scheme.hpp + semi_implicit_rules.cpp  explicit momentum, implicit pressure
//   quasi_static_scheme.hpp  + quasi_static_rules.cpp   implicit u-p without inertia
// A new scheme adds its enum value (hmpm::Scheme, problem.hpp) and its row
// in the table of schemes (schemes/table.hpp: name, rules, constructor, what
// it reports).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "checkpoint.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

/// One time step of a run, as the time loop calls it.
class TimeScheme {
 public:
  virtual ~TimeScheme() = default;
  /// The stable step of `problem` under this scheme, and the dt chosen.
  virtual StableStep stable_step(const Problem& problem) const = 0;
  /// Length of the step that starts at t, for schemes whose steps vary
  /// (StableStep::fixed false); the loop shortens it to end at time.end.
  /// Fixed-step schemes are never asked.
  virtual double next_dt(double /*t*/) { return 0.0; }
  /// Advances the simulation from t to t + dt; failures are recorded in the
  /// simulation (the loop reads them after the step).
  virtual void step(double t, double dt) = 0;
  /// Adds the scheme's counters (iterations, cut-backs) to the result.
  virtual void report(RunResult& /*result*/) const {}
  /// Writes the state the scheme carries from one step to the next (between
  /// steps; checkpoint.hpp), and reads it back into a fresh scheme.
  virtual void save(checkpoint::Writer& /*w*/) const {}
  virtual void load(checkpoint::Reader& /*r*/) {}
};

/// The rules of a scheme that need only the Problem.
struct SchemeRules {
  /// Stable step and the dt the run will use (StableStep::chosen).
  StableStep (*stable_step)(const Problem& problem);
  /// Appends the issues that make `problem` unrunnable under the scheme
  /// (e.g. a user dt above its stable limit). `step` is stable_step(problem).
  void (*check)(const Problem& problem, const StableStep& step, std::vector<ProblemIssue>& issues);
};

/// The rules of the explicit scheme (schemes/explicit_rules.cpp).
const SchemeRules& explicit_scheme_rules();
/// The rules of the semi-implicit scheme (schemes/semi_implicit_rules.cpp).
const SchemeRules& semi_implicit_scheme_rules();
/// The rules of the quasi-static scheme (schemes/quasi_static_rules.cpp).
const SchemeRules& quasi_static_scheme_rules();

/// Per material of `problem`: some body of it has particles (only those
/// limit a stable step); every material when none has (explicit_rules.cpp).
std::vector<bool> materials_with_particles(const Problem& problem);

/// The rules of the scheme `problem` runs with (problem.time.scheme; schemes/table.cpp).
const SchemeRules& scheme_rules(const Problem& problem);

/// Steps of length dt to reach `end`, the last one shortened to end there.
inline std::int64_t fixed_step_count(double end, double dt) {
  if (!(dt > 0) || !(end > 0)) return 1;
  const double n = std::ceil(end / dt - 1e-9);
  return n < 1 ? 1 : (n > 9.0e18 ? INT64_MAX : static_cast<std::int64_t>(n));
}

}  // namespace hmpm
