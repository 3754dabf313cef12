// results/reactions.cpp — reactions.json and reactions.csv (results/writers.hpp).
#include "results/writers.hpp"

#include <cmath>

#include "hmpm/format.hpp"
#include "results/columns.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;
using results::vector_suffix;

void write_reactions_json(const fs::path& path, const Reactions& r) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"time\": [";
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    if (k) line += ", ";
    append_json_number(line, r.time[k]);
  }
  line += "],\n \"boundaries\": [";
  out << line;
  const auto d = static_cast<std::size_t>(r.dimension);
  for (std::size_t b = 0; b < r.force.size(); ++b) {
    line = b ? ",\n  {" : "\n  {";
    line += "\"index\": " + std::to_string(b) + ", \"force\": [";
    for (std::size_t k = 0; k < r.time.size(); ++k) {
      line += k ? ", [" : "[";
      for (std::size_t a = 0; a < d; ++a) {
        if (a) line += ", ";
        const std::size_t i = k * d + a;
        append_json_number(line, i < r.force[b].size() ? r.force[b][i] : std::nan(""));
      }
      line += "]";
      if (line.size() > (1u << 16)) {
        out << line;
        line.clear();
      }
    }
    out << line << "]}";
  }
  out << "\n ]\n}\n";
  file.commit();
}

void write_reactions_csv(const fs::path& path, const Reactions& r) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  const auto d = static_cast<std::size_t>(r.dimension);
  std::string line = "time";
  for (std::size_t b = 0; b < r.force.size(); ++b)
    for (std::size_t a = 0; a < d; ++a)
      line += ",b" + std::to_string(b) + "_force_" + vector_suffix[a];
  out << line << '\n';
  for (std::size_t k = 0; k < r.time.size(); ++k) {
    line.clear();
    append_number(line, r.time[k]);
    for (const std::vector<double>& f : r.force)
      for (std::size_t a = 0; a < d; ++a) {
        line += ',';
        const std::size_t i = k * d + a;
        append_number(line, i < f.size() ? f[i] : std::nan(""));
      }
    out << line << '\n';
  }
  file.commit();
}

}  // namespace hmpm::api
