// time.cpp — the "time" section (end time, scheme, time step or step
// growth, Courant factor, implicit controls) and "local_damping", a number
// or a function of time.
#include <limits>

#include "expression.hpp"
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view time_allowed[] = {"end",     "scheme",   "dt",
                                             "courant", "implicit", "on_collapse"};
constexpr std::string_view time_required[] = {"end"};
constexpr std::string_view growth_allowed[] = {"initial", "max", "growth"};
constexpr std::string_view implicit_allowed[] = {"tolerance", "max_iterations", "max_cutbacks",
                                                 "linear_solver", "linear_tolerance"};
// In the order of hmpm::Scheme and hmpm::LinearSolver.
constexpr std::string_view schemes[] = {"explicit", "semi_implicit", "quasi_static"};
constexpr std::string_view linear_solvers[] = {"auto", "direct", "iterative"};
// In the order of hmpm::CollapseAction.
constexpr std::string_view collapse_actions[] = {"stop", "continue"};

constexpr double inf = std::numeric_limits<double>::infinity();

template <typename Enum>
std::optional<Enum> enum_of(std::string_view word, Keys names) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == word) return static_cast<Enum>(i);
  return std::nullopt;
}

void read_step_growth(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, growth_allowed, growth_allowed)) return;
  StepGrowth g;
  const bool initial_ok = c.r.number_at(j, path, "initial", Range::positive(), g.initial);
  const bool max_ok = c.r.number_at(j, path, "max", Range::positive(), g.max);
  const bool growth_ok = c.r.number_at(j, path, "growth", {1.0, inf, false, false}, g.growth);
  if (initial_ok && max_ok && g.max < g.initial) {
    c.r.error(path + "/max", "is " + format_number(g.max) + " s, below initial " +
                                 format_number(g.initial) + " s; max must be >= initial");
    return;
  }
  if (initial_ok && max_ok && growth_ok) c.p.time.growth = g;
}

void read_dt(ParseContext& c, const json& j, const std::string& path) {
  if (j.is_object()) {
    if (c.p.time.scheme != Scheme::quasi_static) {
      c.r.error(path, std::string("an object (step growth {\"initial\", \"max\", \"growth\"}) is "
                                  "accepted only with time.scheme 'quasi_static'; this run's "
                                  "scheme is '") +
                          scheme_name(c.p.time.scheme) +
                          "': give dt as a number of seconds, or set time.scheme to "
                          "'quasi_static'");
      return;
    }
    read_step_growth(c, j, path);
    return;
  }
  if (!j.is_number()) {
    c.r.error(path, std::string("expected a number of seconds > 0") +
                        (c.p.time.scheme == Scheme::quasi_static
                             ? " or an object {\"initial\", \"max\", \"growth\"}"
                             : "") +
                        ", got " + j.type_name());
    return;
  }
  if (auto v = c.r.number(j, path, Range::positive())) c.p.time.dt = *v;
}

void read_implicit(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, implicit_allowed)) return;
  ImplicitControl& ic = c.p.time.implicit;
  c.r.number_at(j, path, "tolerance", {0.0, 1.0, true, true}, ic.tolerance);
  if (j.contains("max_iterations"))
    if (auto v = c.r.integer(j["max_iterations"], path + "/max_iterations", 1, 1000))
      ic.max_iterations = static_cast<int>(*v);
  if (j.contains("max_cutbacks"))
    if (auto v = c.r.integer(j["max_cutbacks"], path + "/max_cutbacks", 0, 50))
      ic.max_cutbacks = static_cast<int>(*v);
  if (j.contains("linear_solver"))
    if (auto s = c.r.one_of(j["linear_solver"], path + "/linear_solver", linear_solvers))
      ic.linear_solver = *enum_of<LinearSolver>(*s, linear_solvers);
  c.r.number_at(j, path, "linear_tolerance", {0.0, 1.0, true, true}, ic.linear_tolerance);
  if (c.p.time.scheme == Scheme::explicit_scheme)
    c.warnings.push_back({path,
                          "is ignored by the explicit scheme (it has no iterations); set "
                          "time.scheme to 'semi_implicit' or 'quasi_static' to use it, or "
                          "remove it"});
}

}  // namespace

void time_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/time", time_allowed));
  out.push_back(keys_entry("/time/dt", growth_allowed));
  out.push_back(keys_entry("/time/implicit", implicit_allowed));
}

Keys scheme_names() {
  return schemes;
}
Keys linear_solver_names() {
  return linear_solvers;
}

void read_time(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, time_allowed, time_required)) return;
  // The scheme first: it decides what dt may be.
  if (j.contains("scheme"))
    if (auto s = c.r.one_of(j["scheme"], path + "/scheme", schemes))
      c.p.time.scheme = *enum_of<Scheme>(*s, schemes);
  c.r.number_at(j, path, "end", Range::positive(), c.p.time.end);
  if (j.contains("dt")) read_dt(c, j["dt"], path + "/dt");
  c.r.number_at(j, path, "courant", {0.0, 1.0, true, false}, c.p.time.courant);
  if (j.contains("implicit")) read_implicit(c, j["implicit"], path + "/implicit");
  if (j.contains("on_collapse"))
    if (auto s = c.r.one_of(j["on_collapse"], path + "/on_collapse", collapse_actions))
      c.p.time.on_collapse = *enum_of<CollapseAction>(*s, collapse_actions);
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
