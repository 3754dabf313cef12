// parse_job.cpp — the job spec walked once: JSON -> hmpm::Problem.
//
// One pass over the document records every problem with its JSON pointer
// (SpecReader), builds the Problem as it goes, and only then runs the
// checks that need the whole Problem: the solver's own check_problem, the
// particle and node selections, and the limits with the cost estimate.
// Nothing after parse_job looks anything up by string.
#include <algorithm>
#include <cmath>
#include <map>
#include <span>

#include "expression.hpp"
#include "hmpm/api/job.hpp"
#include "spec_reader.hpp"

namespace hmpm::api {
namespace {

using Keys = std::span<const std::string_view>;

// ---------------------------------------------------------------- key tables
// The accepted keys of every object; spec_object_keys() exposes them so the
// JSON Schema test can compare.
constexpr std::string_view kTop[] = {
    "name",          "description",      "dimension",    "grid",      "shape_function", "materials",
    "bodies",        "gravity",          "boundaries",   "tractions", "time",           "output",
    "local_damping", "gravity_constant", "initial_state"};
constexpr std::string_view kTopRequired[] = {"dimension", "grid", "materials", "bodies", "time"};
constexpr std::string_view kGrid[] = {"min", "max", "cells"};
constexpr std::string_view kMaterial[] = {"model",         "density",          "youngs_modulus",
                                          "poisson_ratio", "friction_angle",   "dilatancy_angle",
                                          "cohesion",      "tensile_strength", "hydraulic"};
constexpr std::string_view kMaterialRequired[] = {"model", "density", "youngs_modulus",
                                                  "poisson_ratio"};
constexpr std::string_view kPlasticKeys[] = {"friction_angle", "dilatancy_angle", "cohesion",
                                             "tensile_strength"};
constexpr std::string_view kHydraulic[] = {"porosity", "hydraulic_conductivity",
                                           "fluid_bulk_modulus", "fluid_density",
                                           "solid_bulk_modulus", "darcy_inertia"};
constexpr std::string_view kHydraulicRequired[] = {"porosity", "hydraulic_conductivity",
                                                   "fluid_bulk_modulus"};
constexpr std::string_view kBody[] = {"material", "box", "particles_per_cell", "initial"};
constexpr std::string_view kBodyRequired[] = {"material", "box"};
constexpr std::string_view kBox[] = {"min", "max"};
constexpr std::string_view kInitial[] = {"velocity", "pore_pressure", "effective_stress"};
constexpr std::string_view kBoundary[] = {"nodes", "velocity", "pore_pressure", "rigid",
                                          "friction"};
constexpr std::string_view kBoundaryRequired[] = {"nodes"};
constexpr std::string_view kSelection[] = {"box"};
constexpr std::string_view kTraction[] = {"particles", "face", "traction"};
constexpr std::string_view kInitialState[] = {"geostatic"};
constexpr std::string_view kGeostatic[] = {"water_table", "k0"};
constexpr std::string_view kTime[] = {"end", "dt", "courant"};
constexpr std::string_view kTimeRequired[] = {"end"};
constexpr std::string_view kOutput[] = {"series", "snapshots"};
constexpr std::string_view kSeries[] = {"particles", "fields", "interval"};
constexpr std::string_view kSeriesRequired[] = {"particles", "fields"};
constexpr std::string_view kNear[] = {"near"};
constexpr std::string_view kSnapshots[] = {"interval", "fields"};
constexpr std::string_view kSnapshotsRequired[] = {"interval"};

constexpr std::string_view kModels[] = {"linear_elastic", "mohr_coulomb", "drucker_prager"};
constexpr std::string_view kShapes[] = {"linear", "gimp", "bspline"};
constexpr std::string_view kFaces[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
constexpr std::string_view kFieldNames[] = {"position",      "displacement",   "velocity",
                                            "pore_pressure", "darcy_velocity", "effective_stress",
                                            "strain",        "porosity",       "total_stress"};
constexpr Field kFields[] = {Field::position,      Field::displacement,   Field::velocity,
                             Field::pore_pressure, Field::darcy_velocity, Field::effective_stress,
                             Field::strain,        Field::porosity,       Field::total_stress};
constexpr std::string_view kAxisNames[] = {"x", "y", "z"};
constexpr int kMaxParticlesPerCell = 10;
// At most this many errors are reported (then one line counting the rest).
constexpr std::size_t kMaxErrors = 1000;
// Work bound for laying out bodies (bodies x cells summed over the axes).
constexpr double kMaxLayoutWork = 5e7;
// Work bound for checks that visit every particle per selection.
constexpr double kMaxNearWork = 2e8;

std::string quoted_list(const std::vector<std::string>& words) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i) out += ", ";
    out += '\'';
    out += words[i];
    out += '\'';
  }
  return out;
}

std::int64_t to_count(double v) {
  if (!(v > 0)) return 0;
  if (v >= 9.2e18) return std::numeric_limits<std::int64_t>::max();
  return static_cast<std::int64_t>(v);
}

// Number of whole cells of `grid` along `axis` inside [lo, hi], with the
// tolerance the solver's particle layout uses.
std::int64_t cells_inside(const Grid& grid, int axis, double lo, double hi) {
  const double h = (grid.max[axis] - grid.min[axis]) / grid.cells[axis];
  const double tol = 1e-9 * h;
  const double first = std::ceil((lo - tol - grid.min[axis]) / h);
  const double last =
      std::floor((hi + tol - grid.min[axis]) / h);  // exclusive upper cell edge index
  const double a = std::max(first, 0.0);
  const double b = std::min(last, static_cast<double>(grid.cells[axis]));
  return b > a ? static_cast<std::int64_t>(b - a) : 0;
}

