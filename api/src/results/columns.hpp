// results/columns.hpp — what the result writers share: JSON strings (by
// nlohmann), component suffixes and column names, and the values of a
// Series by field, row, particle and component.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "hmpm/run.hpp"

namespace hmpm::api::results {

/// `text` as a JSON string, quotes included (nlohmann's escaping).
std::string json_string(const std::string& text);

inline const char* const vector_suffix[] = {"x", "y", "z"};
inline const char* const tensor_suffix[] = {"xx", "yy", "zz", "xy", "yz", "zx"};

/// The column names of a field ("pore_pressure", "effective_stress_xx", ...):
/// vectors always carry an axis suffix (also in 1D), scalars none.
std::vector<std::string> field_columns(Field field, int dimension);

/// Value of `field` (index f) for series particle p, row r, component c.
double series_value(const Series& s, std::size_t f, std::size_t r, std::size_t p, int nc, int c);

/// Appends field f of series particle p at row r as JSON: a number for a
/// scalar, an array of components for vectors and tensors (also with one
/// component, 1D); then, past 64 KiB, flushes `line` to `out`.
void append_series_value(std::string& line, std::ostream& out, const Series& s, std::size_t f,
                         std::size_t r, std::size_t p);

}  // namespace hmpm::api::results
