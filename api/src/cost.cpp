// cost.cpp — what a job will cost, computed before it runs: particles,
// nodes, steps from the chosen dt, memory, result-file estimates, and the
// steps and expected wall time of every time scheme. The wall-time model
// and its constants are here and nowhere else (docs/performance.md,
// "Wall-time estimate"). The parser checks the limits against it; the
// server shows and stores it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "cost_model.hpp"
#include "hmpm/api/job.hpp"
#include "hmpm/format.hpp"
#include "spec_reader.hpp"

namespace hmpm::api {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

std::int64_t to_count(double v) {
  if (!(v > 0)) return 0;
  if (v >= 9.2e18) return std::numeric_limits<std::int64_t>::max();
  return static_cast<std::int64_t>(v);
}

// ------------------------------------------------------- the wall-time model
// Work is counted in reference particle-steps: one particle-step of a 2D,
// linear-shape, elastic particle on one thread. Calibration gives the
// seconds one takes on this machine. The explicit constants are fitted on
// the examples; the implicit ones are first estimates to be replaced by
// measurements once the schemes run (docs/performance.md).
struct WallModel {
  /// A plastic material's return mapping, per particle-step.
  static constexpr double plastic_factor = 1.8;
  /// GIMP weights (the overlap of the particle's domain with each node's
  /// support) cost more than B-spline or linear ones.
  static constexpr double gimp_factor = 1.3;
  /// Per step whatever the size (phases, boundary values, progress).
  static constexpr double step_overhead = 12.0;
  /// Per run (set-up, first touch of the arrays, result files), seconds.
  static constexpr double run_overhead_s = 1e-3;
  /// Parallel efficiency once a run uses more than one thread.
  static constexpr double parallel_efficiency = 0.8;
  /// semi_implicit: assembling the pressure equation, per particle-step,
  /// on top of the explicit phases.
  static constexpr double pressure_assembly = 2.0;
  /// A sparse solve of n unknowns costs linear_solve * n^1.5 (2D nested
  /// dissection / preconditioned CG on a Laplacian-like matrix): the
  /// semi-implicit pressure equation.
  static constexpr double linear_solve = 0.1;
  /// quasi_static, fitted on the implicit examples (1 000-7 200 particles,
  /// CHOLMOD's LDL^T; bench/estimate.sh, docs/performance.md "Wall-time
  /// estimate"): linear solves per step (an elastic 1D step converges in
  /// one; elastic 2D steps took 2.0-3.7, a solve and the one that checks
  /// it, more where seepage faces or stages change; plastic steps about
  /// 4), the u-p tangent's assembly per solve and implicit particle weight
  /// (the explicit weight, its square root where above 1: a quadratic
  /// B-spline plastic particle costs 1.4x a linear elastic one per solve,
  /// not 3.4x, measured), a fixed part per solve (the factorisation's
  /// set-up) and
  /// the factorisation, up_solve * (unknowns)^1.5 (2D nested dissection).
  static constexpr double solves_per_step_1d = 1.0;
  static constexpr double solves_per_step = 2.5;
  static constexpr double solves_per_plastic_step = 4.0;
  static constexpr double tangent_assembly = 38.0;
  static constexpr double solve_overhead = 150.0;
  static constexpr double up_solve = 0.3;
  /// strength_reduction: the factor of safety assumed before the run (a
  /// typical slope's), the solves of a trial factor that converges and
  /// those of a failing one (at most strength_reduction.max_iterations).
  /// Measured with the trials' line search: converged trials took 9-34
  /// Newton iterations (mean 22; slope B of check_strength_reduction.py
  /// at 0.25 m cells); the failing ones end early when a solve is
  /// singular or a particle is lost, else at the ceiling: slope-safety's
  /// 11 trials took 306 solves, 5 converged and 6 failed.
  static constexpr double assumed_factor_of_safety = 1.5;
  static constexpr double solves_per_converged_trial = 20.0;
  static constexpr double solves_per_failing_trial = 30.0;
};

/// Cost of one particle in reference particle-steps: the nodes it talks to
/// times the components of each, relative to the reference's 4 x 2.
double particle_weight(const Problem& p, const Material& m) {
  const int d = std::clamp(p.dimension, 1, 3);
  const double per_axis = p.shape_function == ShapeFunction::linear ? 2.0 : 3.0;
  double w = std::pow(per_axis, d) * d / 8.0;
  if (p.shape_function == ShapeFunction::gimp) w *= WallModel::gimp_factor;
  if (!std::holds_alternative<LinearElastic>(m.plasticity)) w *= WallModel::plastic_factor;
  return w;
}

/// The particles of every body weighted by their cost, and the count.
struct Work {
  double weighted = 0.0;           ///< reference particle-steps per step
  double implicit_weighted = 0.0;  ///< the quasi-static tangent's weight, per solve
  double particles = 0.0;
  bool plastic = false;
};

Work particle_work(const Problem& p) {
  Work w;
  for (const Body& b : p.bodies) {
    Problem one;
    one.dimension = p.dimension;
    one.grid = p.grid;
    one.bodies.push_back(b);
    one.bodies.back().material = 0;
    one.materials.push_back(b.material >= 0 && b.material < static_cast<int>(p.materials.size())
                                ? p.materials[static_cast<std::size_t>(b.material)]
                                : Material{});
    const double n = static_cast<double>(count_particles(one));
    w.particles += n;
    const double weight = particle_weight(p, one.materials[0]);
    w.weighted += n * weight;
    w.implicit_weighted += n * (weight > 1 ? std::sqrt(weight) : weight);
    w.plastic =
        w.plastic || (n > 0 && !std::holds_alternative<LinearElastic>(one.materials[0].plasticity));
  }
  return w;
}

double grid_nodes(const Problem& p) {
  double nodes = 1;
  for (int a = 0; a < std::clamp(p.dimension, 1, 3); ++a) nodes *= p.grid.cells[a] + 1.0;
  return nodes;
}

/// Solver threads a run of `particles` uses when given `threads`: as
/// RunOptions::min_particles_per_thread decides in the solver.
double solver_threads(double particles, int threads) {
  const RunOptions defaults;
  const double usable =
      std::floor(particles / static_cast<double>(defaults.min_particles_per_thread));
  return std::clamp(usable, 1.0, static_cast<double>(std::max(threads, 1)));
}

/// Linear solves per quasi-static step.
double quasi_static_solves(const Problem& p, const Work& w) {
  if (w.plastic) return WallModel::solves_per_plastic_step;
  return p.dimension == 1 ? WallModel::solves_per_step_1d : WallModel::solves_per_step;
}

/// One quasi-static linear solve: the tangent's assembly, the fixed part
/// and the factorisation, in reference particle-steps.
double quasi_static_solve(const Problem& p, const Work& w, double speedup) {
  const int d = std::clamp(p.dimension, 1, 3);
  return WallModel::tangent_assembly * w.implicit_weighted / speedup + WallModel::solve_overhead +
         WallModel::up_solve * std::pow(grid_nodes(p) * (d + 1), 1.5);
}

/// Expected wall time of `steps` steps of `scheme`.
double wall_seconds(const Problem& p, Scheme scheme, double steps, const Calibration& cal) {
  const Work w = particle_work(p);
  const double threads = solver_threads(w.particles, cal.threads);
  const double speedup = threads > 1 ? threads * WallModel::parallel_efficiency : 1.0;
  const double explicit_step = w.weighted / speedup + WallModel::step_overhead;
  const double nodes = grid_nodes(p);
  double per_step = explicit_step;
  switch (scheme) {
    case Scheme::explicit_scheme:
      break;
    case Scheme::semi_implicit:
      per_step += WallModel::pressure_assembly * w.weighted / speedup +
                  WallModel::linear_solve * std::pow(nodes, 1.5);
      break;
    case Scheme::quasi_static:
      per_step =
          quasi_static_solves(p, w) * quasi_static_solve(p, w, speedup) + WallModel::step_overhead;
      break;
  }
  double work = steps * per_step;
  // strength_reduction (quasi-static, after the last stage): trial factors
  // from F = 1 in steps of `increment` up to the assumed factor of safety,
  // then a bisection of ceil(log2(increment / resolution)) trials; about
  // half of the bisection's trials converge (about 20 solves each), and each
  // failing trial about solves_per_failing_trial (at most
  // strength_reduction.max_iterations).
  if (p.strength_reduction && scheme == Scheme::quasi_static) {
    const StrengthReduction& sr = *p.strength_reduction;
    const double f = std::min(WallModel::assumed_factor_of_safety, sr.max_factor);
    const double bisections =
        std::max(0.0, std::ceil(std::log2(sr.increment / sr.resolution) - 1e-9));
    const double converged = 1 + std::ceil((f - 1) / sr.increment - 1e-9) + bisections / 2;
    const double failed = f < sr.max_factor ? bisections : 0.0;
    Work plastic = w;
    plastic.plastic = true;
    work += (converged * WallModel::solves_per_converged_trial +
             failed * std::min(WallModel::solves_per_failing_trial,
                               static_cast<double>(std::max(1, sr.max_iterations)))) *
            quasi_static_solve(p, plastic, speedup);
  }
  return WallModel::run_overhead_s + work * cal.seconds_per_particle_step;
}

// --------------------------------------------------- what limits each step
/// Materials some body uses.
std::vector<const Material*> used_materials(const Problem& p) {
  std::vector<const Material*> out;
  for (const Body& b : p.bodies)
    if (b.material >= 0 && b.material < static_cast<int>(p.materials.size()))
      out.push_back(&p.materials[static_cast<std::size_t>(b.material)]);
  return out;
}

double constrained_modulus(const Material& m) {
  const double nu = m.poisson_ratio;
  return m.youngs_modulus * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
}

double mixture_density(const Material& m) {
  if (!m.hydraulic) return m.density;
  const double n = m.hydraulic->porosity;
  return (1 - n) * m.density + n * m.hydraulic->fluid_density;
}

/// Storage Q = n/Kf + (1 - n)/Ks (1/Pa).
double storage(const Hydraulic& h) {
  const double grains = std::isfinite(h.solid_bulk_modulus) && h.solid_bulk_modulus > 0
                            ? (1 - h.porosity) / h.solid_bulk_modulus
                            : 0.0;
  return h.porosity / h.fluid_bulk_modulus + grains;
}

/// The physical scales of a problem that decide which scheme fits it.
struct Scales {
  double h = inf;              ///< smallest cell size, m
  double length = 0;           ///< largest extent of the bodies, m
  double skeleton_speed = 0;   ///< max sqrt(E_oed / rho), m/s
  double consolidation = inf;  ///< min length^2 / c_v, s (inf when dry)
};

Scales scales(const Problem& p) {
  Scales s;
  const int d = std::clamp(p.dimension, 1, 3);
  for (int a = 0; a < d; ++a) {
    if (p.grid.cells[a] > 0) s.h = std::min(s.h, (p.grid.max[a] - p.grid.min[a]) / p.grid.cells[a]);
    for (const Body& b : p.bodies) s.length = std::max(s.length, b.box.max[a] - b.box.min[a]);
  }
  for (const Material* m : used_materials(p)) {
    const double e_oed = constrained_modulus(*m);
    s.skeleton_speed = std::max(s.skeleton_speed, std::sqrt(e_oed / mixture_density(*m)));
    if (m->hydraulic) {
      const double gamma_w = m->hydraulic->fluid_density * p.gravity_constant;
      const double c_v =
          m->hydraulic->hydraulic_conductivity / (gamma_w * (1 / e_oed + storage(*m->hydraulic)));
      if (c_v > 0) s.consolidation = std::min(s.consolidation, s.length * s.length / c_v);
    }
  }
  return s;
}

std::string fmt(double v) {
  return format_significant(v, 3);
}

// ------------------------------------------------------ the memory model
// Bytes, from the solver's arrays (solver/src/state/): what each particle
// and node holds, the nodal sums each extra solver thread keeps in a
// private buffer of the whole grid, the series the run keeps until it ends
// and one snapshot's arrays. Compared with the peak RSS of `hmpm run` in
// docs/performance.md ("Memory estimate").
struct MemoryModel {
  /// The process itself, the spec and its parse, thread stacks touched.
  static constexpr double base = 16.0 * (1 << 20);
  /// Internal state variables per particle assumed for a plastic model.
  static constexpr double plastic_state_variables = 4;
  /// std::vector doubling: a series of n values holds up to 2n while it
  /// grows (measured: 1.3n at the end of the runs of bench/memory.py).
  static constexpr double growth = 2.0;
  /// Set-up's temporaries per particle (initial positions for the
  /// geostatic state and the formula checks, the geostatic columns).
  static constexpr double setup_per_particle = 48;
};

/// Samples of the profiles (output.profiles): t = 0, each interval and
/// each listed time.
double profile_rows(const Problem& p) {
  const OutputRequest& o = p.output;
  if (o.profiles.empty()) return 0;
  const double listed = static_cast<double>(o.profile_times.size());
  if (!(o.profile_interval > 0)) return 1 + listed;
  return std::floor(stage_problem(p, stage_count(p) - 1).time.end / o.profile_interval + 1e-9) + 1 +
         listed;
}

/// Values of one profile sample: every component of every field of every point.
double profile_values(const Problem& p) {
  double values = 0;
  for (const ProfileLine& line : p.output.profiles) {
    double per_point = 0;
    for (Field f : line.fields) per_point += field_components(f, p.dimension);
    values += per_point * static_cast<double>(line.particles.size());
  }
  return values;
}

bool any_fluid(const Problem& p) {
  return std::any_of(p.materials.begin(), p.materials.end(),
                     [](const Material& m) { return m.hydraulic.has_value(); });
}

double memory_bytes(const Problem& p, const CostEstimate& c, double threads) {
  const double d = std::clamp(p.dimension, 1, 3);
  const bool fluid = any_fluid(p);
  const std::vector<const Material*> used = used_materials(p);
  const bool plastic = std::any_of(used.begin(), used.end(), [](const Material* m) {
    return !std::holds_alternative<LinearElastic>(m->plasticity);
  });
  // x, x0, v; mass, volume; stress, strain (Voigt); material, cell.
  double particle = 8 * (3 * d + 2 + 12) + 2 + 4 * d;
  if (p.shape_function == ShapeFunction::gimp) particle += 16;  // half_length, box_inverse
  if (fluid) particle += 8 * (3 + d);  // pressure, pressure_out, porosity, darcy
  if (plastic) particle += 8 * MemoryModel::plastic_state_variables;
  // Varying parameters (solver/src/materials/varying.hpp): each value, and
  // what it derives: Lame's constants (E), the whole strength constants (c,
  // phi; Mohr-Coulomb's are 48 doubles), k/gamma_w (k). The fields are
  // generated over the particles at set-up (a value and a lattice node each).
  bool strength = false, any_varying = false;
  for (const Material& m : p.materials)
    for (const VaryingParameter& v : m.varying) {
      any_varying = true;
      particle += 8;
      if (v.parameter == MaterialParameter::youngs_modulus) particle += 16;
      if (v.parameter == MaterialParameter::hydraulic_conductivity) particle += 8;
      strength = strength || v.parameter == MaterialParameter::cohesion ||
                 v.parameter == MaterialParameter::friction_angle;
    }
  if (strength) particle += 8 * 48;
  if (any_varying) particle += 8 * 4;
  // Scattered sums (mass, momentum, force, remap; storage, pressure, flux)
  // per node, in the grid and in every extra thread's buffer; the grid
  // also keeps velocity and acceleration (and dp).
  const double sums = 8 * (1 + 3 * d) + (fluid ? 24 : 0);
  const double grid = sums + 16 * d + (fluid ? 8 : 0);
  // The 3-node shape functions in 2D and 3D scatter mass, momentum and
  // force through a 64-byte record per node and thread (NodeRecord).
  const double records = p.shape_function != ShapeFunction::linear && d >= 2 ? 64 * threads : 0;
  const double nodes = static_cast<double>(c.nodes);
  const double particles = static_cast<double>(c.particles);
  double bytes = MemoryModel::base + particles * (particle + MemoryModel::setup_per_particle) +
                 nodes * (grid + (threads - 1) * sums + records);
  // The series: every value of every row, kept until the end of the run.
  const OutputRequest& o = p.output;
  double per_row = 1;  // time
  for (Field f : o.series_fields)
    per_row += field_components(f, p.dimension) * static_cast<double>(o.series_particles.size());
  if (c.series_rows > 0)
    bytes += MemoryModel::growth * 8 * per_row * static_cast<double>(c.series_rows);
  // The profiles: every value of every line at every profile time.
  bytes += MemoryModel::growth * 8 * profile_values(p) * profile_rows(p);
  // The reactions: a time and a vector per boundary per sample.
  if (c.reaction_rows > 0)
    bytes += MemoryModel::growth * 8 *
             (1.0 + static_cast<double>(p.boundaries.size() * p.dimension)) *
             static_cast<double>(c.reaction_rows);
  // One snapshot's arrays (3 components per vector, 6 per tensor), filled
  // while the file is written.
  if (c.snapshots > 0) {
    double values = 2;  // volume, mass
    for (Field f : o.snapshot_fields.empty() ? default_snapshot_fields(p) : o.snapshot_fields)
      values += field_components(f, 3);
    bytes += particles * (8 * values + 4);
  }
  return bytes;
}

}  // namespace

