// parser.hpp — what the section readers of a job spec share.
//
// parse_job walks the document once (job.cpp). Each spec section has its
// own file in this folder with its accepted keys beside the code that reads
// them: grid.cpp, materials.cpp (with material_models.cpp, the table of
// constitutive models), bodies.cpp, boundaries.cpp, tractions.cpp,
// initial_state.cpp, time.cpp, output.cpp; values.cpp reads what several
// sections share (boxes, selections, formulas), motion.cpp tables of time
// and accelerations. Every reader records its
// problems in the ParseContext's SpecReader with their JSON pointers and
// fills the Problem as it goes. checks.cpp then runs the checks that need
// the whole Problem, locations.cpp turns the solver's issue locations into
// JSON pointers, and tables.cpp prints every table for `hmpm spec-keys`.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"
#include "spec_reader.hpp"

namespace hmpm::api::parse {

using Keys = std::span<const std::string_view>;

inline constexpr std::string_view axis_names[] = {"x", "y", "z"};

/// A formula (not a plain number) of position read from the spec, checked
/// for finite values once the particles are known.
struct PositionFormula {
  std::size_t body;
  std::string path;
  FieldOfPosition f;
  std::size_t length = 0;  ///< characters: what one evaluation costs, roughly
};
/// A formula of time read from the spec, checked over [0, end].
struct TimeFormula {
  std::string path;
  FieldOfTime f;
  std::size_t length = 0;  ///< characters
};
/// An output.series particle given as {"near": [...]}, resolved once the
/// particles are known.
struct PendingNear {
  std::size_t slot;  ///< index into series_particles
  Vec3 at;
  std::string path;
};

/// An output.series particle entry {"polygon": [...]} (2D): every particle
/// whose initial position lies inside or on it, in numbering order, replaces
/// the entry once the particles are known.
struct PendingPolygon {
  std::size_t slot;  ///< index into series_particles
  Polygon polygon;
  std::string path;
};

struct IntegratedFormula;  // motion.cpp

/// The state of one parse: the reader with its errors, the Problem being
/// built and what the whole-problem checks need later.
struct ParseContext {
  ParseContext(const Limits& l, const Calibration& cal) : limits(l), calibration(cal) {}

