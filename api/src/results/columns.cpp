// results/columns.cpp — see results/columns.hpp.
#include "results/columns.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "hmpm/format.hpp"

namespace hmpm::api::results {

std::string json_string(const std::string& text) {
  // Replaced, not thrown on: a message may quote bytes that are not UTF-8.
  return nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::vector<std::string> field_columns(Field field, int dimension) {
  std::vector<std::string> out;
  const FieldKind kind = field_info(field).kind;
  for (int c = 0; c < field_components(field, dimension); ++c) {
    std::string name = field_name(field);
    if (kind == FieldKind::tensor) name += std::string("_") + tensor_suffix[c];
    if (kind == FieldKind::vector) name += std::string("_") + vector_suffix[c];
    out.push_back(std::move(name));
  }
  return out;
}

double series_value(const Series& s, std::size_t f, std::size_t r, std::size_t p, int nc, int c) {
  const std::size_t np = s.particles.size();
  const std::size_t i = (r * np + p) * static_cast<std::size_t>(nc) + static_cast<std::size_t>(c);
  return i < s.values[f].size() ? s.values[f][i] : std::nan("");
}

void append_series_value(std::string& line, std::ostream& out, const Series& s, std::size_t f,
                         std::size_t r, std::size_t p) {
  const int nc = field_components(s.fields[f], s.dimension);
  const bool scalar = field_info(s.fields[f]).kind == FieldKind::scalar;
  if (!scalar) line += "[";
  for (int c = 0; c < nc; ++c) {
    if (c) line += ", ";
    append_json_number(line, series_value(s, f, r, p, nc, c));
  }
  if (!scalar) line += "]";
  if (line.size() > (1u << 16)) {
    out << line;
    line.clear();
  }
}

}  // namespace hmpm::api::results
