// results/series.cpp — series.json and series.csv (results/writers.hpp).
#include "results/writers.hpp"

#include <cmath>

#include "hmpm/format.hpp"
#include "results/columns.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;
using results::append_series_value;
using results::field_columns;
using results::json_string;
using results::series_value;

void write_series_json(const fs::path& path, const Series& s) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  for (std::size_t r = 0; r < s.time.size(); ++r) {
    if (r) line += ", ";
    append_json_number(line, s.time[r]);
  }
  line += "],\n \"particles\": [";
  out << line;
  const std::size_t rows = s.time.size();
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    line = p ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(s.particles[p]) + ", \"initial_position\": [";
    for (int a = 0; a < s.dimension; ++a) {
      if (a) line += ", ";
      append_json_number(line, p < s.initial_positions.size()
                                   ? s.initial_positions[p][static_cast<std::size_t>(a)]
                                   : std::nan(""));
    }
    line += "]";
    out << line;
    for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
      line = ",\n   ";
      line += json_string(field_name(s.fields[f]));
      line += ": [";
      for (std::size_t r = 0; r < rows; ++r) {
        if (r) line += ", ";
        append_series_value(line, out, s, f, r, p);
      }
      line += "]";
      out << line;
    }
    out << "}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

void write_series_csv(const fs::path& path, const Series& s) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "time";
  for (std::size_t p = 0; p < s.particles.size(); ++p) {
    for (const Field field : s.fields)
      for (const std::string& column : field_columns(field, s.dimension))
        line += ",p" + std::to_string(s.particles[p]) + "_" + column;
  }
  out << line << '\n';
  for (std::size_t r = 0; r < s.time.size(); ++r) {
    line.clear();
    append_number(line, s.time[r]);
    for (std::size_t p = 0; p < s.particles.size(); ++p)
      for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
        const int nc = field_components(s.fields[f], s.dimension);
        for (int c = 0; c < nc; ++c) {
          line += ',';
          append_number(line, series_value(s, f, r, p, nc, c));
        }
      }
    out << line << '\n';
  }
  file.commit();
}

}  // namespace hmpm::api