// Number of grid nodes along `axis` inside the closed interval [lo, hi].
std::int64_t nodes_inside(const Grid& grid, int axis, double lo, double hi) {
  const double h = (grid.max[axis] - grid.min[axis]) / grid.cells[axis];
  const double tol = 1e-9 * h;
  const double first = std::ceil((lo - tol - grid.min[axis]) / h);
  const double last = std::floor((hi + tol - grid.min[axis]) / h);
  const double a = std::max(first, 0.0);
  const double b = std::min(last, static_cast<double>(grid.cells[axis]));
  return b >= a ? static_cast<std::int64_t>(b - a) + 1 : 0;
}

// A formula (not a plain number) read from the spec, checked for finite
// values once the particles are known.
struct PositionFormula {
  std::size_t body;
  std::string path;
  FieldOfPosition f;
};
struct TimeFormula {
  std::string path;
  FieldOfTime f;
};

struct PendingNear {
  std::size_t slot;  // index into series_particles
  Vec3 at;
  std::string path;
};

class JobParser {
 public:
  explicit JobParser(const Limits& limits) : limits_(limits) {}

  ParseResult parse(std::string_view text);

 private:
  void parse_root(const json& root);
  void parse_grid(const json& j, const std::string& path);
  void parse_materials(const json& j, const std::string& path);
  void parse_material(const std::string& name, const json& j, const std::string& path);
  void parse_hydraulic(Material& m, const json& j, const std::string& path);
  void parse_body(const json& j, const std::string& path);
  void parse_initial(Body& body, const json& j, const std::string& path);
  void parse_boundary(const json& j, const std::string& path);
  void parse_traction(const json& j, const std::string& path);
  void parse_time(const json& j, const std::string& path);
  void parse_initial_state(const json& j, const std::string& path);
  void parse_output(const json& j, const std::string& path);
  std::vector<Field> parse_fields(const json& j, const std::string& path);
  std::optional<Box> parse_box(const json& j, const std::string& path);
  // {"box": {...}} or "all"; "all" is the whole grid.
  std::optional<Box> parse_selection(const json& j, const std::string& path, bool& all);
  FieldOfPosition position_value(const json& j, const std::string& path);
  std::optional<FieldOfTime> time_value(const json& j, const std::string& path);

  void check_whole_problem();
  bool check_particle_budget();
  void resolve_near();
  void check_traction_selections();
  void check_formulas_are_finite();
  void check_limits();
  std::string pointer_for(const std::string& where) const;

  const Limits& limits_;
  SpecReader r_;
  Problem p_;
  std::string name_ = "job";
  int dim_ = 0;           // 0 while unknown or invalid: vector lengths are not checked
  bool grid_ok_ = false;  // grid valid: boxes can be checked against it
  std::map<std::string, int> material_index_;
  std::vector<PendingNear> near_;
  std::vector<PositionFormula> position_formulas_;
  std::vector<TimeFormula> time_formulas_;
  bool damping_formula_ = false;  // local_damping given as a formula of t
  std::vector<std::string> traction_paths_;
  bool any_pore_pressure_bc_ = false;
  std::string first_pore_pressure_bc_;
};

ParseResult JobParser::parse(std::string_view text) {
  ParseResult result;
  if (text.size() > static_cast<std::size_t>(limits_.max_body_bytes)) {
    result.errors.push_back({"", "spec is " + std::to_string(text.size()) +
                                     " bytes; the limit is " +
                                     std::to_string(limits_.max_body_bytes) + " bytes"});
    return result;
  }
  json root;
  if (!parse_json_guarded(text, limits_.max_json_depth, root, result.errors)) return result;
  parse_root(root);
  if (r_.error_count() == 0) check_whole_problem();
  result.errors = std::move(r_.errors());
  // A hostile spec can hold millions of mistakes; the first thousand say enough.
  if (result.errors.size() > kMaxErrors) {
    const std::size_t more = result.errors.size() - kMaxErrors;
    result.errors.resize(kMaxErrors);
    result.errors.push_back({"", std::to_string(more) + " more errors not shown"});
  }
  if (result.errors.empty()) {
    ParsedJob job;
    job.name = name_;
    job.cost = estimate_cost(p_);
    for (const ProblemIssue& w : problem_warnings(p_))
      job.warnings.push_back({pointer_for(w.where), w.message});
    job.problem = std::move(p_);
    result.job = std::move(job);
  }
  return result;
}

