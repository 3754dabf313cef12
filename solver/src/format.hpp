// format.hpp — the solver's one number formatter for messages (internal).
#pragma once

#include <sstream>
#include <string>

namespace hmpm {

/// `v` with `precision` significant digits, as std::ostream prints it
/// (e.g. 0.001, 1e+09): for failure reports, checks and warnings.
inline std::string format_number(double v, int precision) {
  std::ostringstream o;
  o.precision(precision);
  o << v;
  return o.str();
}

}  // namespace hmpm
