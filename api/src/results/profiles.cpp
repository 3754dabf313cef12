// results/profiles.cpp — profiles.json and profiles.csv (results/writers.hpp).
#include "results/writers.hpp"

#include <algorithm>
#include <cmath>

#include "hmpm/format.hpp"
#include "results/columns.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;
using results::append_series_value;
using results::field_columns;
using results::json_string;
using results::series_value;

namespace {

void append_point(std::string& line, const Vec3& x, int dimension) {
  line += "[";
  for (int a = 0; a < dimension; ++a) {
    if (a) line += ", ";
    append_json_number(line, x[static_cast<std::size_t>(a)]);
  }
  line += "]";
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

void write_profiles_json(const fs::path& path, const std::vector<Series>& profiles,
                         const std::vector<ProfileGeometry>& geometry) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  const std::vector<double> no_times;
  const std::vector<double>& times = profiles.empty() ? no_times : profiles[0].time;
  for (std::size_t r = 0; r < times.size(); ++r) {
    if (r) line += ", ";
    append_json_number(line, times[r]);
  }
  line += "],\n \"profiles\": [";
  out << line;
  for (std::size_t l = 0; l < profiles.size() && l < geometry.size(); ++l) {
    const Series& s = profiles[l];
    const ProfileGeometry& g = geometry[l];
    line = l ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(l) + ", \"from\": ";
    append_point(line, g.from, s.dimension);
    line += ", \"to\": ";
    append_point(line, g.to, s.dimension);
    line += ",\n   \"points\": [";
    for (std::size_t k = 0; k < g.points.size(); ++k) {
      if (k) line += ", ";
      append_point(line, g.points[k], s.dimension);
    }
    line += "],\n   \"distance\": [";
    for (std::size_t k = 0; k < g.points.size(); ++k) {
      if (k) line += ", ";
      append_json_number(line, distance(g.points[k], g.from));
    }
    line += "],\n   \"particles\": [";
    for (std::size_t k = 0; k < s.particles.size(); ++k) {
      if (k) line += ", ";
      line += std::to_string(s.particles[k]);
    }
    line += "],\n   \"initial_positions\": [";
    for (std::size_t k = 0; k < s.initial_positions.size(); ++k) {
      if (k) line += ", ";
      append_point(line, s.initial_positions[k], s.dimension);
    }
    line += "]";
    out << line;
    for (std::size_t f = 0; f < s.fields.size() && f < s.values.size(); ++f) {
      line = ",\n   " + json_string(field_name(s.fields[f])) + ": [";
      for (std::size_t r = 0; r < s.time.size(); ++r) {
        line += r ? ",\n    [" : "\n    [";
        for (std::size_t k = 0; k < s.particles.size(); ++k) {
          if (k) line += ", ";
          append_series_value(line, out, s, f, r, k);
        }
        line += "]";
      }
      line += "]";
      out << line;
    }
    out << "}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

void write_profiles_csv(const fs::path& path, const std::vector<Series>& profiles,
                        const std::vector<ProfileGeometry>& geometry) {
  // One row per time, profile and point; the columns of every field any
  // profile has (empty where a profile does not have it).
  std::vector<Field> fields;
  int dimension = 1;
  for (const Series& s : profiles) {
    dimension = s.dimension;
    for (Field f : s.fields)
      if (std::find(fields.begin(), fields.end(), f) == fields.end()) fields.push_back(f);
  }
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "time,profile,point,distance";
  for (Field f : fields)
    for (const std::string& column : field_columns(f, dimension)) {
      line += ',';
      line += column;
    }
  out << line << '\n';
  const std::size_t rows = profiles.empty() ? 0 : profiles[0].time.size();
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t l = 0; l < profiles.size() && l < geometry.size(); ++l) {
      const Series& s = profiles[l];
      for (std::size_t k = 0; k < s.particles.size() && k < geometry[l].points.size(); ++k) {
        line.clear();
        append_number(line, r < s.time.size() ? s.time[r] : std::nan(""));
        // Piece by piece: GCC 12 warns (-Wstringop-overflow, a false
        // positive) on "literal" + std::string&& here, fatal under -Werror.
        line += ',';
        line += std::to_string(l);
        line += ',';
        line += std::to_string(k);
        line += ',';
        append_number(line, distance(geometry[l].points[k], geometry[l].from));
        for (Field f : fields) {
          const auto at = std::find(s.fields.begin(), s.fields.end(), f);
          const int nc = field_components(f, dimension);
          for (int c = 0; c < nc; ++c) {
            line += ',';
            if (at != s.fields.end())
              append_number(line, series_value(s, static_cast<std::size_t>(at - s.fields.begin()),
                                               r, k, nc, c));
          }
        }
        out << line << '\n';
      }
    }
  file.commit();
}

}  // namespace hmpm::api
