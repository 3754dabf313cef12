// job.cpp — parse_job: the top level of a job spec and the one pass over it.
//
// Reads the document's top-level keys (the table below) and hands each
// section to its reader; when the document has no error, runs the
// whole-problem checks, then builds the ParsedJob with its cost estimate
// and the solver's warnings. Nothing after parse_job looks anything up by
// string.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <utility>

#include "parser.hpp"

namespace hmpm::api {
namespace parse {
namespace {

constexpr std::string_view top_allowed[] = {
    "name",           "description",       "dimension",     "grid",
    "shape_function", "materials",         "bodies",        "gravity",
    "boundaries",     "tractions",         "time",          "output",
    "local_damping",  "gravity_constant",  "initial_state", "fluxes",
    "stages",         "strength_reduction"};
constexpr std::string_view top_required[] = {"dimension", "grid", "materials", "bodies", "time"};
// At most this many errors are reported (then one line counting the rest).
constexpr std::size_t max_errors = 1000;

}  // namespace

std::optional<std::pair<std::size_t, char32_t>> forbidden_in_name(std::string_view s) {
  std::size_t position = 0;
  for (std::size_t i = 0; i < s.size(); ++position) {
    const auto lead = static_cast<unsigned char>(s[i]);
    const int length = lead < 0x80 ? 1 : lead < 0xE0 ? 2 : lead < 0xF0 ? 3 : 4;
    char32_t cp = length == 1 ? lead : lead & (0x7F >> length);
    for (int k = 1; k < length && i + k < s.size(); ++k)
      cp = (cp << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
    i += static_cast<std::size_t>(length);
    const bool control = cp < 0x20 || (cp >= 0x7F && cp <= 0x9F);
    const bool bidi = cp == 0x061C || cp == 0x200E || cp == 0x200F ||
                      (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
    // Characters that show as nothing (or as a blank): zero-width spaces
    // and joiners, the soft hyphen, invisible operators, fillers, the byte
    // order mark, interlinear annotations, tag characters.
    const bool invisible = cp == 0x00AD || cp == 0x034F || cp == 0x115F || cp == 0x1160 ||
                           cp == 0x17B4 || cp == 0x17B5 || (cp >= 0x180B && cp <= 0x180F) ||
                           (cp >= 0x200B && cp <= 0x200D) || (cp >= 0x2060 && cp <= 0x2064) ||
                           (cp >= 0x206A && cp <= 0x206F) || cp == 0x3164 || cp == 0xFEFF ||
                           cp == 0xFFA0 || (cp >= 0xFFF9 && cp <= 0xFFFB) ||
                           (cp >= 0x1D173 && cp <= 0x1D17A) || (cp >= 0xE0000 && cp <= 0xE007F);
    if (control || bidi || invisible) return std::pair{position, cp};
  }
  return std::nullopt;
}

std::optional<std::string> read_label(ParseContext& c, const json& j, const std::string& path,
                                      std::size_t max_characters, const char* what) {
  auto s = c.r.string(j, path, max_characters);
  if (!s) return std::nullopt;
  if (const auto bad = forbidden_in_name(*s)) {
    char code[16];
    std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(bad->second));
    c.r.error(path, std::string("holds ") + code + " at character " +
                        std::to_string(bad->first + 1) + "; " + what +
                        " may not contain control characters (U+0000-U+001F, U+007F-U+009F), "
                        "bidirectional controls (U+061C, U+200E, U+200F, U+202A-U+202E, "
                        "U+2066-U+2069) or invisible characters (zero-width spaces and "
                        "joiners U+200B-U+200D, U+2060-U+2064, U+FEFF, the soft hyphen U+00AD, "
                        "fillers, tags): remove it");
    return std::nullopt;
  }
  return s;
}

namespace {

void read_name(ParseContext& c, const json& j) {
  if (auto s = read_label(c, j, "/name", 200, "a job name")) c.name = *s;
}

void read_root(ParseContext& c, const json& root) {
  SpecReader& r = c.r;
  if (!r.object(root, "", top_allowed, top_required)) return;
  if (root.contains("name")) read_name(c, root["name"]);
  if (root.contains("description")) r.string(root["description"], "/description", 100'000);
  if (root.contains("dimension"))
    if (auto d = r.integer(root["dimension"], "/dimension", 1, 3)) c.dim = static_cast<int>(*d);
  c.p.dimension = std::max(c.dim, 1);
  if (root.contains("grid")) read_grid(c, root["grid"], "/grid");
  if (root.contains("shape_function"))
    read_shape_function(c, root["shape_function"], "/shape_function");
  if (root.contains("materials")) read_materials(c, root["materials"], "/materials");
  if (root.contains("bodies")) read_bodies(c, root["bodies"], "/bodies");
  if (root.contains("gravity"))
    if (auto g = r.vector(root["gravity"], "/gravity", c.dim)) c.p.gravity = *g;
  if (root.contains("gravity_constant"))
    if (auto g = r.number(root["gravity_constant"], "/gravity_constant", Range::positive()))
      c.p.gravity_constant = *g;
  if (root.contains("local_damping"))
    read_local_damping(c, root["local_damping"], "/local_damping");
  if (root.contains("boundaries")) read_boundaries(c, root["boundaries"], "/boundaries");
  if (root.contains("tractions")) read_tractions(c, root["tractions"], "/tractions");
  if (root.contains("fluxes")) read_fluxes(c, root["fluxes"], "/fluxes");
  if (root.contains("time")) read_time(c, root["time"], "/time");
  if (root.contains("initial_state"))
    read_initial_state(c, root["initial_state"], "/initial_state");
  if (root.contains("output")) read_output(c, root["output"], "/output");
  if (root.contains("stages")) read_stages(c, root["stages"], "/stages");  // after the lists
  if (root.contains("strength_reduction"))
    read_strength_reduction(c, root["strength_reduction"], "/strength_reduction");

  if (c.any_pore_pressure_bc &&
      std::none_of(c.p.materials.begin(), c.p.materials.end(),
                   [](const Material& m) { return m.hydraulic.has_value(); }))
    r.error(c.first_pore_pressure_bc, "prescribes pore pressure but no material has 'hydraulic'");
}

ParseResult parse_text(std::string_view text, const Limits& limits,
                       const Calibration& calibration) {
  ParseResult result;
  if (text.size() > static_cast<std::size_t>(limits.max_body_bytes)) {
    result.errors.push_back({"", "spec is " + std::to_string(text.size()) +
                                     " bytes; the limit is " +
                                     std::to_string(limits.max_body_bytes) + " bytes"});
    return result;
  }
  json root;
  const TopArrayLimit stage_limit{"stages", max_stages, " (merge stages, or split the job)"};
  if (!parse_json_guarded(text, limits.max_json_depth, root, result.errors, stage_limit))
    return result;
  ParseContext c(limits, calibration);
  read_root(c, root);
  if (c.r.error_count() == 0) check_stage_budget(c);
  if (c.r.error_count() == 0) check_whole_problem(c);
  result.errors = std::move(c.r.errors());
  // A hostile spec can hold millions of mistakes; the first thousand say enough.
  if (result.errors.size() > max_errors) {
    const std::size_t more = result.errors.size() - max_errors;
    result.errors.resize(max_errors);
    result.errors.push_back({"", std::to_string(more) + " more errors not shown"});
  }
  if (result.errors.empty()) {
    ParsedJob job;
    job.name = c.name;
    job.profiles = std::move(c.profiles);
    job.cost = c.cost ? std::move(*c.cost) : estimate_cost(c.p, calibration);
    job.warnings = std::move(c.warnings);
    for (const ProblemIssue& w : problem_warnings(c.p))
      job.warnings.push_back({pointer_of_solver_location(w.where), w.message});
    job.problem = std::move(c.p);
    result.job = std::move(job);
  }
  return result;
}

}  // namespace

SpecObjectKeys keys_entry(std::string location, Keys keys) {
  return SpecObjectKeys{std::move(location), std::vector<std::string>(keys.begin(), keys.end())};
}

}  // namespace parse

const std::vector<SpecObjectKeys>& spec_object_keys() {
  static const std::vector<SpecObjectKeys> table = [] {
    std::vector<SpecObjectKeys> t{parse::keys_entry("", parse::top_allowed)};
    parse::grid_keys(t);
    parse::material_keys(t);
    parse::body_keys(t);
    parse::boundary_keys(t);
    parse::traction_keys(t);
    parse::flux_keys(t);
    parse::initial_state_keys(t);
    parse::time_keys(t);
    parse::strength_reduction_keys(t);
    parse::output_keys(t);
    parse::stage_keys(t);
    return t;
  }();
  return table;
}

ParseResult parse_job(std::string_view json_text, const Limits& limits,
                      const Calibration& calibration) {
  try {
    return parse::parse_text(json_text, limits, calibration);
  } catch (const std::exception& e) {
    ParseResult r;
    r.errors.push_back({"", std::string("internal error while reading the spec: ") + e.what()});
    return r;
  }
}

}  // namespace hmpm::api
