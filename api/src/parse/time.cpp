// time.cpp — the "time" section (end time, time step, Courant factor) and
// "local_damping", a number or a function of time.
#include "expression.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view time_allowed[] = {"end", "dt", "courant"};
constexpr std::string_view time_required[] = {"end"};

}  // namespace

void time_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/time", time_allowed));
}

void read_time(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, time_allowed, time_required)) return;
  c.r.number_at(j, path, "end", Range::positive(), c.p.time.end);
  c.r.number_at(j, path, "dt", Range::positive(), c.p.time.dt);
  c.r.number_at(j, path, "courant", {0.0, 1.0, true, false}, c.p.time.courant);
}

void read_local_damping(ParseContext& c, const json& j, const std::string& path) {
  // A number is checked here; a formula of t is checked over [0, end] by
  // checks.cpp and each step by the solver (a value outside [0, 1) fails
  // the run at that step).
  if (j.is_number()) {
    if (auto v = c.r.number(j, path, {0.0, 1.0, false, true}))
      c.p.local_damping = constant_field_of_time(*v);
  } else if (auto f = read_value_of_time(c, j, path)) {
    c.p.local_damping = *f;
    c.damping_formula = true;
  }
}

}  // namespace hmpm::api::parse