void JobParser::parse_root(const json& root) {
  if (!r_.object(root, "", kTop, kTopRequired)) return;
  if (root.contains("name"))
    if (auto s = r_.string(root["name"], "/name", 200)) name_ = *s;
  if (root.contains("description")) r_.string(root["description"], "/description", 100'000);
  if (root.contains("dimension"))
    if (auto d = r_.integer(root["dimension"], "/dimension", 1, 3)) dim_ = static_cast<int>(*d);
  p_.dimension = std::max(dim_, 1);
  if (root.contains("grid")) parse_grid(root["grid"], "/grid");
  if (root.contains("shape_function")) {
    if (auto s = r_.one_of(root["shape_function"], "/shape_function", kShapes))
      p_.shape_function = *s == "gimp"      ? ShapeFunction::gimp
                          : *s == "bspline" ? ShapeFunction::bspline
                                            : ShapeFunction::linear;
  }
  if (root.contains("materials")) parse_materials(root["materials"], "/materials");
  if (root.contains("bodies")) {
    const json& b = root["bodies"];
    if (r_.array(b, "/bodies")) {
      if (b.empty()) r_.error("/bodies", "is empty; at least one body is needed");
      for (std::size_t i = 0; i < b.size(); ++i) parse_body(b[i], child_pointer("/bodies", i));
    }
  }
  if (root.contains("gravity"))
    if (auto g = r_.vector(root["gravity"], "/gravity", dim_)) p_.gravity = *g;
  if (root.contains("gravity_constant"))
    if (auto g = r_.number(root["gravity_constant"], "/gravity_constant", Range::positive()))
      p_.gravity_constant = *g;
  if (root.contains("local_damping")) {
    // A number is checked here; a formula of t is checked each step by the
    // solver (a value outside [0, 1) fails the run at that step).
    const json& d = root["local_damping"];
    if (d.is_number()) {
      if (auto v = r_.number(d, "/local_damping", {0.0, 1.0, false, true}))
        p_.local_damping = constant_field_of_time(*v);
    } else if (auto f = time_value(d, "/local_damping")) {
      p_.local_damping = *f;
      damping_formula_ = true;
    }
  }
  if (root.contains("boundaries")) {
    const json& b = root["boundaries"];
    if (r_.array(b, "/boundaries"))
      for (std::size_t i = 0; i < b.size(); ++i)
        parse_boundary(b[i], child_pointer("/boundaries", i));
  }
  if (root.contains("tractions")) {
    const json& t = root["tractions"];
    if (r_.array(t, "/tractions"))
      for (std::size_t i = 0; i < t.size(); ++i)
        parse_traction(t[i], child_pointer("/tractions", i));
  }
  if (root.contains("time")) parse_time(root["time"], "/time");
  if (root.contains("initial_state")) parse_initial_state(root["initial_state"], "/initial_state");
  if (root.contains("output")) parse_output(root["output"], "/output");

  if (any_pore_pressure_bc_ &&
      std::none_of(p_.materials.begin(), p_.materials.end(),
                   [](const Material& m) { return m.hydraulic.has_value(); }))
    r_.error(first_pore_pressure_bc_, "prescribes pore pressure but no material has 'hydraulic'");
}

void JobParser::parse_grid(const json& j, const std::string& path) {
  if (!r_.object(j, path, kGrid, kGrid)) return;
  const std::size_t before = r_.error_count();
  std::optional<Vec3> lo, hi;
  if (j.contains("min")) lo = r_.vector(j["min"], path + "/min", dim_);
  if (j.contains("max")) hi = r_.vector(j["max"], path + "/max", dim_);
  if (j.contains("cells")) {
    const json& c = j["cells"];
    const std::string cp = path + "/cells";
    if (r_.per_axis(c, cp, dim_, "integer number of cells")) {
      double total = 1.0;
      for (std::size_t a = 0; a < c.size() && a < 3; ++a) {
        if (auto n = r_.integer(c[a], child_pointer(cp, a), 1, limits_.max_cells)) {
          p_.grid.cells[a] = static_cast<int>(*n);
          total *= static_cast<double>(*n);
        }
      }
      if (total > static_cast<double>(limits_.max_cells))
        r_.error(cp, "grid has " + format_count(total) + " cells; the limit is " +
                         std::to_string(limits_.max_cells));
    }
  }
  if (lo && hi) {
    p_.grid.min = *lo;
    p_.grid.max = *hi;
    for (int a = 0; a < dim_; ++a)
      if (!(hi->at(a) > lo->at(a)))
        r_.error(child_pointer(path + "/max", a), "is " + format_number(hi->at(a)) +
                                                      "; must be greater than grid min " +
                                                      format_number(lo->at(a)));
  }
  grid_ok_ = dim_ > 0 && r_.error_count() == before;
}

void JobParser::parse_materials(const json& j, const std::string& path) {
  if (!j.is_object()) {
    r_.error(path, std::string("expected an object of named materials, got ") + j.type_name());
    return;
  }
  if (j.empty()) r_.error(path, "is empty; at least one material is needed");
  for (const auto& [name, value] : j.items())
    parse_material(name, value, child_pointer(path, name));
}

void JobParser::parse_material(const std::string& name, const json& j, const std::string& path) {
  Material m;
  m.name = name;
  if (name.empty() || name.size() > 100)
    r_.error(path, "material names must have 1 to 100 characters");
  if (r_.object(j, path, kMaterial, kMaterialRequired)) {
    r_.number_at(j, path, "density", Range::positive(), m.density);
    r_.number_at(j, path, "youngs_modulus", Range::positive(), m.youngs_modulus);
    if (j.contains("poisson_ratio")) {
      const json& v = j["poisson_ratio"];
      const std::string vp = path + "/poisson_ratio";
      if (v.is_number() && v.get<double>() == 0.5)
        r_.error(vp,
                 "is 0.5; must be in (-1, 0.5): an incompressible skeleton has an infinite "
                 "wave speed, so no explicit time step is stable");
      else if (auto nu = r_.number(v, vp, {-1.0, 0.5, true, true}))
        m.poisson_ratio = *nu;
    }
    std::string model = "linear_elastic";
    if (j.contains("model"))
      if (auto s = r_.one_of(j["model"], path + "/model", kModels)) model = *s;
    if (model == "linear_elastic") {
      for (std::string_view key : kPlasticKeys)
        if (j.contains(key))
          r_.error(
              child_pointer(path, key),
              "applies only to models 'mohr_coulomb' and 'drucker_prager', not 'linear_elastic'");
    } else {
      for (std::string_view key : {"friction_angle", "dilatancy_angle", "cohesion"})
        if (!j.contains(key))
          r_.error(child_pointer(path, key), "is required for model '" + model + "'");
      double phi = 30, psi = 0, c = 0, t = 0;
      const Range angle{0.0, 90.0, false, true};
      r_.number_at(j, path, "friction_angle", angle, phi);
      if (j.contains("dilatancy_angle")) {
        if (auto v = r_.number(j["dilatancy_angle"], path + "/dilatancy_angle", angle)) {
          psi = *v;
          if (psi > phi)
            r_.error(path + "/dilatancy_angle", "is " + format_number(psi) +
                                                    " degrees; must not exceed friction_angle " +
                                                    format_number(phi));
        }
      }
      if (j.contains("cohesion"))
        if (auto v = r_.number(j["cohesion"], path + "/cohesion", Range::non_negative())) {
          c = *v;
          if (c == 0 && phi == 0 && j.contains("friction_angle"))
            r_.error(path + "/cohesion",
                     "is 0 with friction_angle 0: the material would have no strength");
        }
      r_.number_at(j, path, "tensile_strength", Range::non_negative(), t);
      if (model == "mohr_coulomb")
        m.plasticity = MohrCoulomb{phi, psi, c, t};
      else
        m.plasticity = DruckerPrager{phi, psi, c, t};
    }
    if (j.contains("hydraulic")) parse_hydraulic(m, j["hydraulic"], path + "/hydraulic");
  }
  material_index_[name] = static_cast<int>(p_.materials.size());
  p_.materials.push_back(std::move(m));
}

void JobParser::parse_hydraulic(Material& m, const json& j, const std::string& path) {
  if (!r_.object(j, path, kHydraulic, kHydraulicRequired)) return;
  Hydraulic h;
  r_.number_at(j, path, "porosity", {0.0, 1.0, true, true}, h.porosity);
  if (j.contains("hydraulic_conductivity"))
    if (auto v = r_.number(j["hydraulic_conductivity"], path + "/hydraulic_conductivity",
                           Range::non_negative()))
      h.hydraulic_conductivity = *v;
  r_.number_at(j, path, "fluid_bulk_modulus", Range::positive(), h.fluid_bulk_modulus);
  r_.number_at(j, path, "fluid_density", Range::positive(), h.fluid_density);
  r_.number_at(j, path, "solid_bulk_modulus", Range::positive(), h.solid_bulk_modulus);
  if (j.contains("darcy_inertia"))
    if (auto v = r_.boolean(j["darcy_inertia"], path + "/darcy_inertia")) h.darcy_inertia = *v;
  m.hydraulic = h;
}

std::optional<Box> JobParser::parse_box(const json& j, const std::string& path) {
  if (!r_.object(j, path, kBox, kBox)) return std::nullopt;
  std::optional<Vec3> lo, hi;
  if (j.contains("min")) lo = r_.vector(j["min"], path + "/min", dim_);
  if (j.contains("max")) hi = r_.vector(j["max"], path + "/max", dim_);
  if (!lo || !hi) return std::nullopt;
  bool ok = true;
  for (int a = 0; a < dim_; ++a) {
    if ((*hi)[a] < (*lo)[a]) {
      r_.error(child_pointer(path + "/max", a),
               "is " + format_number((*hi)[a]) + "; must be >= min " + format_number((*lo)[a]));
      ok = false;
      continue;
    }
    if (!grid_ok_) continue;
    const double tol = 1e-9 * (p_.grid.max[a] - p_.grid.min[a]);
    const std::string range = "; the grid spans [" + format_number(p_.grid.min[a]) + ", " +
                              format_number(p_.grid.max[a]) + "] along " +
                              std::string(kAxisNames[a]);
    if ((*lo)[a] < p_.grid.min[a] - tol || (*lo)[a] > p_.grid.max[a] + tol) {
      r_.error(child_pointer(path + "/min", a),
               "is " + format_number((*lo)[a]) + ", outside the grid" + range);
      ok = false;
    }
    if ((*hi)[a] > p_.grid.max[a] + tol || (*hi)[a] < p_.grid.min[a] - tol) {
      r_.error(child_pointer(path + "/max", a),
               "is " + format_number((*hi)[a]) + ", outside the grid" + range);
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return Box{*lo, *hi};
}

std::optional<Box> JobParser::parse_selection(const json& j, const std::string& path, bool& all) {
  all = false;
  if (j.is_string()) {
    if (j.get_ref<const std::string&>() == "all") {
      all = true;
      return Box{p_.grid.min, p_.grid.max};
    }
    r_.error(path,
             "expected \"all\" or {\"box\": {\"min\": [...], \"max\": [...]}}, got the string '" +
                 j.get_ref<const std::string&>().substr(0, 64) + "'");
    return std::nullopt;
  }
  if (!j.is_object()) {
    r_.error(path,
             std::string("expected \"all\" or {\"box\": {\"min\": [...], \"max\": [...]}}, got ") +
                 j.type_name());
    return std::nullopt;
  }
  if (!r_.object(j, path, kSelection, kSelection) || !j.contains("box")) return std::nullopt;
  return parse_box(j["box"], path + "/box");
}

FieldOfPosition JobParser::position_value(const json& j, const std::string& path) {
  if (j.is_string()) {
    std::string error;
    if (auto f = compile_field_of_position(j.get_ref<const std::string&>(), error)) {
      position_formulas_.push_back({p_.bodies.size(), path, *f});
      return *f;
    }
    r_.error(path, error);
    return {};
  }
  if (!j.is_number()) {
    r_.error(path,
             std::string("expected a number or a formula string in x, y, z, got ") + j.type_name());
    return {};
  }
  if (auto v = r_.number(j, path)) return constant_field_of_position(*v);
  return {};
}

std::optional<FieldOfTime> JobParser::time_value(const json& j, const std::string& path) {
  if (j.is_string()) {
    std::string error;
    if (auto f = compile_field_of_time(j.get_ref<const std::string&>(), error)) {
      time_formulas_.push_back({path, *f});
      return f;
    }
    r_.error(path, error);
    return std::nullopt;
  }
  if (!j.is_number()) {
    r_.error(path, std::string("expected a number or a formula string in t, got ") + j.type_name());
    return std::nullopt;
  }
  if (auto v = r_.number(j, path)) return constant_field_of_time(*v);
  return std::nullopt;
}

void JobParser::parse_body(const json& j, const std::string& path) {
  Body body;
  body.material = -1;
  if (!r_.object(j, path, kBody, kBodyRequired)) return;
  if (j.contains("material")) {
    if (auto name = r_.string(j["material"], path + "/material", 100)) {
      if (auto it = material_index_.find(*name); it != material_index_.end()) {
        body.material = it->second;
      } else {
        std::vector<std::string> names;
        for (const auto& [n, i] : material_index_) names.push_back(n);
        r_.error(path + "/material",
                 "unknown material '" + *name + "'; defined materials: " +
                     (names.empty() ? std::string("none") : quoted_list(names)));
      }
    }
  }
  if (j.contains("box"))
    if (auto b = parse_box(j["box"], path + "/box")) body.box = *b;
  if (j.contains("particles_per_cell"))
    if (auto n = r_.integer(j["particles_per_cell"], path + "/particles_per_cell", 1,
                            kMaxParticlesPerCell))
      body.particles_per_cell = static_cast<int>(*n);
  if (j.contains("initial")) parse_initial(body, j["initial"], path + "/initial");
  p_.bodies.push_back(std::move(body));
}

void JobParser::parse_initial(Body& body, const json& j, const std::string& path) {
  if (!r_.object(j, path, kInitial)) return;
  if (j.contains("velocity")) {
    const json& v = j["velocity"];
    const std::string vp = path + "/velocity";
    if (r_.per_axis(v, vp, dim_, "number or formula")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a)
        body.initial.velocity[a] = position_value(v[a], child_pointer(vp, a));
    }
  }
  if (j.contains("pore_pressure")) {
    body.initial.pore_pressure = position_value(j["pore_pressure"], path + "/pore_pressure");
    if (body.material >= 0 && !p_.materials[static_cast<std::size_t>(body.material)].hydraulic)
      r_.error(path + "/pore_pressure",
               "is given but material '" +
                   p_.materials[static_cast<std::size_t>(body.material)].name +
                   "' has no 'hydraulic' properties");
  }
  if (j.contains("effective_stress")) {
    const json& s = j["effective_stress"];
    const std::string sp = path + "/effective_stress";
    if (!s.is_array() || s.size() != 6) {
      r_.error(
          sp,
          "expected an array of 6 numbers or formulas (Voigt order xx, yy, zz, xy, yz, zx), got " +
              (s.is_array() ? std::to_string(s.size()) + " entries" : std::string(s.type_name())));
    } else {
      for (std::size_t k = 0; k < 6; ++k)
        body.initial.effective_stress[k] = position_value(s[k], child_pointer(sp, k));
    }
  }
}

void JobParser::parse_boundary(const json& j, const std::string& path) {
  if (!r_.object(j, path, kBoundary, kBoundaryRequired)) return;
  Boundary b;
  if (j.contains("nodes")) {
    bool all = false;
    const std::string np = path + "/nodes";
    if (auto box = parse_selection(j["nodes"], np, all)) {
      b.nodes.all = all;
      b.nodes.box = *box;
      if (!all && grid_ok_) {
        double count = 1;
        for (int a = 0; a < dim_; ++a)
          count *= static_cast<double>(nodes_inside(p_.grid, a, box->min[a], box->max[a]));
        if (count == 0)
          r_.error(np + "/box", "selects no grid node; nodes lie at min + i * cell size");
      }
    }
  }
  if (!j.contains("velocity") && !j.contains("pore_pressure") && !j.contains("rigid"))
    r_.error(path, "needs 'velocity', 'pore_pressure' and/or 'rigid'");
  if (j.contains("velocity")) {
    const json& v = j["velocity"];
    const std::string vp = path + "/velocity";
    if (r_.per_axis(v, vp, dim_, "number, formula in t or null")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        if (v[a].is_null()) continue;
        if (auto f = time_value(v[a], child_pointer(vp, a))) {
          b.velocity[a] = std::move(*f);
          b.has_velocity = true;
        }
      }
    }
  }
  if (j.contains("rigid")) {
    const json& v = j["rigid"];
    const std::string vp = path + "/rigid";
    if (r_.per_axis(v, vp, dim_, "true or false")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        const std::string ap = child_pointer(vp, a);
        const auto tied = r_.boolean(v[a], ap);
        if (!tied) continue;
        b.rigid[a] = *tied;
        if (b.rigid[a] && b.velocity[a])
          r_.error(ap, "is true but velocity/" + std::to_string(a) +
                           " prescribes that component; a rigid tie needs it free");
      }
    }
  }
  if (j.contains("friction")) {
    // A Coulomb coefficient, or "rough" for no slip; which component is the
    // wall normal (exactly one prescribed) is checked by check_problem.
    const json& f = j["friction"];
    const std::string fp = path + "/friction";
    if (f.is_string()) {
      if (f.get<std::string>() == "rough")
        b.friction = std::numeric_limits<double>::infinity();
      else
        r_.error(fp, "expected a number >= 0 (Coulomb coefficient) or \"rough\" (no slip), got \"" +
                         f.get<std::string>() + "\"");
    } else if (auto mu = r_.number(f, fp, Range::non_negative())) {
      b.friction = *mu;
    }
    if (!j.contains("velocity"))
      r_.error(fp,
               "needs 'velocity' with the wall-normal component prescribed and the others null");
  }
  if (j.contains("pore_pressure")) {
    b.pore_pressure = time_value(j["pore_pressure"], path + "/pore_pressure");
    if (!any_pore_pressure_bc_) first_pore_pressure_bc_ = path + "/pore_pressure";
    any_pore_pressure_bc_ = true;
  }
  p_.boundaries.push_back(std::move(b));
}

