// problem.hpp — the typed description of an hmpm simulation.
//
// This is what the solver consumes: a structured background grid, materials,
// bodies filled with particles, boundary conditions, loads, time control and
// output requests. It is built once (by the api module from a JSON job spec,
// or directly by tests and benchmarks) and never looked up by string
// afterwards. All quantities are SI: metres, seconds, kilograms, pascals.
//
// Functions of position (initial fields) are evaluated once per particle at
// set-up; functions of time (boundary values, tractions) once per time step,
// never per particle.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "hmpm/fields.hpp"
#include "hmpm/random_field.hpp"

namespace hmpm {

/// A point or vector with up to three components; unused trailing components
/// are zero in 1D and 2D.
using Vec3 = std::array<double, 3>;

/// A value that may depend on position (x, y, z) — initial fields.
/// An empty function means "zero".
using FieldOfPosition = std::function<double(const Vec3& x)>;

/// A value that may depend on time t in seconds — boundary values and loads.
/// An empty function means "zero".
using FieldOfTime = std::function<double(double t)>;

/// A value that may depend on position x and time t — fluxes. x is the
/// particle's initial position. An empty function means "zero".
using FieldOfSpaceTime = std::function<double(const Vec3& x, double t)>;

/// Axis-aligned box [min, max] (closed). Components beyond the dimension are ignored.
struct Box {
  Vec3 min{0.0, 0.0, 0.0};
  Vec3 max{0.0, 0.0, 0.0};
};

/// Structured background grid; cell size per axis = (max - min) / cells.
struct Grid {
  Vec3 min{0.0, 0.0, 0.0};
  Vec3 max{1.0, 1.0, 1.0};
  std::array<int, 3> cells{1, 1, 1};
};

enum class ShapeFunction { linear, gimp, bspline };

/// Hydraulic properties: their presence makes a material a saturated porous
/// medium solved with the u-p formulation.
struct Hydraulic {
  double porosity = 0.3;                 ///< n, in (0, 1)
  double hydraulic_conductivity = 1e-3;  ///< k in m/s (Darcy's "permeability" of the paper)
  double fluid_bulk_modulus = 2.2e9;     ///< Kf in Pa
  double fluid_density = 1000.0;         ///< rho_f in kg/m^3
  /// Ks in Pa; infinity means incompressible grains.
  double solid_bulk_modulus = std::numeric_limits<double>::infinity();
  /// Keep the fluid-acceleration term rho_f a of Darcy's law (the paper's
  /// u-p model). false drops it (the low-frequency u-p simplification);
  /// see docs/verification.md for when that is needed.
  bool darcy_inertia = true;
};

struct LinearElastic {};

/// Mohr-Coulomb, non-associated, with tension cut-off. Angles in degrees.
struct MohrCoulomb {
  double friction_angle_deg = 30.0;
  double dilatancy_angle_deg = 0.0;
  double cohesion = 0.0;          ///< Pa
  double tensile_strength = 0.0;  ///< Pa; cut-off on the major principal stress
  /// Exponential strain softening from the values above (the peak) to the
  /// residual ones: X = X_r + (X_p - X_r) exp(-shape_factor kappa), kappa
  /// the particle's accumulated equivalent plastic strain under this
  /// material. reference_cell_size > 0 regularises it: the shape factor is
  /// shape_factor h / reference_cell_size on a grid of cell size h (the
  /// geometric mean of the cell's sides), so that the displacement across
  /// a shear band (about one cell wide) that softens the soil, and the
  /// energy dissipated per unit band length, do not change with the grid.
  struct Softening {
    double residual_cohesion = 0.0;             ///< Pa
    double residual_friction_angle_deg = 0.0;   ///< degrees
    double residual_dilatancy_angle_deg = 0.0;  ///< degrees
    double shape_factor = 0.0;                  ///< eta, per unit plastic strain
    double reference_cell_size = 0.0;           ///< m; 0: not regularised
    /// Set by regularise_softening (hmpm/run.hpp): shape_factor is already
    /// the regularised one.
    bool regularised = false;
  };
  std::optional<Softening> softening = std::nullopt;
};

/// Drucker-Prager fitted to Mohr-Coulomb (plane-strain match). Angles in degrees.
struct DruckerPrager {
  double friction_angle_deg = 30.0;
  double dilatancy_angle_deg = 0.0;
  double cohesion = 0.0;
  double tensile_strength = 0.0;
};

/// Modified Cam-Clay (Roscoe & Burland): yield surface
/// q^2/M^2 + p'(p' - p'c) = 0 (p' compression positive), associated flow,
/// isotropic hardening of p'c with the plastic volumetric strain, elastic
/// bulk modulus K = (1 + e) p' / kappa with a constant Poisson's ratio
/// (Material::poisson_ratio). The void ratio e and p'c are per-particle
/// state variables (materials/modified_cam_clay.hpp). Material::youngs_modulus
/// is then only a reference stiffness for the stable-step rules, the
/// quasi-static scheme's scalings and the plausibility checks (the api sets
/// it to the elastic Young's modulus at p' = p'c, docs/job-spec.md).
struct ModifiedCamClay {
  double lambda = 0.1;                ///< slope of the NCL in e - ln p'
  double kappa = 0.03;                ///< slope of the unloading-reloading line
  double critical_state_ratio = 1.2;  ///< M
  double initial_void_ratio = 1.0;    ///< e at the initial stress
  /// p'c in Pa at each particle's initial position; empty: the
  /// overconsolidation ratio times the particle's initial mean effective stress.
  FieldOfPosition preconsolidation_pressure;
  double overconsolidation_ratio = 1.0;  ///< used when preconsolidation_pressure is empty
};

using Plasticity = std::variant<LinearElastic, MohrCoulomb, DruckerPrager, ModifiedCamClay>;

/// A material parameter that may vary from particle to particle (each has
/// its output field of the same name, fields.hpp). Cam-Clay's
/// preconsolidation pressure is the initial value of its state variable:
/// its output is the state's field of that name (the particle's p'c as it
/// hardens, the field's value until it yields).
enum class MaterialParameter : std::uint8_t {
  youngs_modulus,             ///< Pa
  cohesion,                   ///< Pa (mohr_coulomb, drucker_prager)
  friction_angle,             ///< degrees (mohr_coulomb, drucker_prager)
  hydraulic_conductivity,     ///< m/s (materials with hydraulic)
  preconsolidation_pressure,  ///< Pa (modified_cam_clay)
};
inline constexpr int material_parameter_count = 5;

/// A parameter's value at each particle of a material: a spatially
/// correlated random field (random_field.hpp) generated once, at set-up,
/// over the initial positions of every particle of every body of the
/// material (bodies a stage adds included, so a fill of the same material
/// continues the ground's field), in the job's particle order; or a
/// function of the particle's initial position. The Material's own number
/// for the parameter is then its nominal value (the field's mean): what
/// the material-level uses read (absorbing boundaries' impedance,
/// plausibility warnings), not the particles.
struct VaryingParameter {
  MaterialParameter parameter = MaterialParameter::youngs_modulus;
  std::optional<RandomField> random_field;
  FieldOfPosition value;  ///< used when random_field is absent
};

struct Material {
  std::string name;  ///< for messages only
  /// Bulk density (dry material) or grain density rho_s (with hydraulic).
  double density = 1.0;
  double youngs_modulus = 1.0;
  double poisson_ratio = 0.0;
  Plasticity plasticity = LinearElastic{};
  std::optional<Hydraulic> hydraulic;
  /// Parameters that vary from particle to particle, each at most once
  /// (check_problem); empty: the material is homogeneous.
  std::vector<VaryingParameter> varying;
};

/// Initial fields of a body; each entry is a function of the particle's
/// initial position. Empty functions mean zero.
struct InitialFields {
  std::array<FieldOfPosition, 3> velocity;
  FieldOfPosition pore_pressure;
  /// Voigt order: xx, yy, zz, xy, yz, zx. Compression negative.
  std::array<FieldOfPosition, 6> effective_stress;
};

/// A plane polygon: vertices in order (either orientation), closed
/// implicitly; it must be simple (no two edges cross or touch) with
/// non-zero area. In a 2D problem its coordinates are (x, y).
struct Polygon {
  std::vector<std::array<double, 2>> vertices;
};

/// A polygon extruded along `axis` over [from, to]. The polygon's two
/// coordinates are the other two axes in order: axis z (2): (x, y);
/// axis y (1): (x, z); axis x (0): (y, z). 3D only.
struct Prism {
  Polygon polygon;
  int axis = 2;
  double from = 0.0;
  double to = 0.0;
};

/// Explicit particles: initial positions and volumes (m^3 in 3D, m^2 in 2D
/// (per metre of thickness), m in 1D (per unit cross-section)), one each.
struct ParticleList {
  std::vector<Vec3> positions;
  std::vector<double> volumes;
};

/// A body of one material filled with particles. Its shape is `box` unless
/// `polygon` (2D), `prism` (3D) or `points` is set (at most one of them).
/// A box is filled with `particles_per_cell` particles per axis per cell,
/// at sub-cell centres, of the cells of the grid that lie inside the box; a
/// polygon or prism at the sub-cell centres (of every cell) that lie inside
/// it or on its boundary; `points` gives its particles explicitly. A
/// particle position inside several bodies belongs to the first body that
/// lists it: a later body loses it (problem_warnings says how many), so no
/// place ever holds two particles. An earlier points body claims only its
/// own positions.
struct Body {
  int material = 0;  ///< index into Problem::materials
  Box box;
  std::optional<Polygon> polygon;
  std::optional<Prism> prism;
  std::optional<ParticleList> points;
  int particles_per_cell = 2;
  InitialFields initial;
};

/// Grid nodes a boundary condition applies to.
struct NodeSelection {
  bool all = false;
  Box box;  ///< closed box; used when !all and no polygon
  /// 2D: the nodes inside the polygon or on its boundary (within 1e-6 of
  /// the smallest cell size); replaces the box when set.
  std::optional<Polygon> polygon;
};

/// A viscous (Lysmer-Kuhlemeyer) absorbing boundary: at each selected node
/// the force C_a (v_in,a(t) - v_a) + the node's force at rest along every
/// axis a, with C_a = rho c_a times the node's share of the face (c the
/// P-wave speed along the normal, the S-wave speed along the others, of
/// `material`: the undrained P modulus E_oed + 1/Q with pore water).
/// v_in is the boundary's `velocity` (when given): the motion of a rock
/// outcrop, so the wave sent in is half of it (a compliant base). The force
/// at rest is the reaction the node needed in the first step its stage
/// runs: the static load stays carried, the dynamic part is absorbed.
struct Absorbing {
  int normal = 0;            ///< the face's normal axis
  std::size_t material = 0;  ///< index in Problem::materials: the medium beyond
};

/// Prescribed nodal velocity components and/or pore pressure.
struct Boundary {
  NodeSelection nodes;
  /// One entry per axis; std::nullopt leaves that component free.
  std::array<std::optional<FieldOfTime>, 3> velocity;
  bool has_velocity = false;  ///< any velocity component prescribed
  /// Per axis: the spec gave this velocity as an acceleration (integrated
  /// from rest at t = 0); messages then name `acceleration`.
  std::array<bool, 3> from_acceleration{false, false, false};
  std::optional<FieldOfTime> pore_pressure;
  /// When set, the prescribed pore pressure varies along the face: each
  /// node takes pore_pressure_field(its position, t) (a reservoir, p =
  /// gamma_w (h(t) - y)); `pore_pressure` must then be set too (the value
  /// at the origin: the checks of formulas use it).
  FieldOfSpaceTime pore_pressure_field;
  /// Axes along which the selected nodes move as one rigid, frictionless
  /// plate: each step their momenta and forces are summed, so they share one
  /// velocity component (Mandel's plates). A velocity prescribed on the same
  /// axis by any boundary wins.
  std::array<bool, 3> rigid{false, false, false};
  /// Coulomb friction of a wall: needs exactly one prescribed velocity
  /// component (the wall normal), the others free. Each step the tangential
  /// nodal velocity loses at most friction * |normal velocity change imposed
  /// by the wall| and is never reversed (a wall at rest tangentially).
  /// +infinity: no slip ("rough"). std::nullopt: no friction (free
  /// components untouched).
  std::optional<double> friction;
  /// A seepage face on these nodes (saturated runs): water may leave but
  /// not enter. Each step a node whose pressure would rise above zero is
  /// held at p = 0 (it drains); one below zero is left free (no flow in).
  /// Not with a prescribed pore_pressure on the same entry.
  bool seepage = false;
  /// Dashpots instead of prescribed velocities: `velocity` is then the
  /// input (outcrop) motion, not a constraint.
  std::optional<Absorbing> absorbing;
};

/// Surface load on one face of the particles inside `particles`.
/// Force = traction * (particle volume / its initial length along the face normal).
struct Traction {
  Box particles;  ///< closed box of initial positions; used when no polygon
  /// 2D: the particles whose initial position lies inside the polygon or on
  /// its boundary (as NodeSelection::polygon); replaces the box when set.
  std::optional<Polygon> polygon;
  int axis = 0;                         ///< face normal axis: 0 = x, 1 = y, 2 = z
  int side = +1;                        ///< +1 for "x+", -1 for "x-"
  std::array<FieldOfTime, 3> traction;  ///< Pa, per axis
  /// When set for an axis, the load varies along the face: each selected
  /// particle takes traction_field[a](its initial position, t) (a load that
  /// grows along x, a water load on a sloping face); `traction[a]` must
  /// then be set too (the value at the origin: the checks of formulas use
  /// it).
  std::array<FieldOfSpaceTime, 3> traction_field;
};

/// Water flowing across one face of the particles inside `particles`
/// (or `polygon`): a volumetric flux per unit area, m/s, positive into the
/// soil (rainfall infiltration, a recharge well, a drain when negative).
/// Mapped like a Traction, at the loaded face of each selected particle,
/// with the face area V / length0 (V0 / length0 in the quasi-static scheme).
struct Flux {
  Box particles;                   ///< closed box of initial positions; used when no polygon
  std::optional<Polygon> polygon;  ///< 2D: replaces the box when set
  int axis = 0;                    ///< face normal axis
  int side = +1;                   ///< +1 for "x+", -1 for "x-"
  /// m/s into the soil at (initial position, t).
  FieldOfSpaceTime rate;
  /// false: `rate` does not depend on x, evaluated once per step.
  bool rate_varies_in_space = false;
};

/// A pore pressure prescribed on one face of the particles inside
/// `particles` (or `polygon`): the soil's own surface wherever it lies in
/// the grid and as it moves (a drained ground surface, a reservoir, a river).
/// Each selected particle exchanges water with the face through the
/// half-particle between its centre and the face (a Robin condition,
/// docs/job-spec.md "where to put drained boundaries"): into the soil at
/// (k/gamma_w) (p_face - p_particle) / (l/2) per unit area, l the particle's
/// current length along the normal. A seepage face has p_face = 0 and only
/// lets water out.
struct SurfacePressure {
  Box particles;                   ///< closed box of initial positions; used when no polygon
  std::optional<Polygon> polygon;  ///< 2D: replaces the box when set
  int axis = 0;                    ///< face normal axis
  int side = +1;                   ///< +1 for "x+", -1 for "x-"
  /// Pa at (the face's current centre, t); empty with `seepage`.
  FieldOfSpaceTime pore_pressure;
  /// A seepage face: water leaves at p = 0, never enters.
  bool seepage = false;
};

/// Geostatic initial state of horizontally layered ground (verification §6).
/// The vertical axis is the axis of gravity (the only non-zero component);
/// "above" is against gravity. At every particle, from the bodies stacked
/// above it in its column (each with its mixture density rho, constant per
/// body):
///   total vertical stress  sigma_v  = -|g| * integral of rho up to the ground surface
///   pore pressure          p        = rho_f |g| * (depth below the water table)
///                                     (materials with `hydraulic`; 0 for dry ones)
///   effective stress       sigma'_v = sigma_v + p,  sigma'_h = K0 sigma'_v
///                          (both horizontal axes), no shear.
/// Dry materials (no `hydraulic`) model the ground above the water table
/// with their bulk density; every material with `hydraulic` must lie below
/// the table (the u-p model is fully saturated) and the table must not lie
/// above the ground surface. check_problem reports violations.
struct Geostatic {
  /// Water table: coordinate along the vertical axis, m. Absent: no free
  /// water, so no material may have `hydraulic`.
  std::optional<double> water_table;
  /// K0 = sigma'_h / sigma'_v for every material; absent: nu/(1-nu) of each
  /// material (the at-rest ratio of laterally confined linear elasticity).
  std::optional<double> k0;
  /// Per-material K0 (index = material), overriding `k0`; empty or
  /// std::nullopt entries fall back to `k0`.
  std::vector<std::optional<double>> material_k0;
};

/// Procedures that set the initial state of all bodies together.
struct InitialState {
  std::optional<Geostatic> geostatic;
};

/// The time integration scheme of a run (docs/schemes.md says which to use).
enum class Scheme {
  /// Forward Euler u-p, momentum-based MUSL (the seed paper). dt is bounded
  /// by the undrained wave speed and by the hydraulic diffusion limit.
  explicit_scheme,
  /// Momentum explicit, pore pressure implicit (a nodal pressure equation
  /// solved each step): dt is bounded by the skeleton's wave speed only.
  semi_implicit,
  /// No inertia; implicit u-p, backward Euler, Newton iterations: any dt is
  /// stable (consolidation over days to years).
  quasi_static,
};

/// Geometric growth of the quasi-static step: dt_0 = initial, dt_{n+1} =
/// min(max, growth * dt_n).
struct StepGrowth {
  double initial = 0.0;  ///< s, > 0
  double max = 0.0;      ///< s, >= initial
  double growth = 1.0;   ///< factor >= 1
};

/// Linear solver of the implicit schemes' sparse systems.
enum class LinearSolver {
  automatic,  ///< the scheme chooses by size (documented in docs/schemes.md)
  direct,     ///< sparse Cholesky / LDL^T (symmetric) or LU (SuiteSparse, Eigen)
  iterative,  ///< preconditioned conjugate gradients / BiCGSTAB (Eigen)
};

/// Convergence controls of the implicit schemes (ignored by the explicit one).
struct ImplicitControl {
  /// Newton converges when, for each equation (equilibrium and the mass
  /// balance), the residual norm falls below tolerance times the norm of
  /// the magnitudes of the terms that make it up (a load-scaled measure:
  /// it does not depend on how far the step started from equilibrium).
  double tolerance = 1e-8;
  int max_iterations = 25;  ///< Newton iterations per step before a cut-back
  int max_cutbacks = 8;     ///< halvings of a step before the run fails
  LinearSolver linear_solver = LinearSolver::automatic;
  double linear_tolerance = 1e-12;  ///< relative residual of iterative solves
  /// quasi_static: factor on the pressure-projection stabilisation tau =
  /// 1/(2G) of equal-order u-p (docs/schemes.md); 0 turns it off (tests only:
  /// near-incompressible water then shows the checkerboard it removes).
  double pressure_stabilisation = 1.0;
  /// quasi_static: Newton with the elastic stiffness at plastic points
  /// instead of the algorithmic (consistent) tangent; linear instead of
  /// quadratic convergence. Not in the JSON: for tests that compare the two.
  bool elastic_tangent = false;
};

/// What a run does when it finds the soil collapsing (time.on_collapse;
/// docs/job-spec.md "Collapse"): stop there (the run fails with a message
/// saying where and at what load), or report it and go on.
enum class CollapseAction { stop, go_on };

struct TimeControl {
  double end = 1.0;  ///< s, required
  /// s; the time the stage in force starts at (stage_problem sets it; 0 for
  /// a job's first stage): the step rules count steps over end - start.
  double start = 0.0;
  Scheme scheme = Scheme::explicit_scheme;
  std::optional<double> dt;  ///< s; absent: automatic
  /// quasi_static only: geometric growth instead of a fixed dt (dt absent).
  std::optional<StepGrowth> growth;
  double courant = 0.5;  ///< factor on the stable step when dt is automatic
  ImplicitControl implicit;
  /// Absent: stop in the quasi-static scheme (it cannot go past a limit
  /// load), go on in the dynamic schemes (a run-out is what they follow).
  std::optional<CollapseAction> on_collapse;
};

/// The action a run takes at a collapse: time.on_collapse, or the scheme's default.
inline CollapseAction collapse_action(const TimeControl& t) {
  if (t.on_collapse) return *t.on_collapse;
  return t.scheme == Scheme::quasi_static ? CollapseAction::stop : CollapseAction::go_on;
}

/// Factor of safety by strength reduction (quasi-static scheme; the job's
/// `strength_reduction`): after the last stage, the strength of every
/// Mohr-Coulomb and Drucker-Prager material is divided by F, c / F and
/// tan(phi) / F (the dilatancy angle kept at most the reduced friction
/// angle), F raised from 1 in steps of `increment` from the converged state
/// at the previous F, a step that does not converge halved until it is
/// below `resolution`. The factor of safety is the largest F that
/// converged (docs/job-spec.md "Strength reduction").
struct StrengthReduction {
  double increment = 0.1;     ///< first step of F
  double resolution = 0.005;  ///< F is bracketed to within this
  double max_factor = 10.0;   ///< F is not raised above this (the result is then "at least")
  /// Newton iterations of a trial F before it counts as not converged (each
  /// with a line search; time.implicit.max_iterations is the time steps').
  int max_iterations = 100;
  /// m: a trial that converges only after a particle has moved further
  /// than this since F = 1 counts as failed (the slide criterion); unset:
  /// slide_fraction of the soil's height (collapse_watch.hpp soil_height).
  std::optional<double> displacement_limit;
  static constexpr double slide_fraction = 0.005;
};

/// The contract name of a scheme ("explicit", "semi_implicit", "quasi_static"):
/// its row in the solver's table of schemes (src/schemes/table.hpp).
const char* scheme_name(Scheme s);

/// A profile: fields of the particles nearest to points along a line (the
/// api picks them: output.profiles in the job spec), sampled together.
struct ProfileLine {
  std::vector<std::int64_t> particles;  ///< global particle indices, one per point
  std::vector<Field> fields;
};

/// The average degree of consolidation of the ground (output.consolidation
/// in the job spec): with the excess pore pressure integrated over the
/// particles' initial volumes,
///   E(t) = sum over the counted particles of (p - p_steady(x)) V0,
///   U(t) = 1 - E(t) / E(from),
/// the fraction of the excess at `from` that has drained (Terzaghi's
/// average degree of consolidation in 1D). Counted: the particles in the
/// run whose material has pore water and whose initial position the
/// selection holds (every one when `all`).
struct ConsolidationRequest {
  /// s; > 0: sampled at `from` (t = 0: before the first step; later: at
  /// the end of the first step that reaches it), then at the end of the
  /// steps that reach from + k interval.
  double interval = 0.0;
  double from = 0.0;  ///< s; the reference instant: U(from) = 0
  /// Pa, the pore pressure once the consolidation is over (hydrostatic, or
  /// 0 without gravity), at the particle's current position; empty: 0.
  FieldOfPosition steady_pore_pressure;
  bool all = true;                 ///< count every particle with pore water; else the selection:
  Box particles;                   ///< closed box of initial positions; used when no polygon
  std::optional<Polygon> polygon;  ///< 2D: replaces the box when set
};

struct OutputRequest {
  std::vector<std::int64_t> series_particles;  ///< global particle indices
  std::vector<Field> series_fields;
  double series_interval = 0.0;        ///< s; <= 0: every step
  std::vector<Field> snapshot_fields;  ///< empty: all fields
  double snapshot_interval = 0.0;      ///< s; <= 0: no snapshots
  /// s; > 0: the force each boundary exerts on the soil, sampled at the end
  /// of the steps that reach each multiple of it (RunResult::reactions);
  /// <= 0: none.
  double reactions_interval = 0.0;
  /// Profiles, each sampled (like a series) at t = 0, at the end of the
  /// steps that reach each multiple of profile_interval (> 0: an interval)
  /// and at the end of the steps that reach each of profile_times (s,
  /// increasing, in the run; isochrones). One of the two when any. The
  /// quasi-static scheme's growing steps land on both exactly; fixed steps
  /// sample at the end of the first step that reaches the time.
  std::vector<ProfileLine> profiles;
  double profile_interval = 0.0;
  std::vector<double> profile_times;
  ConsolidationRequest consolidation;  ///< none unless its interval > 0
};

/// A later stage of a staged job (Problem::stages): from the end of the
/// stage before to `end`, with its changes. The state carries over; what a
/// stage does not set stays as it was (the job's top level is the first
/// stage). Lists it sets replace the whole list in force.
struct Stage {
  std::string name;  ///< for messages and progress
  double end = 0.0;  ///< s, absolute; after the previous stage's end
  /// Bodies whose particles join the run at the stage's start (a fill, a
  /// construction layer), with their initial fields; a body some stage adds
  /// is absent before it (and from the geostatic state).
  std::vector<int> add_bodies;
  /// Bodies whose particles leave the run at the stage's start (excavation).
  std::vector<int> remove_bodies;
  /// A body's new material at the stage's start: (body index, material
  /// index), e.g. elastic gravity loading, then Mohr-Coulomb. Its particles
  /// keep their stress, pore pressure, porosity, mass and displacement;
  /// their plastic strain and internal state variables start again from 0.
  /// The new material has the same density and pore water (hydraulic or
  /// not, porosity, fluid density) as the one in force.
  struct BodyMaterial {
    int body = 0;
    int material = 0;
  };
  std::vector<BodyMaterial> body_materials;
  std::optional<std::vector<Boundary>> boundaries;
  std::optional<std::vector<Traction>> tractions;
  std::optional<std::vector<Flux>> fluxes;
  std::optional<Vec3> gravity;
  /// The stage's time control (scheme, dt, courant, implicit); its `end`
  /// is ignored (the stage's own end rules).
  std::optional<TimeControl> time;
  std::optional<FieldOfTime> local_damping;
  /// At the stage's start, the particles' current positions become their
  /// initial ones (displacement and strain start again from zero; later
  /// selections by initial position use them): after a gravity-loading
  /// stage.
  bool reset_displacement = false;
};

struct Problem {
  int dimension = 1;  ///< 1 (uniaxial strain), 2 (plane strain) or 3
  Grid grid;
  ShapeFunction shape_function = ShapeFunction::linear;
  std::vector<Material> materials;
  std::vector<Body> bodies;
  Vec3 gravity{0.0, 0.0, 0.0};  ///< m/s^2
  std::vector<Boundary> boundaries;
  std::vector<Traction> tractions;
  std::vector<Flux> fluxes;  ///< saturated runs only (check_problem)
  /// Pore pressures on the faces of particles (saturated runs only).
  std::vector<SurfacePressure> surface_pressures;
  TimeControl time;
  OutputRequest output;
  /// Acceleration of gravity used for the unit weight of water gamma_w = rho_f * g.
  double gravity_constant = 9.81;
  /// Local (Cundall) damping coefficient in [0, 1) as a function of time
  /// (evaluated once per step, e.g. damping during a settling phase only);
  /// empty = none. A value outside [0, 1) fails the run at that step.
  FieldOfTime local_damping;
  InitialState initial_state;
  /// Later stages, in order (empty: one stage, the job itself, to
  /// time.end). stage_problem (hmpm/run.hpp) gives the Problem in force
  /// during each.
  std::vector<Stage> stages;
  std::string first_stage_name = "initial";  ///< the top level's stage name
  /// After the last stage: the factor of safety by strength reduction.
  std::optional<StrengthReduction> strength_reduction;
};

/// The time the whole job ends: the last stage's end (stages end in
/// order, check_problem), else time.end.
inline double job_end_time(const Problem& problem) {
  return problem.stages.empty() ? problem.time.end : problem.stages.back().end;
}

}  // namespace hmpm
