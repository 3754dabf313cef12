// stages.cpp — `stages`: a job as a sequence of stages (Problem::stages).
//
//   "stages": [{"name": "excavation", "end": 2.0,
//               "remove_bodies": [1], "add_bodies": [],
//               "boundaries": [...], "tractions": [...], "fluxes": [...],
//               "gravity": [...], "time": {...}, "local_damping": ...,
//               "body_materials": [{"body": 0, "material": "clay-mc"}]}, ...]
//
// The top level is the first stage (to time.end); each entry a later one,
// to its own `end` (absolute, after the stage before). What an entry sets
// replaces what was in force: a list replaces the whole list, `time` the
// whole time control (scheme, dt, courant, implicit: what it omits takes
// its default, not the stage before's). Lists are read by the top level's
// readers, so an entry's boundaries, tractions and fluxes take every form
// and check the top level's do. Body indices and the order of the ends are
// the solver's checks (check_problem).
#include <string>
#include <utility>
#include <vector>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view stage_allowed[] = {
    "name",   "end",     "add_bodies", "remove_bodies", "boundaries",         "tractions",
    "fluxes", "gravity", "time",       "local_damping", "reset_displacement", "body_materials"};
constexpr std::string_view stage_required[] = {"end"};
constexpr std::string_view body_material_keys[] = {"body", "material"};

/// Reads into `target` what `read` puts into the top level's `slot`,
/// leaving the top level as it was.
template <class T, class Read>
void read_into(T& slot, std::optional<T>& target, Read&& read) {
  T saved = std::move(slot);
  slot = T{};
  read();
  target = std::move(slot);
  slot = std::move(saved);
}

std::vector<int> read_body_list(ParseContext& c, const json& j, const std::string& path) {
  std::vector<int> out;
  if (!c.r.array(j, path, 1)) return out;
  for (std::size_t i = 0; i < j.size(); ++i)
    if (auto b = c.r.integer(j[i], child_pointer(path, i), 0, 65535))
      out.push_back(static_cast<int>(*b));
  return out;
}

// "body_materials": [{"body": index, "material": name}, ...]: a body's new
// material from the stage's start (the checks of body, density and pore
// water are the solver's: check_problem).
void read_body_materials(ParseContext& c, const json& j, const std::string& path, Stage& s) {
  if (!c.r.array(j, path, 1)) return;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string ip = child_pointer(path, i);
    const json& e = j[i];
    if (!c.r.object(e, ip, body_material_keys, body_material_keys)) continue;
    const auto body = c.r.integer(e["body"], ip + "/body", 0, 65535);
    const auto material = read_material_name(c, e["material"], ip + "/material");
    if (body && material) s.body_materials.push_back({static_cast<int>(*body), *material});
  }
}

void read_stage(ParseContext& c, const json& j, const std::string& path, Stage& s) {
  if (!c.r.object(j, path, stage_allowed, stage_required)) return;
  if (j.contains("name"))
    if (auto n = read_label(c, j["name"], path + "/name", 200, "a stage name")) s.name = *n;
  c.r.number_at(j, path, "end", Range::positive(), s.end);
  if (j.contains("add_bodies"))
    s.add_bodies = read_body_list(c, j["add_bodies"], path + "/add_bodies");
  if (j.contains("remove_bodies"))
    s.remove_bodies = read_body_list(c, j["remove_bodies"], path + "/remove_bodies");
  if (j.contains("body_materials"))
    read_body_materials(c, j["body_materials"], path + "/body_materials", s);
  if (j.contains("reset_displacement"))
    if (auto b = c.r.boolean(j["reset_displacement"], path + "/reset_displacement"))
      s.reset_displacement = *b;
  if (j.contains("gravity"))
    if (auto g = c.r.vector(j["gravity"], path + "/gravity", c.dim)) s.gravity = *g;
  if (j.contains("boundaries"))
    read_into(c.p.boundaries, s.boundaries,
              [&] { read_boundaries(c, j["boundaries"], path + "/boundaries"); });
  if (j.contains("tractions")) {
    std::vector<std::string> paths = std::move(c.traction_paths);
    read_into(c.p.tractions, s.tractions,
              [&] { read_tractions(c, j["tractions"], path + "/tractions"); });
    c.traction_paths = std::move(paths);
  }
  if (j.contains("fluxes")) {
    std::vector<std::string> paths = std::move(c.flux_paths);
    read_into(c.p.fluxes, s.fluxes, [&] { read_fluxes(c, j["fluxes"], path + "/fluxes"); });
    c.flux_paths = std::move(paths);
  }
  if (j.contains("local_damping")) {
    const bool formula = c.damping_formula;
    read_into(c.p.local_damping, s.local_damping,
              [&] { read_local_damping(c, j["local_damping"], path + "/local_damping"); });
    c.damping_formula = formula || c.damping_formula;
  }
  if (j.contains("time")) {
    const json& t = j["time"];
    if (t.is_object() && t.contains("end")) {
      c.r.error(path + "/time/end",
                "a stage's end is " + path + "/end (its time control has no end of its own)");
      return;
    }
    json with_end = t;
    if (with_end.is_object()) with_end["end"] = s.end > 0 ? s.end : 1.0;
    read_into(c.p.time, s.time, [&] { read_time(c, with_end, path + "/time"); });
  }
}

}  // namespace

void stage_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/stages/*", stage_allowed));
  out.push_back(keys_entry("/stages/*/body_materials/*", body_material_keys));
}

void read_stages(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path, 1)) return;
  if (j.size() > max_stages) {
    c.r.error(path, "has " + std::to_string(j.size()) + " stages; the limit is " +
                        std::to_string(max_stages) + " (merge stages, or split the job)");
    return;
  }
  for (std::size_t i = 0; i < j.size(); ++i) {
    Stage s;
    s.name = "stage " + std::to_string(i + 1);
    read_stage(c, j[i], child_pointer(path, i), s);
    c.p.stages.push_back(std::move(s));
  }
}

void check_stage_budget(ParseContext& c) {
  const Problem& p = c.p;
  if (p.stages.empty()) return;
  std::size_t items = p.materials.size() + p.bodies.size() + p.boundaries.size() +
                      p.tractions.size() + p.fluxes.size();
  for (const Stage& s : p.stages) {
    items += s.add_bodies.size() + s.remove_bodies.size();
    if (s.boundaries) items += s.boundaries->size();
    if (s.tractions) items += s.tractions->size();
    if (s.fluxes) items += s.fluxes->size();
  }
  if (p.stages.size() * items > max_stage_items_product) {
    c.r.error("/stages", "has " + std::to_string(p.stages.size()) + " stages in a problem of " +
                             std::to_string(items) +
                             " materials, bodies, boundaries, tractions and fluxes: each "
                             "stage is checked with the whole problem in force, so their product "
                             "is limited to " +
                             std::to_string(max_stage_items_product) +
                             " (merge stages, or split the job)");
  }
}

}  // namespace hmpm::api::parse
