// results/consolidation.cpp — consolidation.json and .csv (results/writers.hpp).
#include "results/writers.hpp"

#include <cmath>

#include "hmpm/format.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;

namespace {
double average_excess(const RunResult::Consolidation& c, std::size_t k) {
  return k < c.volume.size() && c.volume[k] > 0 ? c.excess[k] / c.volume[k] : std::nan("");
}
}  // namespace

void write_consolidation_json(const fs::path& path, const RunResult::Consolidation& c,
                              double from) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  std::string line = "{\"from\": ";
  append_json_number(line, from);
  line += ", \"t50\": ";
  append_json_number(line, c.t50);
  line += ", \"t90\": ";
  append_json_number(line, c.t90);
  auto column = [&](const char* name, auto value) {
    line += ",\n \"";
    line += name;
    line += "\": [";
    for (std::size_t k = 0; k < c.time.size(); ++k) {
      if (k) line += ", ";
      append_json_number(line, value(k));
    }
    line += "]";
    out << line;
    line.clear();
  };
  column("time", [&](std::size_t k) { return c.time[k]; });
  column("degree", [&](std::size_t k) { return k < c.degree.size() ? c.degree[k] : std::nan(""); });
  column("average_excess_pore_pressure", [&](std::size_t k) { return average_excess(c, k); });
  column("volume", [&](std::size_t k) { return k < c.volume.size() ? c.volume[k] : std::nan(""); });
  out << "\n}\n";
  file.commit();
}

void write_consolidation_csv(const fs::path& path, const RunResult::Consolidation& c) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "time,degree,average_excess_pore_pressure,volume\n";
  std::string line;
  for (std::size_t k = 0; k < c.time.size(); ++k) {
    line.clear();
    append_number(line, c.time[k]);
    line += ',';
    append_number(line, k < c.degree.size() ? c.degree[k] : std::nan(""));
    line += ',';
    append_number(line, average_excess(c, k));
    line += ',';
    append_number(line, k < c.volume.size() ? c.volume[k] : std::nan(""));
    out << line << '\n';
  }
  file.commit();
}

}  // namespace hmpm::api