void JobParser::parse_traction(const json& j, const std::string& path) {
  if (!r_.object(j, path, kTraction, kTraction)) return;
  Traction t;
  if (j.contains("particles")) {
    bool all = false;
    if (auto box = parse_selection(j["particles"], path + "/particles", all)) t.particles = *box;
  }
  if (j.contains("face")) {
    if (auto f = r_.one_of(j["face"], path + "/face", kFaces)) {
      t.axis = (*f)[0] - 'x';
      t.side = (*f)[1] == '+' ? +1 : -1;
      if (dim_ > 0 && t.axis >= dim_)
        r_.error(path + "/face", "is '" + *f + "', but a " + std::to_string(dim_) +
                                     "D problem has no " + std::string(kAxisNames[t.axis]) +
                                     " axis");
    }
  }
  if (j.contains("traction")) {
    const json& v = j["traction"];
    const std::string vp = path + "/traction";
    if (r_.per_axis(v, vp, dim_, "number or formula in t")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a)
        if (auto f = time_value(v[a], child_pointer(vp, a))) t.traction[a] = std::move(*f);
    }
  }
  traction_paths_.push_back(path + "/particles");
  p_.tractions.push_back(std::move(t));
}

void JobParser::parse_time(const json& j, const std::string& path) {
  if (!r_.object(j, path, kTime, kTimeRequired)) return;
  r_.number_at(j, path, "end", Range::positive(), p_.time.end);
  r_.number_at(j, path, "dt", Range::positive(), p_.time.dt);
  r_.number_at(j, path, "courant", {0.0, 1.0, true, false}, p_.time.courant);
}

