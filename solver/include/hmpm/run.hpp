// run.hpp — running a Problem: set-up checks, the time loop, and what comes out.
//
// `run()` is the one entry point: it fills the bodies with particles, picks
// or checks the time step, advances the explicit u-p MPM cycle to the end
// time, samples the requested outputs, reports progress and honours
// cooperative cancellation. It never throws for a physical failure: a run
// that diverges, loses a particle or inverts a volume ends with
// `RunStatus::failed` and a message naming the step, time, particle and what
// to change. It throws `std::invalid_argument` only for a Problem that
// `check_problem` would have rejected.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

/// A problem found in a Problem before running. `where` names the part in
/// the vocabulary of the job spec (e.g. "time/dt", "bodies/0/box"), so the
/// api can turn it into a JSON pointer.
/// A place in the job spec as its parts (object keys and array indices), e.g.
/// {"materials", "a/b", "hydraulic"}: the api turns the parts into a JSON
/// pointer (escaping each), so a name holding '/' keeps its meaning.
struct Location {
  std::vector<std::string> parts;

  Location() = default;
  Location(std::initializer_list<std::string> p) : parts(p) {}
  /// This location with one more part (a key, or an index).
  Location operator/(std::string part) const {
    Location l = *this;
    l.parts.push_back(std::move(part));
    return l;
  }
  Location operator/(std::size_t index) const { return *this / std::to_string(index); }
  /// The parts joined by '/', for messages ("materials/a/b/hydraulic").
  std::string text() const {
    std::string out;
    for (const std::string& part : parts) out += (out.empty() ? "" : "/") + part;
    return out;
  }
};

struct ProblemIssue {
  Location where;
  std::string message;
};

/// Stable time step estimate, in seconds.
struct StableStep {
  double mechanical = 0.0;  ///< h_min / c, c the undrained P-wave speed
  double hydraulic = 0.0;   ///< explicit diffusion limit h^2 / (2 d c_h); inf if dry
  double limit = 0.0;       ///< min of the two (Courant factor 1)
  double chosen = 0.0;      ///< the dt the run will use
  double wave_speed = 0.0;  ///< m/s, fastest material
  /// Steps to time.end: ceil(end / chosen) for a fixed dt; the scheme's
  /// count for a growing one (quasi_static).
  std::int64_t steps = 0;
  /// true when every step is `chosen` long (the last one ends at time.end);
  /// false when the scheme picks each step (quasi_static growth/automatic).
  bool fixed = true;
  /// Varying steps (fixed false): the geometric plan the scheme follows
  /// (initial = chosen), before the steps are shortened to land on output
  /// instants.
  StepGrowth plan{};
  /// The stiffness of some material with particles changes with its state
  /// (Modified Cam-Clay: K = (1 + e) p'/kappa) and dt is automatic: the
  /// scheme re-evaluates the mechanical limit from the particles' state
  /// before every step (fixed false; `chosen` and `steps` are then the
  /// estimate at the materials' reference stiffness).
  bool follows_state = false;
  /// The mechanical limit over the materials whose stiffness does not change
  /// with state (inf if none), s: what the re-evaluation starts from.
  double steady_mechanical = 0.0;
};

/// Estimates the stable step for `problem` (automatic or user dt).
StableStep stable_step(const Problem& problem);

/// The snapshot fields when the output lists none: every field, a material
/// parameter's (Field::youngs_modulus ...) only when some material varies it.
std::vector<Field> default_snapshot_fields(const Problem& problem);

/// Checks a Problem for anything the solver cannot run: dimensions,
/// positive moduli and densities, boxes inside the grid, a user dt above the
/// stable limit (refused, with the limit in the message), empty bodies.
/// Returns every issue found; empty means runnable.
std::vector<ProblemIssue> check_problem(const Problem& problem);

