// output.cpp — the "output" section: the time series of chosen particles,
// the snapshots, with their fields (names from hmpm::field_table), and the
// boundaries' reaction forces.
#include <algorithm>
#include <limits>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view output_allowed[] = {"series", "snapshots", "reactions", "profiles",
                                               "consolidation"};
constexpr std::string_view profiles_allowed[] = {"interval", "times", "lines"};
constexpr std::string_view profiles_required[] = {"lines"};
constexpr std::string_view line_allowed[] = {"from", "to", "points", "fields"};
constexpr std::string_view series_allowed[] = {"particles", "fields", "interval"};
constexpr std::string_view series_required[] = {"particles", "fields"};
constexpr std::string_view near_allowed[] = {"near", "polygon"};
constexpr std::string_view snapshots_allowed[] = {"interval", "fields"};
constexpr std::string_view snapshots_required[] = {"interval"};
constexpr std::string_view reactions_allowed[] = {"interval"};
constexpr std::string_view reactions_required[] = {"interval"};
constexpr std::string_view consolidation_allowed[] = {"interval", "from", "steady_pore_pressure",
                                                      "particles"};
constexpr std::string_view consolidation_required[] = {"interval"};

std::vector<Field> read_fields(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  std::vector<Field> out;
  if (!r.array(j, path, 1)) return out;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string fp = child_pointer(path, i);
    auto name = r.one_of(j[i], fp, field_names());
    if (!name) continue;
    const Field f = std::find_if(field_table.begin(), field_table.end(), [&](const FieldInfo& e) {
                      return e.name == *name;
                    })->field;
    if (std::find(out.begin(), out.end(), f) != out.end()) {
      r.error(fp, "'" + *name + "' is listed twice");
      continue;
    }
    if (f == Field::excess_pore_pressure && c.excess_field_path.empty()) c.excess_field_path = fp;
    out.push_back(f);
  }
  return out;
}

void read_series_particles(ParseContext& c, const json& parts, const std::string& pp) {
  SpecReader& r = c.r;
  OutputRequest& out = c.p.output;
  if (!r.array(parts, pp, 1)) return;
  if (parts.size() > static_cast<std::size_t>(c.limits.max_series_particles)) {
    r.error(pp, "selects " + std::to_string(parts.size()) + " particles; the limit is " +
                    std::to_string(c.limits.max_series_particles));
    return;
  }
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string ip = child_pointer(pp, i);
    const json& e = parts[i];
    out.series_particles.push_back(-1);
    if (e.is_object()) {
      if (!r.object(e, ip, near_allowed)) continue;
      if (e.contains("near") == e.contains("polygon")) {
        r.error(ip, e.contains("near") ? "gives both 'near' and 'polygon'; give one"
                                       : "needs 'near' or 'polygon'");
      } else if (e.contains("near")) {
        if (auto at = r.vector(e["near"], ip + "/near", c.dim))
          c.near.push_back({out.series_particles.size() - 1, *at, ip});
      } else if (c.dim != 2) {
        r.error(ip + "/polygon",
                "selects in the (x, y) plane, which needs a 2D problem; this one "
                "is " +
                    std::to_string(c.dim) + "D: name particles or use 'near'");
      } else if (auto poly = read_polygon(c, e["polygon"], ip + "/polygon", {0, 1})) {
        c.series_polygons.push_back({out.series_particles.size() - 1, std::move(*poly), ip});
      }
    } else if (e.is_number()) {
      if (auto n = r.integer(e, ip, 0, std::numeric_limits<std::int64_t>::max()))
        out.series_particles.back() = *n;
    } else {
      r.error(ip, std::string("expected a particle index (integer >= 0), {\"near\": [x, ...]} or "
                              "{\"polygon\": [[x, y], ...]}, got ") +
                      e.type_name());
    }
  }
}