void JobParser::parse_initial_state(const json& j, const std::string& path) {
  if (!r_.object(j, path, kInitialState)) return;
  if (!j.contains("geostatic")) return;
  const json& g = j["geostatic"];
  const std::string gp = path + "/geostatic";
  if (!r_.object(g, gp, kGeostatic)) return;
  Geostatic geo;
  r_.number_at(g, gp, "water_table", Range::any(), geo.water_table);
  if (g.contains("k0")) {
    const json& k = g["k0"];
    const std::string kp = gp + "/k0";
    if (k.is_object()) {
      geo.material_k0.resize(p_.materials.size());
      for (const auto& [name, value] : k.items()) {
        const std::string mp = child_pointer(kp, name);
        const auto it = material_index_.find(name);
        if (it == material_index_.end()) {
          r_.error(mp, "names no material");
          continue;
        }
        if (auto v = r_.number(value, mp, Range::non_negative()))
          geo.material_k0[static_cast<std::size_t>(it->second)] = *v;
      }
    } else if (k.is_number()) {
      if (auto v = r_.number(k, kp, Range::non_negative())) geo.k0 = *v;
    } else {
      r_.error(kp, std::string("expected a number >= 0 or an object of material name -> number, "
                               "got ") +
                       k.type_name());
    }
  }
  p_.initial_state.geostatic = std::move(geo);
}