namespace cost {

double growth_step_count(double end, const StepGrowth& g) {
  if (!(g.initial > 0) || !(end > 0)) return 0;
  const double max = std::max(g.max, g.initial);
  if (g.growth <= 1 || max <= g.initial) return std::ceil(end / g.initial - 1e-9);
  // Growing steps until dt reaches max: k, covering initial (g^k - 1)/(g - 1).
  const double k = std::ceil(std::log(max / g.initial) / std::log(g.growth) - 1e-12);
  const double covered = g.initial * (std::pow(g.growth, k) - 1) / (g.growth - 1);
  if (covered >= end)
    return std::ceil(std::log(1 + end * (g.growth - 1) / g.initial) / std::log(g.growth) - 1e-9);
  return k + std::ceil((end - covered) / max - 1e-9);
}

SchemeCost scheme_cost(const Problem& problem, Scheme scheme, const Calibration& calibration) {
  Problem p = problem;  // shallow enough: the bodies' formulas are shared functions
  const bool own = scheme == problem.time.scheme;
  p.time.scheme = scheme;
  if (!own) {
    p.time.dt.reset();
    p.time.growth.reset();
  }
  SchemeCost c;
  c.scheme = scheme;
  const StableStep s = stable_step(p);
  const double steps = static_cast<double>(s.steps);
  c.dt = s.chosen;
  c.fixed = s.fixed;
  c.steps = to_count(steps);
  c.wall_seconds = wall_seconds(p, scheme, steps, calibration);
  return c;
}

std::string scheme_advice(const Problem& p, std::int64_t max_steps,
                          const Calibration& calibration) {
  const Scales s = scales(p);
  const double limit = static_cast<double>(max_steps);
  const StableStep current = stable_step(p);
  const double crossing = s.skeleton_speed > 0 ? s.length / s.skeleton_speed : inf;
  // Consolidation long compared with any wave: inertia plays no part.
  if (p.time.scheme != Scheme::quasi_static && p.time.end > 100 * crossing) {
    const SchemeCost q = scheme_cost(p, Scheme::quasi_static, calibration);
    if (static_cast<double>(q.steps) <= limit) {
      Problem automatic = p;  // the plan the solver follows when dt is absent
      automatic.time.scheme = Scheme::quasi_static;
      automatic.time.dt.reset();
      automatic.time.growth.reset();
      const StepGrowth g = stable_step(automatic).plan;
      std::string a = "use time.scheme 'quasi_static' (no inertia, any step is stable): about " +
                      format_count(static_cast<double>(q.steps)) +
                      " steps with dt {\"initial\": " + fmt(g.initial) +
                      ", \"max\": " + fmt(g.max) + ", \"growth\": " + fmt(g.growth) + "}, about " +
                      fmt(q.wall_seconds) + " s; the end time is " + fmt(p.time.end / crossing) +
                      " times the time a skeleton wave takes to cross the soil (" + fmt(s.length) +
                      " m / " + fmt(s.skeleton_speed) + " m/s = " + fmt(crossing) + " s)";
      if (std::isfinite(s.consolidation))
        a += ", and consolidation over " + fmt(s.length) + " m takes about " +
             fmt(s.consolidation) + " s (H^2/c_v)";
      return a + " (docs/schemes.md)";
    }
  }
  // Water (its stiffness or the hydraulic diffusion) limits the explicit
  // step, and the skeleton alone would allow a much larger one.
  if (p.time.scheme == Scheme::explicit_scheme) {
    const SchemeCost semi = scheme_cost(p, Scheme::semi_implicit, calibration);
    if (static_cast<double>(semi.steps) <= limit && semi.dt > 2 * current.chosen) {
      const std::string what =
          current.hydraulic < current.mechanical
              ? "the explicit hydraulic diffusion limit (" + fmt(current.hydraulic) + " s)"
              : "the undrained wave speed " + fmt(current.wave_speed) + " m/s with the water";
      return "use time.scheme 'semi_implicit' (pore pressure implicit): about " +
             format_count(static_cast<double>(semi.steps)) + " steps of " + fmt(semi.dt) +
             " s, about " + fmt(semi.wall_seconds) +
             " s; its step is limited by the skeleton's wave speed sqrt(E_oed/rho) = " +
             fmt(s.skeleton_speed) + " m/s, the explicit one by " + what + " (docs/schemes.md)";
    }
  }
  return "";
}

}  // namespace cost

