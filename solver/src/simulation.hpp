// simulation.hpp — the state of one u-p MPM run and its phases (internal).
//
// One Simulation<Dim, Shape> owns the particle and grid state of a run
// (state/), the compiled constraints (boundary/), the material constants
// (materials/) and the threads, and offers the phases a time scheme
// (schemes/) composes into a step. The equations (u-p formulation):
//
//   mixture momentum   rho a = div(sigma' - p I) + rho b
//   fluid mass balance Q dp/dt = -div v - div w,   Q = (1-n)/Ks + n/Kf
//   Darcy              w = -k/(rho_f g) (grad p - rho_f b + rho_f a)
//
// Pore pressure lives on the grid during a step. Particles carry it from step
// to step as a transported state updated with nodal increments (FLIP), and
// report the value interpolated from the nodal field. Because everything the
// equations see is the nodal field, the particle-level checkerboard mode of
// one-particle-per-cell layouts cannot enter the solution, and the linear
// steady state is reproduced exactly at every particle. The Darcy term
// rho_f a uses the acceleration of the re-mapped nodal velocities of the
// same step, interpolated to the particle (see docs/verification.md for why
// this is stable, and for the compressible-fluid regime where the u-p
// equations themselves are not: darcy_inertia_growth_ratio in
// materials/material.hpp).
//
// The parts (ExaMPM's pattern): the state a step changes (GridState,
// ParticleState), the Model it reads (the Problem in force, material
// constants, compiled boundaries and loads), the Threads with their private
// nodal sums (state/threads.hpp), the Failures (failures.hpp) and the
// reaction tally. A scheme is given a StepContext, references to these
// parts, and composes the phases, free functions over a StepContext, into a
// step; nothing is a friend of the Simulation, which keeps only set-up, the
// stages and the time loop.
//
// Where the code lives: set-up in setup.hpp, the phases in phases/ (one file
// each: particle_to_grid, grid, grid_to_particle, stress_and_flux,
// pore_pressure, pressure_projection, reactions), failure reports in
// failures.hpp, output in output.hpp, the time loop in time_loop.hpp. Explicitly instantiated per
// dimension in simulation_instance.cpp, so every hot loop is compiled for fixed sizes and inlined
// within one translation unit. No phase allocates, calls a virtual function or looks anything up by
// string.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "boundary/constraints.hpp"
#include "boundary/surface_pressures.hpp"
#include "boundary/tractions.hpp"
#include "collapse_watch.hpp"
#include "failures.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "interrupt.hpp"
#include "materials/material.hpp"
#include "shape.hpp"
#include "state/grid.hpp"
#include "state/particles.hpp"
#include "state/threads.hpp"

namespace hmpm {

/// What a step reads and does not change: the Problem in force (a stage's),
/// the material constants, the compiled boundaries and loads. Set up by the
/// Simulation, compiled again when a stage begins.
template <int Dim>
struct RunModel {
  using Vec = VecD<Dim>;
  Problem problem;  ///< the Problem in force: stage_problem(job, stage) (stages.hpp)
  std::vector<MaterialConstants> constants;
  std::vector<double> inv_ks, inv_kf;
  /// Compiled boundaries; their per-step flags (a friction node sticking, an
  /// absorbing base's forces at rest) change during a step.
  mutable Constraints constraints;
  std::vector<TractionLoad> tractions;
  std::vector<FluxLoad> fluxes;                        ///< saturated runs only
  std::vector<SurfacePressureLoad> surface_pressures;  ///< saturated runs only
  Vec gravity = Vec::Zero();
  Vec grid_max = Vec::Zero();
  bool fluid = false;
  bool plastic = false;     ///< any material with a return mapping
  int state_variables = 0;  ///< internal state variables per particle (materials/)
  double mass_tolerance = 0.0;
  StableStep stable;
};

/// A node component whose constraint force is charged to a boundary.
struct ReactionCharge {
  std::int64_t node;
  int axis;
  int boundary;     ///< index in Problem::boundaries
  bool prescribed;  ///< a prescribed velocity (else friction or a rigid tie)
  /// Friction: the wall's flag of the node sticking this step (null otherwise).
  const std::uint8_t* stuck;
};

/// Reactions (set up only when the output asks for them; phases/reactions.hpp):
/// per node component the boundary charged with it (-1: none), the charged
/// components, a force kept per charge, the step's force of each boundary,
/// and whether the time loop samples the current step.
struct ReactionTally {
  std::vector<int> owner;
  std::vector<ReactionCharge> charges;
  std::vector<double> extra;
  std::vector<Vec3> force;
  bool due = false;
};

/// What a time scheme is given: references to the parts of the run it may
/// touch, and the stencil of a particle. Cheap to copy; each scheme keeps
/// one, whose `damping` is the local damping of its current step.
template <int Dim, class Shape>
struct StepContext {
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;
  using Out = Scatter<Dim>;
  /// The factors axes_ahead keeps: those of the particle and of the two after it.
  using AxesAhead = typename StencilT::Axes[4];