/// Things in a runnable Problem a user should know before running: each a
/// `where` in the job-spec vocabulary and a message saying what to change.
/// Today: materials whose fluid is so compressible that the u-p equations
/// with Darcy's rho_f a term are near or past their stability limit
/// (docs/verification.md); bodies that lose particle positions to an
/// earlier body where they overlap. The run's RunResult::warnings repeat them.
std::vector<ProblemIssue> problem_warnings(const Problem& problem);

/// Stages of a job: 1 + problem.stages.size() (the top level is stage 0).
inline std::size_t stage_count(const Problem& problem) {
  return 1 + problem.stages.size();
}

/// The Problem in force during stage k: the top level with the changes of
/// stages 1..k applied (lists replaced, gravity, time control, damping),
/// time.end the stage's end. Bodies stay the job's (all of them);
/// stage_bodies says which have particles.
Problem stage_problem(const Problem& problem, std::size_t k);

/// The cell size strain softening is regularised with: the geometric mean
/// of a cell's sides in the problem's dimension.
double softening_cell_size(const Problem& problem);

/// `problem` with every regularised softening (Softening::reference_cell_size
/// > 0) applied: its shape factor times softening_cell_size / the reference
/// (marked `regularised`, so applying it again changes nothing). A run does
/// this before it sets up.
Problem regularise_softening(const Problem& problem);

/// Per body: whether its particles are in the run during stage k (a body
/// some stage adds is absent before that stage; a removed one from its
/// stage on).
std::vector<bool> stage_bodies(const Problem& problem, std::size_t k);

/// The job's ground at the start: the Problem without the bodies a stage
/// adds (the geostatic state and its checks see this ground).
Problem initial_ground(const Problem& problem);

/// Number of particles the bodies generate (lays the bodies out).
std::int64_t count_particles(const Problem& problem);

/// Initial positions of every particle, in the global numbering of the
/// contract (bodies in order; in a box, polygon or prism body x fastest,
/// then y, then z; in a points body the given order), without the
/// positions a body loses to an earlier one.
std::vector<Vec3> initial_positions(const Problem& problem);

/// Appends to `issues` what makes `polygon` unusable, at `where` (or an
/// index under it): fewer than 3 vertices, a repeated vertex, zero area,
/// edges that cross or touch. check_problem runs it on every polygon of the
/// Problem.
void check_polygon(const Polygon& polygon, const Location& where,
                   std::vector<ProblemIssue>& issues);

/// Whether a grid node at `x` belongs to the selection (its box, with a
/// tolerance of 1e-9 cell sizes, or its polygon, inside or on the boundary
/// within 1e-6 of the smallest cell size).
bool node_selected(const Problem& problem, const NodeSelection& nodes, const Vec3& x);

/// Whether a particle with initial position `x` is loaded by the traction
/// (inside its box, or inside or on its polygon as node_selected).
bool particle_selected(const Problem& problem, const Traction& traction, const Vec3& x);
/// The same for a flux.
bool particle_selected(const Problem& problem, const Flux& flux, const Vec3& x);
/// The same for a surface pressure.
bool particle_selected(const Problem& problem, const SurfacePressure& s, const Vec3& x);
/// Whether output.consolidation counts the particle initially at x (its
/// selection; pore water aside).
bool particle_selected(const Problem& problem, const ConsolidationRequest& c, const Vec3& x);

/// Index of the particle whose initial position is nearest to `x`; -1 if none.
std::int64_t nearest_particle(const Problem& problem, const Vec3& x);

struct Progress {
  std::int64_t step = 0;
  std::int64_t total_steps = 0;
  double time = 0.0;      ///< simulated time, s
  double end_time = 0.0;  ///< s
  double fraction = 0.0;  ///< time / end_time in [0, 1]
};