// output.profiles: {"interval", "times", "lines": [{"from", "to", "points",
// "fields"}]}. The particles nearest to each point are found with the whole
// problem (resolve_profiles in checks.cpp); the times are checked against
// the run's end and their order by check_problem.
void read_profiles(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  OutputRequest& out = c.p.output;
  if (!r.object(j, path, profiles_allowed, profiles_required)) return;
  r.number_at(j, path, "interval", Range::positive(), out.profile_interval);
  if (!j.contains("interval") && !j.contains("times"))
    r.error(path + "/interval", "is required (or give the listed 'times')");
  if (j.contains("times") && r.array(j["times"], path + "/times", 1)) {
    const json& times = j["times"];
    if (times.size() > static_cast<std::size_t>(c.limits.max_series_rows)) {
      r.error(path + "/times", "lists " + std::to_string(times.size()) +
                                   " times; the limit (that of the series) is " +
                                   std::to_string(c.limits.max_series_rows));
    } else {
      for (std::size_t i = 0; i < times.size(); ++i)
        if (auto t = r.number(times[i], child_pointer(path + "/times", i)))
          out.profile_times.push_back(*t);
    }
  }
  if (!j.contains("lines")) return;
  const json& lines = j["lines"];
  const std::string lp = path + "/lines";
  if (!r.array(lines, lp, 1)) return;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string ip = child_pointer(lp, i);
    const json& e = lines[i];
    if (!r.object(e, ip, line_allowed, line_allowed)) continue;
    ProfileGeometry g;
    ProfileLine line;
    const auto from = e.contains("from") ? r.vector(e["from"], ip + "/from", c.dim) : std::nullopt;
    const auto to = e.contains("to") ? r.vector(e["to"], ip + "/to", c.dim) : std::nullopt;
    std::int64_t points = 0;
    if (e.contains("points"))
      if (auto n = r.integer(e["points"], ip + "/points", 2, c.limits.max_series_particles))
        points = *n;
    if (e.contains("fields")) line.fields = read_fields(c, e["fields"], ip + "/fields");
    if (from && to && points >= 2) {
      g.from = *from;
      g.to = *to;
      for (std::int64_t k = 0; k < points; ++k) {
        const double s = static_cast<double>(k) / static_cast<double>(points - 1);
        Vec3 x{0, 0, 0};
        for (int a = 0; a < 3; ++a) x[a] = g.from[a] + s * (g.to[a] - g.from[a]);
        g.points.push_back(x);
      }
    }
    c.profiles.push_back(std::move(g));
    out.profiles.push_back(std::move(line));
  }
}

// output.consolidation: {"interval", "from", "steady_pore_pressure",
// "particles"}. Without steady_pore_pressure: the hydrostatic pressure
// under the geostatic state's water table when the job has one (gravity
// and the fluid density of the first material with pore water), else 0.
void read_consolidation(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  ConsolidationRequest& out = c.p.output.consolidation;
  if (!r.object(j, path, consolidation_allowed, consolidation_required)) return;
  r.number_at(j, path, "interval", Range::positive(), out.interval);
  r.number_at(j, path, "from", Range::non_negative(), out.from);
  if (j.contains("steady_pore_pressure"))
    out.steady_pore_pressure =
        read_value_of_position(c, j["steady_pore_pressure"], path + "/steady_pore_pressure");
  else
    c.consolidation_hydrostatic = true;  // resolved with the whole problem (checks.cpp)
  if (j.contains("particles")) {
    bool all = false;
    if (auto box = read_selection(c, j["particles"], path + "/particles", all, &out.polygon)) {
      out.particles = *box;
      out.all = all;
    }
  }
}

}  // namespace

Keys field_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> out;
    out.reserve(field_table.size());
    for (const FieldInfo& f : field_table) out.push_back(f.name);
    return out;
  }();
  return names;
}

void output_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/output", output_allowed));
  out.push_back(keys_entry("/output/series", series_allowed));
  out.push_back(keys_entry("/output/series/particles/*", near_allowed));
  out.push_back(keys_entry("/output/snapshots", snapshots_allowed));
  out.push_back(keys_entry("/output/reactions", reactions_allowed));
  out.push_back(keys_entry("/output/profiles", profiles_allowed));
  out.push_back(keys_entry("/output/profiles/lines/*", line_allowed));
  out.push_back(keys_entry("/output/consolidation", consolidation_allowed));
}

void read_output(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, output_allowed)) return;
  OutputRequest& out = c.p.output;
  if (j.contains("series")) {
    const json& s = j["series"];
    const std::string sp = path + "/series";
    if (r.object(s, sp, series_allowed, series_required)) {
      if (s.contains("particles")) read_series_particles(c, s["particles"], sp + "/particles");
      if (s.contains("fields")) out.series_fields = read_fields(c, s["fields"], sp + "/fields");
      r.number_at(s, sp, "interval", Range::non_negative(), out.series_interval);
    }
  }
  if (j.contains("snapshots")) {
    const json& s = j["snapshots"];
    const std::string sp = path + "/snapshots";
    if (r.object(s, sp, snapshots_allowed, snapshots_required)) {
      r.number_at(s, sp, "interval", Range::positive(), out.snapshot_interval);
      if (s.contains("fields")) {
        out.snapshot_fields = read_fields(c, s["fields"], sp + "/fields");
        // Points of the VTU files are the particle positions: always written.
        if (!out.snapshot_fields.empty() &&
            std::find(out.snapshot_fields.begin(), out.snapshot_fields.end(), Field::position) ==
                out.snapshot_fields.end())
          out.snapshot_fields.insert(out.snapshot_fields.begin(), Field::position);
      }
    }
  }
  if (j.contains("profiles")) read_profiles(c, j["profiles"], path + "/profiles");
  if (j.contains("consolidation"))
    read_consolidation(c, j["consolidation"], path + "/consolidation");
  if (j.contains("reactions")) {
    const json& s = j["reactions"];
    const std::string sp = path + "/reactions";
    if (r.object(s, sp, reactions_allowed, reactions_required))
      r.number_at(s, sp, "interval", Range::positive(), out.reactions_interval);
  }
}

}  // namespace hmpm::api::parse