  GridState<Dim>& grid;
  ParticleState<Dim>& particles;
  const RunModel<Dim>& model;
  Threads<Dim, Shape>& threads;
  Failures& failures;
  ReactionTally& reactions;
  double damping = 0.0;  ///< local damping coefficient of the current step

  /// Runs phase(scatter, begin, end) over the particles (Threads::for_particles).
  template <class Phase>
  void for_particles(unsigned fields, Phase&& phase) {
    threads.for_particles(grid, particles.size(), fields, phase);
  }
  /// Runs f(begin, end) over blocks of the nodes (Threads::for_nodes).
  template <class F>
  void for_nodes(F&& f) {
    threads.for_nodes(grid.count, f);
  }

  /// The stencil of particle p at its current position.
  template <bool Grad = true>
  inline void stencil_of(std::size_t p, StencilT& s) const {
    s.template compute<Grad>(particles.x[p], grid.origin, grid.inv_h, grid.cells, grid.stride,
                             box_of(p));
  }

  /// In the step: the first phase locates each particle's stencil (and
  /// records the cells), the later phases, before particles move, reuse them.
  template <bool Grad, bool Located>
  __attribute__((always_inline)) inline void stencil_in_step(std::size_t p, StencilT& s) const {
    s.template compute<Grad, Located>(particles.x[p], grid.origin, grid.inv_h, grid.cells,
                                      grid.stride, box_of(p), particles.cell[p].data());
  }

  /// The factors of particle p's stencil (StencilT::factorised shape functions).
  template <bool Located, bool Grad = true>
  __attribute__((always_inline)) inline void axes_in_step(std::size_t p,
                                                          typename StencilT::Axes& f) const {
    StencilT::template axes<Located, Grad>(particles.x[p], grid.origin, grid.inv_h, grid.cells,
                                           grid.stride, box_of(p), particles.cell[p].data(), f);
  }

  /// In a loop over particles [begin, end), particle p's factors (computed
  /// two particles before) after computing particle p + 2's: the chain of
  /// dependent operations of a stencil's factors then overlaps the sums of
  /// the particles before (software pipelining; docs/performance.md).
  /// Nothing computed for the node-by-node shape functions
  /// (!StencilT::factorised); Grad = false: weights only.
  template <bool Located, bool Grad = true>
  __attribute__((always_inline)) inline const typename StencilT::Axes& axes_ahead(
      std::size_t p, std::size_t begin, std::size_t end, AxesAhead& ahead) const {
    if constexpr (StencilT::factorised) {
      if (p == begin) {
        axes_in_step<Located, Grad>(p, ahead[0]);
        if (p + 1 < end) axes_in_step<Located, Grad>(p + 1, ahead[1]);
      }
      if (p + 2 < end) axes_in_step<Located, Grad>(p + 2, ahead[(p + 2 - begin) & 3]);
    }
    return ahead[(p - begin) & 3];
  }

  /// Particle p's GIMP box (zero for the other shape functions).
  inline shape::Box box_of(std::size_t p) const {
    if constexpr (std::is_same_v<Shape, shape::Gimp>)  // the arrays are there
      return {particles.half_length[p], particles.box_inverse[p]};
    else
      return shape::box_of(particles, p);
  }
};

/// The stress tensor of Voigt components (xx, yy, zz, xy, yz, zx) in Dim
/// dimensions.
template <int Dim>
inline Eigen::Matrix<double, Dim, Dim> active_stress(const Voigt& s) {
  Eigen::Matrix<double, Dim, Dim> m;
  if constexpr (Dim == 1) {
    m(0, 0) = s[0];
  } else if constexpr (Dim == 2) {
    m << s[0], s[3], s[3], s[1];
  } else {
    m << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
  }
  return m;
}

template <int Dim, class Shape>
class Simulation {
 public:
  using Vec = VecD<Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;