/// All particles' fields at one instant, for snapshot writers. Arrays are
/// flat: entry i of a vector field with c components is [i*c, i*c + c).
/// Vectors always have 3 components (zero-padded), tensors 6 (Voigt).
struct Snapshot {
  int index = 0;  ///< 0, 1, 2, ... in time order
  double time = 0.0;
  /// The failure mechanism of a strength reduction (Problem::strength_reduction:
  /// displacement and plastic strain since F = 1 at the largest F that
  /// converged), not one of the time series; `index` is then that of the
  /// next snapshot of the series, unused.
  bool mechanism = false;
  int dimension = 1;
  std::int64_t particles = 0;
  std::vector<Field> fields;                      ///< which of the arrays below are filled
  std::vector<double> position;                   ///< 3 per particle
  std::vector<double> displacement;               ///< 3
  std::vector<double> velocity;                   ///< 3
  std::vector<double> pore_pressure;              ///< 1
  std::vector<double> darcy_velocity;             ///< 3
  std::vector<double> effective_stress;           ///< 6
  std::vector<double> total_stress;               ///< 6
  std::vector<double> strain;                     ///< 6
  std::vector<double> porosity;                   ///< 1
  std::vector<double> plastic_strain;             ///< 1, accumulated equivalent plastic strain
  std::vector<double> excess_pore_pressure;       ///< 1, pore pressure minus the steady one
  std::vector<double> void_ratio;                 ///< 1, Cam-Clay's e (0 elsewhere)
  std::vector<double> preconsolidation_pressure;  ///< 1, Cam-Clay's p'c, Pa (0 elsewhere)
  /// 1 each: the material parameters at the particles (Field::youngs_modulus ...).
  std::vector<double> youngs_modulus, cohesion, friction_angle, hydraulic_conductivity;
  std::vector<double> volume;  ///< 1, always filled
  std::vector<double> mass;    ///< 1, always filled
  std::vector<int> material;   ///< 1, always filled
  /// 1, always filled: each particle's index in the job's numbering (that of
  /// the series and profiles), kept when stages remove or add bodies.
  std::vector<std::int64_t> id;
};

/// Time histories of the selected particles. `values[f]` holds, for field
/// `fields[f]`, rows in time order; each row is particles x components
/// (components from field_components(fields[f], dimension)).
struct Series {
  int dimension = 1;
  std::vector<double> time;
  std::vector<std::int64_t> particles;
  std::vector<Vec3> initial_positions;
  std::vector<Field> fields;
  std::vector<std::vector<double>> values;
};

/// The force each boundary of the Problem exerts on the soil (the mixture:
/// skeleton and pore water together), sampled at OutputRequest::
/// reactions_interval: the sum, over the node components the boundary
/// constrains, of the nodal force that enforces its constraint. Units: N in
/// 3D, N per metre of thickness in 2D (plane strain), N per square metre of
/// cross-section in 1D. A node component constrained by several boundaries
/// is charged to the one whose constraint is applied last in the order of
/// precedence (boundary/apply.hpp: a prescribed velocity over friction over
/// a rigid tie; among equals, the later boundary in the Problem).
/// `force[b]` holds `dimension` values per sample time, time after time.
struct Reactions {
  int dimension = 1;
  std::vector<double> time;
  std::vector<std::vector<double>> force;  ///< per boundary: dimension values per time
};

/// The complete state of a run after `step`, as opaque bytes (the solver's
/// versioned binary format, checkpoint.hpp): RunOptions::resume with these
/// bytes continues the run to results bit-identical to an uninterrupted run
/// at the same thread count.
struct Checkpoint {
  std::int64_t step = 0;
  double time = 0.0;  ///< simulated time, s
  std::string bytes;
};

/// What a checkpoint holds, read from its header and output bookkeeping.
struct CheckpointInfo {
  int version = 0;
  std::int64_t step = 0;
  double time = 0.0;  ///< simulated time, s
  std::int64_t particles = 0;
  int threads = 1;                     ///< solver threads of the run that wrote it
  std::vector<double> snapshot_times;  ///< snapshots 0.. already taken, in order
};