std::vector<Field> JobParser::parse_fields(const json& j, const std::string& path) {
  std::vector<Field> out;
  if (!r_.array(j, path, 1)) return out;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string fp = child_pointer(path, i);
    auto name = r_.one_of(j[i], fp, kFieldNames);
    if (!name) continue;
    const auto k = static_cast<std::size_t>(
        std::find(std::begin(kFieldNames), std::end(kFieldNames), *name) - std::begin(kFieldNames));
    if (std::find(out.begin(), out.end(), kFields[k]) != out.end()) {
      r_.error(fp, "'" + *name + "' is listed twice");
      continue;
    }
    out.push_back(kFields[k]);
  }
  return out;
}

void JobParser::parse_output(const json& j, const std::string& path) {
  if (!r_.object(j, path, kOutput)) return;
  OutputRequest& out = p_.output;
  if (j.contains("series")) {
    const json& s = j["series"];
    const std::string sp = path + "/series";
    if (r_.object(s, sp, kSeries, kSeriesRequired)) {
      if (s.contains("particles")) {
        const json& parts = s["particles"];
        const std::string pp = sp + "/particles";
        if (r_.array(parts, pp, 1)) {
          if (parts.size() > static_cast<std::size_t>(limits_.max_series_particles))
            r_.error(pp, "selects " + std::to_string(parts.size()) + " particles; the limit is " +
                             std::to_string(limits_.max_series_particles));
          else
            for (std::size_t i = 0; i < parts.size(); ++i) {
              const std::string ip = child_pointer(pp, i);
              const json& e = parts[i];
              out.series_particles.push_back(-1);
              if (e.is_object()) {
                if (r_.object(e, ip, kNear, kNear) && e.contains("near"))
                  if (auto at = r_.vector(e["near"], ip + "/near", dim_))
                    near_.push_back({out.series_particles.size() - 1, *at, ip});
              } else if (e.is_number()) {
                if (auto n = r_.integer(e, ip, 0, std::numeric_limits<std::int64_t>::max()))
                  out.series_particles.back() = *n;
              } else {
                r_.error(
                    ip,
                    std::string(
                        "expected a particle index (integer >= 0) or {\"near\": [x, ...]}, got ") +
                        e.type_name());
              }
            }
        }
      }
      if (s.contains("fields")) out.series_fields = parse_fields(s["fields"], sp + "/fields");
      r_.number_at(s, sp, "interval", Range::non_negative(), out.series_interval);
    }
  }
  if (j.contains("snapshots")) {
    const json& s = j["snapshots"];
    const std::string sp = path + "/snapshots";
    if (r_.object(s, sp, kSnapshots, kSnapshotsRequired)) {
      r_.number_at(s, sp, "interval", Range::positive(), out.snapshot_interval);
      if (s.contains("fields")) {
        out.snapshot_fields = parse_fields(s["fields"], sp + "/fields");
        // Points of the VTU files are the particle positions: always written.
        if (!out.snapshot_fields.empty() &&
            std::find(out.snapshot_fields.begin(), out.snapshot_fields.end(), Field::position) ==
                out.snapshot_fields.end())
          out.snapshot_fields.insert(out.snapshot_fields.begin(), Field::position);
      }
    }
  }
}

// --------------------------------------------------------- whole-problem checks

std::string JobParser::pointer_for(const std::string& where) const {
  // "materials/NAME/..." — the name may itself contain '/', so match it
  // against the known names rather than splitting.
  const std::string prefix = "materials/";
  if (where.rfind(prefix, 0) == 0) {
    for (const Material& m : p_.materials) {
      const std::string head = prefix + m.name;
      if (where == head || where.rfind(head + "/", 0) == 0)
        return "/materials/" + escape_pointer_token(m.name) + where.substr(head.size());
    }
  }
  return where.empty() ? std::string() : "/" + where;
}