  /// Sets the run up; honours options.cancel and options.wall_time_limit_s
  /// while doing so (throws SetupInterrupted, see interrupt.hpp).
  Simulation(const Problem& problem, const RunOptions& options);

  /// Runs the time loop to problem.time.end (time_loop.hpp).
  RunResult run(const RunOptions& options);

 private:
  /// The parts a scheme is given.
  StepContext<Dim, Shape> context() {
    return {grid_, particles_, model_, threads_, failures_, reactions_};
  }

  // ------------------------------------------------------------ set-up (setup.hpp)
  void setup_grid();
  void setup_materials();
  void setup_particles();
  /// The particles' own constants of the parameters that vary (materials/
  /// varying.hpp), from the fields over every body's particles.
  void setup_varying(const std::vector<BodyLayout>& layouts);
  void setup_geostatic();
  /// Staged jobs: the particles of bodies a stage adds leave the run until
  /// then (set-up, before the geostatic state).
  void setup_stages();
  void balance_initial_pressure_state();

  // ------------------------------------------------------------ stages (stages.hpp)
  /// Makes stage k the one in force: its Problem, its bodies' particles,
  /// the constraints, loads and reactions compiled for them.
  void enter_stage(std::size_t k);
  /// The particles of the bodies in force at stage k, and slot_ to match.
  void move_stage_particles(std::size_t k);
  /// Stage::reset_displacement: x0 = x, strain zero.
  void reset_displacement();
  /// Stage::body_materials: the bodies' particles (in the run or not) take
  /// their new material; plastic strain and internal state start from 0.
  void switch_materials(const Stage& stage);

  // ------------------------------------------------------------ after the stages
  /// Problem::strength_reduction from the state at time t
  /// (strength_reduction.hpp): the factor of safety into `result`.
  void reduce_strength(RunResult& result, double t, const RunOptions& options);
  /// A collapse the explicit and semi-implicit schemes follow, if `w`
  /// finds one at time t (time_loop.hpp): true when the run stops there.
  bool report_dynamic_collapse(CollapseWatch<Dim>& w, double t);

  // ------------------------------------------------------------ output (output.hpp)
  void fill_snapshot(Snapshot& snap, const std::vector<Field>& fields) const;
  /// Particle p's pore pressure minus the steady one at its current position
  /// (OutputRequest::consolidation's steady_pore_pressure; 0 without it), 0
  /// where its material has no pore water: the output field
  /// excess_pore_pressure and the sum of sample_consolidation.
  double excess_pore_pressure(std::size_t p) const;
  void sample_series(Series& series, double t) const;
  /// Particle p's value of a material parameter: its own where it varies,
  /// else its material's.
  double parameter_at(std::size_t p, MaterialParameter k) const;
  /// Field::void_ratio or Field::preconsolidation_pressure at particle p:
  /// its Cam-Clay state variable, 0 at particles of other models.
  double cam_clay_value(std::size_t p, Field f) const;
  /// Adds the run warning of a quasi-static run with linear shape
  /// functions whose particles crossed cell boundaries (time_loop.hpp).
  void report_cell_crossings(RunResult& result) const;
  /// Appends the excess pore pressure at time t to `c`
  /// (OutputRequest::consolidation): of every particle in the run when the
  /// request counts all, else of `counted` (job particle indices).
  void sample_consolidation(RunResult::Consolidation& c, const std::vector<std::int64_t>& counted,
                            double t) const;

  const Problem& job_;  ///< the job as given, every stage (Problem::stages)
  std::size_t stage_ = 0;
  // Stages that add or remove bodies: the particles of bodies not in the
  // run (yet, or any more), each particle's slot by its job index (-1: not
  // in the run), the first job index of each body.
  ParticleState<Dim> dormant_;
  std::vector<std::int64_t> slot_;
  std::vector<std::int64_t> body_begin_;
  std::int64_t job_particles_ = 0;     ///< particles of every body of the job
  SetupInterrupt interrupt_;           ///< set-up's stop checks; its start is the run's start
  std::vector<std::string> warnings_;  ///< set-up findings the result reports

  // The parts (StepContext).
  GridState<Dim> grid_;
  ParticleState<Dim> particles_;
  RunModel<Dim> model_;
  Threads<Dim, Shape> threads_;
  Failures failures_;
  ReactionTally reactions_;
};

}  // namespace hmpm