  const Limits& limits;
  const Calibration& calibration;  ///< what the cost is estimated with
  /// The job's cost, estimated once by check_limits (it becomes ParsedJob::cost).
  std::optional<CostEstimate> cost;
  SpecReader r;
  Problem p;
  std::string name = "job";
  int dim = 0;           ///< 0 while unknown or invalid: vector lengths are not checked
  bool grid_ok = false;  ///< grid valid: boxes can be checked against it
  std::map<std::string, int> material_index;
  std::vector<PendingNear> near;
  std::vector<PendingPolygon> series_polygons;
  std::vector<ProfileGeometry> profiles;  ///< output.profiles.lines, particles resolved later
  std::vector<PositionFormula> position_formulas;
  std::vector<TimeFormula> time_formulas;
  /// Acceleration formulas, integrated by integrate_accelerations.
  std::vector<std::shared_ptr<IntegratedFormula>> accelerations;
  bool damping_formula = false;         ///< local_damping given as a formula of t
  std::int64_t formula_characters = 0;  ///< of every formula read so far
  std::size_t formulas = 0;             ///< formulas read so far
  std::vector<std::string> traction_paths;
  std::vector<std::string> flux_paths;  ///< "/fluxes/i/particles", for selection errors
  /// "/surface_pressures/i/particles", for selection errors
  std::vector<std::string> surface_pressure_paths;
  /// output.consolidation without steady_pore_pressure (resolve_consolidation)
  bool consolidation_hydrostatic = false;
  /// Where excess_pore_pressure is first listed among the output fields
  /// (its reference is resolved as output.consolidation's); empty: nowhere.
  std::string excess_field_path;
  bool any_pore_pressure_bc = false;
  std::string first_pore_pressure_bc;
  /// Runnable but worth knowing (e.g. time.implicit with the explicit
  /// scheme); parse_job puts them before the solver's warnings.
  std::vector<SpecError> warnings;
};

// ------------------------------------------------------------- sections
// Each reads the value `j` found at JSON pointer `path`.
void read_grid(ParseContext& c, const json& j, const std::string& path);
void read_shape_function(ParseContext& c, const json& j, const std::string& path);
void read_materials(ParseContext& c, const json& j, const std::string& path);
/// A material parameter given as {"random_field": {...}} (random_fields.cpp).
std::optional<RandomField> read_random_field(ParseContext& c, const json& j,
                                             const std::string& path);
/// A Mohr-Coulomb material's "softening" (softening.cpp); `m` has its model.
void read_softening(ParseContext& c, Material& m, const json& j, const std::string& path);
void softening_keys(std::vector<SpecObjectKeys>& out);
void read_bodies(ParseContext& c, const json& j, const std::string& path);
/// A material's name (a body's, a stage's body_materials'): its index, or
/// an error at `path` naming the defined ones.
std::optional<int> read_material_name(ParseContext& c, const json& j, const std::string& path);
void read_boundaries(ParseContext& c, const json& j, const std::string& path);
void read_tractions(ParseContext& c, const json& j, const std::string& path);
void read_fluxes(ParseContext& c, const json& j, const std::string& path);
void read_surface_pressures(ParseContext& c, const json& j, const std::string& path);
void read_time(ParseContext& c, const json& j, const std::string& path);
void read_strength_reduction(ParseContext& c, const json& j, const std::string& path);
void read_local_damping(ParseContext& c, const json& j, const std::string& path);
void read_initial_state(ParseContext& c, const json& j, const std::string& path);
void read_output(ParseContext& c, const json& j, const std::string& path);
/// `stages` (stages.cpp): after every other section (it reuses their readers).
void read_stages(ParseContext& c, const json& j, const std::string& path);
/// Stages a spec may hold.
inline constexpr std::size_t max_stages = 1000;
/// Stages x (materials + bodies + boundaries + tractions + fluxes, those
/// of every stage included) a spec may hold. Checking and costing a staged
/// job builds and checks the problem in force once per stage (the solver's
/// stage_problem copies the whole problem, stages included, each time), so
/// its cost grows with this product: measured on the 2-core test machine,
/// 100 stages over 19 000 boundaries took 17 s, 999 stages over 1 000
/// boundaries 0.6 s; at 100 000 it stays under a second.
inline constexpr std::size_t max_stage_items_product = 100'000;
/// Refuses (at /stages) a spec beyond max_stage_items_product; after
/// reading, before the whole-problem checks.
void check_stage_budget(ParseContext& c);

/// The first character of `s` (UTF-8, which the JSON parser has checked)
/// that a name shown to people may not hold: C0 and C1 control characters,
/// the bidirectional controls that make a name show as something else, and
/// characters that show as nothing (zero-width spaces and joiners, the
/// soft hyphen, the byte order mark, fillers, tags). Its position (in
/// characters) and code point.
std::optional<std::pair<std::size_t, char32_t>> forbidden_in_name(std::string_view s);
/// A name (the job's, a stage's): a string of at most `max_characters`
/// characters without what forbidden_in_name finds; `what` names it in the
/// error ("a job name").
std::optional<std::string> read_label(ParseContext& c, const json& j, const std::string& path,
                                      std::size_t max_characters, const char* what);

// ------------------------------------------------------ shared value readers
/// {"min": [...], "max": [...]} inside the grid (when the grid is valid).
std::optional<Box> read_box(ParseContext& c, const json& j, const std::string& path);
/// [[u, v], ...]: a plane polygon of 3 or more vertices, whose coordinates
/// are along the axes `plane` (inside the grid when it is valid). Whether it
/// is simple is checked with the whole Problem (check_problem).
std::optional<Polygon> read_polygon(ParseContext& c, const json& j, const std::string& path,
                                    std::array<int, 2> plane);
/// {"box": {...}}, {"polygon": [[x, y], ...]} (2D) or "all"; "all" is the
/// whole grid. A polygon is stored in `*polygon` and its bounding box
/// returned.
std::optional<Box> read_selection(ParseContext& c, const json& j, const std::string& path,
                                  bool& all, std::optional<Polygon>* polygon);
/// The keys of a box and of a selection object (for the key tables).
Keys box_key_names();
Keys selection_key_names();
/// A number or a formula in x, y, z (recorded for the finiteness check).
FieldOfPosition read_value_of_position(ParseContext& c, const json& j, const std::string& path);
/// A number, a formula in t or a table {"table": [[t, v], ...]} (recorded
/// for the finiteness check).
std::optional<FieldOfTime> read_value_of_time(ParseContext& c, const json& j,
                                              const std::string& path);
/// {"table": [[t, v], ...]}: piecewise linear, the end values held outside
/// (motion.cpp).
std::optional<FieldOfTime> read_table_of_time(ParseContext& c, const json& j,
                                              const std::string& path);
/// An acceleration (number, formula in t or table) as the velocity it
/// integrates to from rest at t = 0 (motion.cpp).
std::optional<FieldOfTime> read_acceleration(ParseContext& c, const json& j,
                                             const std::string& path);
/// Tabulates the integrals of the acceleration formulas over the job's
/// time (once its end is known).
void integrate_accelerations(ParseContext& c);
/// A number or a formula in x, y, z, t; `varies_in_space` says whether it
/// uses x, y or z. Checked for finite values over [0, end] at the grid's
/// centre (with the formulas of time).
std::optional<FieldOfSpaceTime> read_value_of_space_time(ParseContext& c, const json& j,
                                                         const std::string& path,
                                                         bool& varies_in_space);

// ------------------------------------------------------ whole-problem checks
/// Particle budget, "near" selections, the solver's check_problem,
/// traction selections, finite formulas and the limits (checks.cpp).
void check_whole_problem(ParseContext& c);

/// The JSON pointer of a location the solver reports (its parts, each
/// escaped: {"materials", "a/b"} -> "/materials/a~1b"), see locations.cpp.
std::string pointer_of_solver_location(const Location& where);

// ------------------------------------------------------------- key tables
/// Appends the accepted keys of the section's objects (for spec_object_keys).
void grid_keys(std::vector<SpecObjectKeys>& out);
void material_keys(std::vector<SpecObjectKeys>& out);
void body_keys(std::vector<SpecObjectKeys>& out);
void boundary_keys(std::vector<SpecObjectKeys>& out);
void traction_keys(std::vector<SpecObjectKeys>& out);
void flux_keys(std::vector<SpecObjectKeys>& out);
void surface_pressure_keys(std::vector<SpecObjectKeys>& out);
void initial_state_keys(std::vector<SpecObjectKeys>& out);
void time_keys(std::vector<SpecObjectKeys>& out);
void strength_reduction_keys(std::vector<SpecObjectKeys>& out);
void output_keys(std::vector<SpecObjectKeys>& out);
void stage_keys(std::vector<SpecObjectKeys>& out);
/// The values of the spec's enumerations: output field names (from
/// hmpm::field_table), traction faces, shape functions.
Keys field_names();
Keys traction_faces();
Keys shape_function_names();
/// time.scheme values (in hmpm::Scheme order) and time.implicit.linear_solver
/// values (in hmpm::LinearSolver order).
Keys scheme_names();
Keys linear_solver_names();
/// `location` with `keys` as one SpecObjectKeys entry.
SpecObjectKeys keys_entry(std::string location, Keys keys);

// --------------------------------------------------------------- helpers
/// "'a', 'b', 'c'".
std::string quoted_list(const std::vector<std::string>& words);
/// Grid nodes along `axis` inside the closed interval [lo, hi].
std::int64_t nodes_inside(const Grid& grid, int axis, double lo, double hi);
/// Whole grid cells along `axis` inside [lo, hi], with the solver's layout tolerance.
std::int64_t cells_inside(const Grid& grid, int axis, double lo, double hi);

}  // namespace hmpm::api::parse