/// Reads and checks `bytes` as a checkpoint of `problem` run with
/// `checkpoint_key` (RunOptions::checkpoint_key): magic, version,
/// dimension, shape function, scheme, particle count, the hash of the key
/// and of the problem's set-up figures, and the checksum of the whole.
/// Throws std::invalid_argument saying what does not match.
CheckpointInfo inspect_checkpoint(const Problem& problem, const std::string& checkpoint_key,
                                  const std::string& bytes);

struct RunOptions {
  int threads = 1;  ///< solver threads; <= 0 means every core
  /// Fewer particles than this per thread and the run uses fewer threads:
  /// below it thread dispatch costs more than it saves.
  std::int64_t min_particles_per_thread = 20000;
  /// Called about every `progress_interval_s` seconds of wall time, and once at the end.
  std::function<void(const Progress&)> on_progress;
  double progress_interval_s = 0.5;
  /// Called for every snapshot as it is taken (written by the caller, not kept).
  std::function<void(const Snapshot&)> on_snapshot;
  /// Checked once per step, and every few hundred particles during set-up
  /// (particle generation, initial-field formulas, geostatic state); when it
  /// becomes true the run stops as cancelled.
  const std::atomic<bool>* cancel = nullptr;
  /// Wall-clock limit on the whole run, set-up included, in seconds (checked
  /// as often as `cancel` in set-up, at each progress report in the time
  /// loop); <= 0: none. Reaching it fails the run with a message naming it.
  /// A resumed run counts the loop time of the runs before it.
  double wall_time_limit_s = 0.0;
  /// Called with a checkpoint of the whole run state after the first step
  /// that ends `checkpoint_interval_s` or more of wall time after the start
  /// or the last checkpoint (<= 0: never), and once more when the run is
  /// cancelled after steps the last checkpoint does not hold. The bytes are
  /// the caller's to store; the buffer is reused by the next call.
  std::function<void(const Checkpoint&)> on_checkpoint;
  double checkpoint_interval_s = 60.0;
  /// Names the job a checkpoint belongs to (e.g. its spec text): its hash is
  /// in every checkpoint, and a checkpoint is resumed only with the same key.
  std::string checkpoint_key;
  /// Checkpoint bytes to continue from (from on_checkpoint of an earlier run
  /// of the same problem and key); null: start at t = 0. A checkpoint that
  /// does not belong to the problem makes run() throw std::invalid_argument.
  const std::string* resume = nullptr;
};

enum class RunStatus { successful, failed, cancelled };
const char* status_name(RunStatus s);