CostEstimate estimate_cost(const Problem& p, const Calibration& calibration) {
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
  const StableStep step = stable_step(p);
  c.dt = step.chosen;
  // A staged job: the steps of every stage, to the last one's end, and
  // the wall time of each stage in its own scheme with its own bodies.
  double steps = static_cast<double>(step.steps);
  double job_end = p.time.end;
  double wall = 0;
  const std::size_t stages = stage_count(p);
  for (std::size_t k = 0; k < stages; ++k) {
    Problem stage = k == 0 ? p : stage_problem(p, k);
    const double stage_steps =
        k == 0 ? steps : static_cast<double>(std::max<std::int64_t>(1, stable_step(stage).steps));
    if (k > 0) {
      steps += stage_steps;
      job_end = stage.time.end;
    }
    if (k + 1 < stages) stage.strength_reduction.reset();  // after the last stage only
    wall += wall_seconds(stage, stage.time.scheme, stage_steps, calibration) -
            (k > 0 ? WallModel::run_overhead_s : 0.0);
  }
  c.steps = to_count(steps);
  c.particle_steps = to_count(static_cast<double>(c.particles) * steps);
  const OutputRequest& o = p.output;
  double rows = 0;
  if (!o.series_particles.empty() && !o.series_fields.empty())
    rows =
        o.series_interval <= c.dt ? steps + 1 : std::floor(job_end / o.series_interval + 1e-9) + 1;
  c.series_rows = to_count(rows);
  const double snaps =
      o.snapshot_interval > 0 ? std::floor(job_end / o.snapshot_interval + 1e-9) + 1 : 0;
  c.snapshots = to_count(snaps);
  const double reaction_rows =
      o.reactions_interval > 0 ? std::floor(job_end / o.reactions_interval + 1e-9) : 0;
  c.reaction_rows = to_count(reaction_rows);
  const double reaction_values = static_cast<double>(p.boundaries.size()) * dim;
  double series_values = 0;
  for (Field f : o.series_fields) series_values += field_components(f, dim);
  series_values *= static_cast<double>(o.series_particles.size());
  // Snapshot arrays have 3 components per vector in every dimension; no
  // fields listed means every field.
  double snapshot_values = 2;  // volume, material
  for (Field f : o.snapshot_fields.empty() ? default_snapshot_fields(p) : o.snapshot_fields)
    snapshot_values += field_components(f, 3);
  // ~22 characters per number in series.json and again in series.csv;
  // base64 float64 in the VTU files is 8 * 4/3 bytes per number.
  const double bytes =
      4096 + rows * (1 + series_values) * 2 * 22 + reaction_rows * (1 + reaction_values) * 2 * 22 +
      profile_rows(p) * profile_values(p) * 2 * 22 +
      snaps * (static_cast<double>(c.particles) * (snapshot_values * 32.0 / 3.0 + 16) + 4096);
  c.output_bytes = to_count(bytes);
  const double threads = solver_threads(static_cast<double>(c.particles), calibration.threads);
  c.threads = static_cast<int>(threads);
  c.memory_bytes = to_count(memory_bytes(p, c, threads));

  c.scheme = p.time.scheme;
  c.calibration = calibration;
  c.wall_seconds = wall;
  for (Scheme s : {Scheme::explicit_scheme, Scheme::semi_implicit, Scheme::quasi_static})
    c.schemes.push_back(s == p.time.scheme
                            ? SchemeCost{s, c.steps, c.dt, step.fixed, c.wall_seconds}
                            : cost::scheme_cost(p, s, calibration));
  return c;
}

}  // namespace hmpm::api