bool JobParser::check_particle_budget() {
  // Count particles from the layout rule without generating them, so a huge
  // body is refused before anything allocates per particle.
  // Laying out a body walks every cell along each axis; many bodies on a
  // fine grid would make validation itself slow.
  double axis_cells = 0;
  for (int a = 0; a < dim_; ++a) axis_cells += p_.grid.cells[a];
  const double layout_work = axis_cells * static_cast<double>(p_.bodies.size());
  if (layout_work > kMaxLayoutWork) {
    r_.error("/bodies", std::to_string(p_.bodies.size()) + " bodies on a grid of " +
                            format_count(axis_cells) +
                            " cells summed over the axes is too much work to lay out (" +
                            format_count(layout_work) + " > " + format_count(kMaxLayoutWork) +
                            "); merge bodies");
    return false;
  }
  double total = 0;
  for (std::size_t b = 0; b < p_.bodies.size(); ++b) {
    const Body& body = p_.bodies[b];
    double n = 1;
    for (int a = 0; a < dim_; ++a) {
      const double along =
          static_cast<double>(cells_inside(p_.grid, a, body.box.min[a], body.box.max[a])) *
          body.particles_per_cell;
      if (along > static_cast<double>(limits_.max_particles)) {
        r_.error(child_pointer("/bodies", b) + "/particles_per_cell",
                 "body would have " + format_count(along) + " particles along " +
                     std::string(kAxisNames[a]) + "; the limit is " +
                     std::to_string(limits_.max_particles) + " particles in all");
        return false;
      }
      n *= along;
    }
    total += n;
  }
  if (total > static_cast<double>(limits_.max_particles)) {
    r_.error("/bodies", "the bodies would create " + format_count(total) +
                            " particles; the limit is " + std::to_string(limits_.max_particles));
    return false;
  }
  return true;
}

void JobParser::check_whole_problem() {
  if (!check_particle_budget()) return;
  resolve_near();
  for (const ProblemIssue& issue : check_problem(p_))
    r_.error(pointer_for(issue.where), issue.message);
  if (r_.error_count() > 0) return;
  check_traction_selections();
  check_formulas_are_finite();
  if (r_.error_count() > 0) return;
  check_limits();
}

void JobParser::resolve_near() {
  if (near_.empty()) return;
  const std::int64_t n = count_particles(p_);
  if (static_cast<double>(near_.size()) * static_cast<double>(n) > kMaxNearWork) {
    r_.error("/output/series/particles",
             std::to_string(near_.size()) + " 'near' selections over " + std::to_string(n) +
                 " particles is too much work to resolve; name particles by index instead");
    return;
  }
  for (const PendingNear& s : near_) {
    const std::int64_t i = nearest_particle(p_, s.at);
    if (i < 0)
      r_.error(s.path, "no particle exists");
    else
      p_.output.series_particles[s.slot] = i;
  }
}

void JobParser::check_traction_selections() {
  // A convenience check, skipped when it would cost more than a moment.
  if (p_.tractions.empty() ||
      static_cast<double>(p_.tractions.size()) * static_cast<double>(count_particles(p_)) >
          kMaxNearWork)
    return;
  const std::vector<Vec3> positions = initial_positions(p_);
  for (std::size_t k = 0; k < p_.tractions.size(); ++k) {
    const Box& box = p_.tractions[k].particles;
    const bool any = std::any_of(positions.begin(), positions.end(), [&](const Vec3& x) {
      for (int a = 0; a < dim_; ++a)
        if (x[a] < box.min[a] - 1e-12 || x[a] > box.max[a] + 1e-12)
          return false;  // as the solver selects
      return true;
    });
    if (!any)
      r_.error(traction_paths_[k],
               "selects no particle; particles sit at sub-cell centres, e.g. the "
               "top row of a body is half a particle spacing below its top face");
  }
}

void JobParser::check_formulas_are_finite() {
  // Time functions: at up to 1001 instants over [0, end], about a million
  // evaluations in all.
  const int intervals = static_cast<int>(std::clamp(
      1e6 / static_cast<double>(std::max<std::size_t>(time_formulas_.size(), 1)), 1.0, 1000.0));
  for (const TimeFormula& tf : time_formulas_) {
    for (int k = 0; k <= intervals; ++k) {
      const double t = p_.time.end * k / intervals;
      const double v = tf.f(t);
      if (!std::isfinite(v)) {
        r_.error(tf.path,
                 "the formula gives " + format_number(v) + " at t = " + format_number(t) + " s");
        break;
      }
      if (damping_formula_ && tf.path == "/local_damping" && !(v >= 0.0 && v < 1.0)) {
        r_.error(tf.path, "the formula gives " + format_number(v) + " at t = " +
                              format_number(t) + " s; local damping must lie in [0, 1)");
        break;
      }
    }
  }
  if (position_formulas_.empty()) return;
  // Initial fields: at every particle of the body, or a regular sample of
  // about a million evaluations in all when the bodies are large.
  std::vector<std::vector<Vec3>> positions(p_.bodies.size());
  double evaluations = 0;
  for (const PositionFormula& pf : position_formulas_) {
    if (pf.body >= p_.bodies.size()) continue;
    if (positions[pf.body].empty()) {
      Problem one;
      one.dimension = p_.dimension;
      one.grid = p_.grid;
      Body b;
      b.box = p_.bodies[pf.body].box;
      b.particles_per_cell = p_.bodies[pf.body].particles_per_cell;
      one.bodies.push_back(b);
      positions[pf.body] = initial_positions(one);
    }
    evaluations += static_cast<double>(positions[pf.body].size());
  }
  const std::size_t stride = static_cast<std::size_t>(std::max(1.0, std::ceil(evaluations / 1e6)));
  for (const PositionFormula& pf : position_formulas_) {
    if (pf.body >= p_.bodies.size()) continue;
    const std::vector<Vec3>& xs = positions[pf.body];
    for (std::size_t i = 0; i < xs.size(); i += stride) {
      const double v = pf.f(xs[i]);
      if (!std::isfinite(v)) {
        std::string at = "x = " + format_number(xs[i][0]);
        if (dim_ > 1) at += ", y = " + format_number(xs[i][1]);
        if (dim_ > 2) at += ", z = " + format_number(xs[i][2]);
        r_.error(pf.path, "the formula gives " + format_number(v) + " at a particle of body " +
                              std::to_string(pf.body) + " (" + at + ")");
        break;
      }
    }
  }
}