struct RunResult {
  RunStatus status = RunStatus::failed;
  std::string message;
  /// The set-up's warnings (problem_warnings), then run_warnings.
  std::vector<std::string> warnings;
  /// Found during the time loop (pore pressure below cavitation, tensile
  /// total stress in a material without tensile strength), also at the end
  /// of `warnings`: the run still ends as it ends.
  std::vector<std::string> run_warnings;
  std::int64_t steps = 0;
  double end_time = 0.0;  ///< simulated time reached, s
  double dt = 0.0;        ///< the first stage's first (or fixed) step, s
  /// How the steps were chosen: "user" (time.dt), "stable" (the automatic
  /// fixed step), "stable_with_state" (re-evaluated before every step from
  /// the particles' stiffness, StableStep::follows_state) or "growing" (the
  /// quasi-static scheme's own steps); of the first stage.
  std::string dt_rule = "stable";
  /// The shortest and longest steps taken, s (a step shortened to end a
  /// stage exactly is not counted); 0 before any step.
  double dt_min = 0.0;
  double dt_max = 0.0;
  std::int64_t particles = 0;
  std::int64_t nodes = 0;
  double solve_seconds = 0.0;  ///< wall time of the time loop only (all runs, when resumed)
  double particle_steps_per_second = 0.0;
  std::int64_t state_bytes = 0;     ///< particle + grid state in memory
  int threads = 1;                  ///< solver threads actually used
  std::string scheme = "explicit";  ///< scheme_name() of the run's scheme
  /// The scheme reports iteration counts (`iterations`; the implicit schemes).
  bool reports_iterations = false;
  /// Implicit schemes: their iteration counts (zero for the explicit one).
  struct Iterations {
    std::int64_t nonlinear = 0;  ///< Newton iterations, all steps (quasi_static)
    std::int64_t linear = 0;     ///< iterations of iterative linear solves (0: direct)
    std::int64_t solves = 0;     ///< linear systems solved
    std::int64_t cutbacks = 0;   ///< steps halved because Newton did not converge
    int max_nonlinear = 0;       ///< most Newton iterations in one step
    /// quasi_static: the scaled residual max(|R_u|/|f|, |R_p|/|terms|) at
    /// each Newton iteration (0 = the initial guess) of the first step that
    /// took max_nonlinear iterations: shows the rate of convergence.
    std::vector<double> worst_residuals;
  } iterations;
  Series series;
  Reactions reactions;  ///< empty unless OutputRequest::reactions_interval > 0
  /// One per OutputRequest::profiles line: its particles' fields at each
  /// profile time.
  std::vector<Series> profiles;
  /// OutputRequest::consolidation: the excess pore pressure of the ground
  /// and the average degree of consolidation at each sample time.
  struct Consolidation {
    std::vector<double> time;    ///< s
    std::vector<double> excess;  ///< E = sum (p - p_steady) V0, Pa m^3 (per unit area / thickness)
    std::vector<double> volume;  ///< sum V0 of the counted particles, m^3
    /// U = 1 - E / E(from) (the first sample is at `from`); NaN (null) in
    /// every sample when E(from) is zero (nothing to consolidate).
    std::vector<double> degree;
    /// s; the first times U reaches 0.5 and 0.9 (linear between samples);
    /// NaN when it does not.
    double t50 = std::numeric_limits<double>::quiet_NaN();
    double t90 = std::numeric_limits<double>::quiet_NaN();
  } consolidation;
  /// The soil found collapsing (time.on_collapse; docs/job-spec.md
  /// "Collapse"): the first time it was, what showed it and where.
  struct Collapse {
    bool found = false;
    double time = 0.0;      ///< s: the last state in equilibrium (quasi-static), or when found
    std::string criterion;  ///< what showed it (the contract's words, docs/job-spec.md)
    /// The resultant of the surface loads (tractions) at `time`, N (per
    /// metre in 2D): the load level of a load-controlled run.
    Vec3 load{0.0, 0.0, 0.0};
    /// The particles yielding at the collapse (plastic in the last
    /// iteration or step): how many, and their bounding box.
    std::int64_t yielding = 0;
    Vec3 yield_min{0.0, 0.0, 0.0}, yield_max{0.0, 0.0, 0.0};
    double max_displacement = 0.0;  ///< m, the largest particle displacement
    bool stopped = false;           ///< the run stopped there (CollapseAction::stop)
    std::string message;            ///< the sentence of the log and the status
  } collapse;
  /// Problem::strength_reduction: the factor of safety.
  struct StrengthReductionResult {
    bool done = false;
    double factor = 0.0;  ///< the largest F that converged
    /// The first F that did not converge (factor + at most the resolution);
    /// NaN when F reached max_factor without failing.
    double failed_at = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> factors;           ///< every converged F, in order
    std::vector<double> max_displacement;  ///< m, since F = 1, at each of `factors`
    std::int64_t attempts = 0;             ///< trial values of F solved (converged or not)
    std::int64_t backtracks = 0;           ///< line-search halvings of the trials' corrections
    /// Trials that lost a particle (it left the grid, its volume or a
    /// value became non-finite): counted as not converged.
    std::int64_t lost_particle = 0;
    /// The slide criterion in force, m (StrengthReduction::displacement_limit),
    /// and the trials that converged only past it.
    double displacement_limit = 0.0;
    std::int64_t past_displacement_limit = 0;
    std::string message;
  } strength_reduction;
};

/// Runs `problem` to its end time. See the file comment for failure modes.
RunResult run(const Problem& problem, const RunOptions& options = {});

}  // namespace hmpm
