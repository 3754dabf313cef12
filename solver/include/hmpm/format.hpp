// format.hpp — numbers as text, one place for every formatter hmpm uses.
//
// Two families, kept apart because existing files and messages depend on
// each byte they produce:
//  - shortest round-trip text (std::to_chars): what the result files and the
//    job-spec messages write, so a number reads back exactly. Non-finite
//    values are "nan", "inf", "-inf", or `null` in JSON;
//  - a fixed number of significant digits (iostream's default notation,
//    like printf "%.*g"): what the solver's messages use ("1.732 times").
// Header-only, standard library only, so the solver can use it too.
#pragma once

#include <charconv>
#include <cmath>
#include <sstream>
#include <string>

namespace hmpm {

/// Appends the shortest text that reads back as `v` ("1e-05", "0.1", "3");
/// non-finite values as "nan", "inf" or "-inf".
inline void append_number(std::string& out, double v) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  if (std::isinf(v)) {
    out += v > 0 ? "inf" : "-inf";
    return;
  }
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

/// As append_number, but a non-finite value is JSON's `null`.
inline void append_json_number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  append_number(out, v);
}

/// The shortest round-trip text of `v` (see append_number).
inline std::string format_number(double v) {
  std::string out;
  append_number(out, v);
  return out;
}

/// `v` with at most `digits` significant digits in iostream's default
/// notation ("1.732", "2.2e+09", "inf"), as `std::ostream << v` after
/// `precision(digits)`.
inline std::string format_significant(double v, int digits) {
  std::ostringstream o;
  o.precision(digits);
  o << v;
  return o.str();
}

/// Four significant digits: the numbers of messages.
inline std::string format4(double v) {
  return format_significant(v, 4);
}

/// A positive bound printed to 4 significant digits without exceeding it
/// ("use dt <= X": X itself must pass the check): the value lowered by half
/// a unit in the 4th digit, then rounded, is at most v.
inline std::string format_upper_bound(double v) {
  return format_significant(v * (1 - 5e-4), 4);
}

/// The same for a lower bound ("at least X"): printed, it is at least v.
inline std::string format_lower_bound(double v) {
  return format_significant(v * (1 + 5e-4), 4);
}

}  // namespace hmpm