void JobParser::check_limits() {
  const CostEstimate c = estimate_cost(p_);
  const StableStep s = stable_step(p_);
  const double steps = std::ceil(p_.time.end / s.chosen - 1e-9);
  if (steps > static_cast<double>(limits_.max_steps)) {
    const std::string why = p_.time.dt ? "end " + format_number(p_.time.end) + " s / dt " +
                                             format_number(s.chosen) + " s"
                                       : "end " + format_number(p_.time.end) +
                                             " s / automatic dt " + format_number(s.chosen) + " s";
    r_.error(p_.time.dt ? "/time/dt" : "/time/end", "the run needs " + format_count(steps) +
                                                        " time steps (" + why + "); the limit is " +
                                                        std::to_string(limits_.max_steps));
  }
  if (c.series_rows > limits_.max_series_rows)
    r_.error("/output/series/interval",
             "the series would have " + std::to_string(c.series_rows) + " rows; the limit is " +
                 std::to_string(limits_.max_series_rows) + "; use a larger interval");
  if (c.snapshots > limits_.max_snapshots)
    r_.error("/output/snapshots/interval",
             "the run would write " + std::to_string(c.snapshots) + " snapshots; the limit is " +
                 std::to_string(limits_.max_snapshots) + "; use a larger interval");
  if (c.output_bytes > limits_.max_output_bytes)
    r_.error("/output", "the result files would take about " + std::to_string(c.output_bytes) +
                            " bytes; the limit is " + std::to_string(limits_.max_output_bytes));
}

}  // namespace

CostEstimate estimate_cost(const Problem& p) {
  CostEstimate c;
  const int dim = std::clamp(p.dimension, 1, 3);
  c.particles = count_particles(p);
  double cells = 1, nodes = 1;
  for (int a = 0; a < dim; ++a) {
    cells *= p.grid.cells[a];
    nodes *= p.grid.cells[a] + 1.0;
  }
  c.cells = to_count(cells);
  c.nodes = to_count(nodes);
  c.dt = stable_step(p).chosen;
  const double steps = c.dt > 0 ? std::ceil(p.time.end / c.dt - 1e-9) : 0.0;
  c.steps = to_count(steps);
  c.particle_steps = to_count(static_cast<double>(c.particles) * steps);
  c.memory_bytes = to_count(400.0 * static_cast<double>(c.particles) + 100.0 * nodes);
  const OutputRequest& o = p.output;
  double rows = 0;
  if (!o.series_particles.empty() && !o.series_fields.empty())
    rows = o.series_interval <= c.dt ? steps + 1
                                     : std::floor(p.time.end / o.series_interval + 1e-9) + 1;
  c.series_rows = to_count(rows);
  const double snaps =
      o.snapshot_interval > 0 ? std::floor(p.time.end / o.snapshot_interval + 1e-9) + 1 : 0;
  c.snapshots = to_count(snaps);
  double series_values = 0;
  for (Field f : o.series_fields) series_values += field_components(f, dim);
  series_values *= static_cast<double>(o.series_particles.size());
  double snapshot_values = 2;  // volume, material
  if (o.snapshot_fields.empty()) {
    snapshot_values += 4 * 3 + 3 * 6 + 2;
  } else {
    for (Field f : o.snapshot_fields) {
      const int n = field_components(f, 3);
      snapshot_values += n;
    }
  }
  // ~22 characters per number in series.json and again in series.csv;
  // base64 float64 in the VTU files is 8 * 4/3 bytes per number.
  const double bytes =
      4096 + rows * (1 + series_values) * 2 * 22 +
      snaps * (static_cast<double>(c.particles) * (snapshot_values * 32.0 / 3.0 + 16) + 4096);
  c.output_bytes = to_count(bytes);
  return c;
}

const std::vector<SpecObjectKeys>& spec_object_keys() {
  static const std::vector<SpecObjectKeys> table = [] {
    auto entry = [](std::string location, Keys keys) {
      return SpecObjectKeys{std::move(location),
                            std::vector<std::string>(keys.begin(), keys.end())};
    };
    return std::vector<SpecObjectKeys>{
        entry("", kTop),
        entry("/grid", kGrid),
        entry("/materials/*", kMaterial),
        entry("/materials/*/hydraulic", kHydraulic),
        entry("/bodies/*", kBody),
        entry("/bodies/*/box", kBox),
        entry("/bodies/*/initial", kInitial),
        entry("/boundaries/*", kBoundary),
        entry("/boundaries/*/nodes", kSelection),
        entry("/boundaries/*/nodes/box", kBox),
        entry("/tractions/*", kTraction),
        entry("/tractions/*/particles", kSelection),
        entry("/tractions/*/particles/box", kBox),
        entry("/initial_state", kInitialState),
        entry("/initial_state/geostatic", kGeostatic),
        entry("/time", kTime),
        entry("/output", kOutput),
        entry("/output/series", kSeries),
        entry("/output/series/particles/*", kNear),
        entry("/output/snapshots", kSnapshots),
    };
  }();
  return table;
}

const char* version() {
  return HMPM_VERSION;
}

ParseResult parse_job(std::string_view json_text, const Limits& limits) {
  try {
    return JobParser(limits).parse(json_text);
  } catch (const std::exception& e) {
    ParseResult r;
    r.errors.push_back({"", std::string("internal error while reading the spec: ") + e.what()});
    return r;
  }
}

}  // namespace hmpm::api
