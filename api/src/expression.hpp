// expression.hpp — numbers and formulas in a job spec, compiled once.
//
// A spec value may be a plain number or a formula string: initial fields are
// functions of the particle's initial position (x, y, z), boundary values and
// loads functions of time (t). Formulas are compiled with muParser at parse
// time, so a bad one is reported as a validation error and never reaches the
// solver. A plain number (or a formula without variables) becomes a constant
// function that never touches muParser.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "hmpm/problem.hpp"

namespace hmpm::api {

/// What a formula may refer to, for messages.
inline constexpr std::string_view expression_help =
    "constant pi; operators + - * / ^; functions sin cos tan exp log (natural) sqrt abs min max";

/// Compiles `text` as a function of x, y, z. On failure returns nullopt and
/// sets `error` to what is wrong (muParser's message and position).
std::optional<FieldOfPosition> compile_field_of_position(std::string_view text, std::string& error);

/// Compiles `text` as a function of t. Same contract as above.
std::optional<FieldOfTime> compile_field_of_time(std::string_view text, std::string& error);

/// Compiles `text` as a function of x, y, z and t; `varies_in_space` says
/// whether it uses x, y or z. Same contract as above.
std::optional<FieldOfSpaceTime> compile_field_of_space_time(std::string_view text,
                                                            std::string& error,
                                                            bool& varies_in_space);

/// Constant functions (no muParser involved).
FieldOfPosition constant_field_of_position(double value);
FieldOfTime constant_field_of_time(double value);
FieldOfSpaceTime constant_field_of_space_time(double value);

}  // namespace hmpm::api
