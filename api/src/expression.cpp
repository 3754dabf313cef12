// expression.cpp — muParser behind FieldOfPosition / FieldOfTime.
//
// A muParser object keeps raw pointers to the variables it was given, so the
// parser and its variables live together in one heap object shared by every
// copy of the std::function; a mutex makes concurrent calls safe (they are
// rare: once per particle at set-up, once per step for time functions).
#include "expression.hpp"

#include <muParser.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>

namespace hmpm::api {
namespace {

struct Compiled {
  mu::Parser parser;
  double x = 0.0, y = 0.0, z = 0.0, t = 0.0;
  std::mutex mutex;
};

// muParser accepts assignments ("x = 3") and lists ("1, 2"); neither makes
// sense for a field, so both are refused.
bool has_assignment(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '=') continue;
    const char before = i > 0 ? s[i - 1] : ' ';
    const char after = i + 1 < s.size() ? s[i + 1] : ' ';
    if (before != '<' && before != '>' && before != '!' && before != '=' && after != '=')
      return true;
  }
  return false;
}

// Compiles with the given variables defined; returns the compiled object and
// whether any variable is used. nullptr and `error` on failure.
// The variables a formula may use.
enum class Variables { position, time, position_and_time };

std::shared_ptr<Compiled> compile(std::string_view text, Variables vars, bool& uses_variables,
                                  std::string& error, bool* uses_position = nullptr) {
  auto c = std::make_shared<Compiled>();
  if (text.empty()) {
    error = "is an empty formula; give a number or a formula";
    return nullptr;
  }
  if (text.size() > 4096) {
    error = "formula is " + std::to_string(text.size()) + " characters; at most 4096";
    return nullptr;
  }
  if (has_assignment(text)) {
    error = "formula '" + std::string(text) + "' contains an assignment '='; use == to compare";
    return nullptr;
  }
  try {
    c->parser.DefineConst("pi", std::numbers::pi);
    if (vars != Variables::position) c->parser.DefineVar("t", &c->t);
    if (vars != Variables::time) {
      c->parser.DefineVar("x", &c->x);
      c->parser.DefineVar("y", &c->y);
      c->parser.DefineVar("z", &c->z);
    }
    c->parser.SetExpr(std::string(text));
    c->parser.Eval();  // parses now, so errors surface at validation time
    if (c->parser.GetNumResults() != 1) {
      error = "formula '" + std::string(text) + "' has " +
              std::to_string(c->parser.GetNumResults()) +
              " comma-separated results; exactly one expected";
      return nullptr;
    }
    const auto used = c->parser.GetUsedVar();
    uses_variables = !used.empty();
    if (uses_position)
      *uses_position = used.count("x") > 0 || used.count("y") > 0 || used.count("z") > 0;
  } catch (const mu::Parser::exception_type& e) {
    error = "bad formula '" + std::string(text) + "': " + e.GetMsg() + " (variables: " +
            (vars == Variables::time       ? "t"
             : vars == Variables::position ? "x, y, z"
                                           : "x, y, z, t") +
            "; " + std::string(expression_help) + ")";
    return nullptr;
  }
  return c;
}

double evaluate(Compiled& c) {
  try {
    return c.parser.Eval();
  } catch (...) {
    return std::nan("");
  }
}

}  // namespace

FieldOfPosition constant_field_of_position(double value) {
  return [value](const Vec3&) { return value; };
}

FieldOfTime constant_field_of_time(double value) {
  return [value](double) { return value; };
}

std::optional<FieldOfPosition> compile_field_of_position(std::string_view text,
                                                         std::string& error) {
  bool uses = false;
  auto c = compile(text, Variables::position, uses, error);
  if (!c) return std::nullopt;
  if (!uses) return constant_field_of_position(evaluate(*c));
  return FieldOfPosition([c](const Vec3& p) {
    std::lock_guard lock(c->mutex);
    c->x = p[0];
    c->y = p[1];
    c->z = p[2];
    return evaluate(*c);
  });
}

std::optional<FieldOfTime> compile_field_of_time(std::string_view text, std::string& error) {
  bool uses = false;
  auto c = compile(text, Variables::time, uses, error);
  if (!c) return std::nullopt;
  if (!uses) return constant_field_of_time(evaluate(*c));
  return FieldOfTime([c](double t) {
    std::lock_guard lock(c->mutex);
    c->t = t;
    return evaluate(*c);
  });
}

std::optional<FieldOfSpaceTime> compile_field_of_space_time(std::string_view text,
                                                            std::string& error,
                                                            bool& varies_in_space) {
  bool uses = false;
  varies_in_space = false;
  auto c = compile(text, Variables::position_and_time, uses, error, &varies_in_space);
  if (!c) return std::nullopt;
  if (!uses) return constant_field_of_space_time(evaluate(*c));
  return FieldOfSpaceTime([c](const Vec3& p, double t) {
    std::lock_guard lock(c->mutex);
    c->x = p[0];
    c->y = p[1];
    c->z = p[2];
    c->t = t;
    return evaluate(*c);
  });
}

FieldOfSpaceTime constant_field_of_space_time(double value) {
  return [value](const Vec3&, double) { return value; };
}

}  // namespace hmpm::api
