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
// Where the code lives: set-up in setup.hpp, the phases in phases/ (one file
// each: particle_to_grid, grid, grid_to_particle, stress_and_flux,
// pore_pressure), failure reports in failures.hpp, output in output.hpp,
// the time loop in time_loop.hpp. Explicitly instantiated per dimension in
// simulation_instance.cpp, so every hot loop is compiled for fixed sizes
// and inlined within one translation unit. No phase allocates, calls a
// virtual function or looks anything up by string.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "boundary/constraints.hpp"
#include "boundary/tractions.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "interrupt.hpp"
#include "materials/material.hpp"
#include "parallel.hpp"
#include "shape.hpp"
#include "state/grid.hpp"
#include "state/particles.hpp"

namespace hmpm {

template <int Dim, class Shape>
class ExplicitScheme;
template <int Dim, class Shape>
class SemiImplicitScheme;
template <int Dim, class Shape>
class QuasiStaticScheme;

template <int Dim, class Shape>
class Simulation {
 public:
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;
  using Out = Scatter<Dim>;

  /// Sets the run up; honours options.cancel and options.wall_time_limit_s
  /// while doing so (throws SetupInterrupted, see interrupt.hpp).
  Simulation(const Problem& problem, const RunOptions& options);

  /// Runs the time loop to problem.time.end (time_loop.hpp).
  RunResult run(const RunOptions& options);

 private:
  friend class ExplicitScheme<Dim, Shape>;
  friend class SemiImplicitScheme<Dim, Shape>;
  friend class QuasiStaticScheme<Dim, Shape>;

  // ------------------------------------------------------------ set-up (setup.hpp)
  void setup_grid();
  void setup_materials();
  void setup_particles();
  void setup_geostatic();
  /// Staged jobs: the particles of bodies a stage adds leave the run until
  /// then (set-up, before the geostatic state).
  void setup_stages();

  // ------------------------------------------------------------ stages (stages.hpp)
  /// Makes stage k the one in force: its Problem, its bodies' particles,
  /// the constraints, loads and reactions compiled for them.
  void enter_stage(std::size_t k);
  /// The particles of the bodies in force at stage k, and slot_ to match.
  void move_stage_particles(std::size_t k);
  /// Stage::reset_displacement: x0 = x, strain zero.
  void reset_displacement();
  void balance_initial_pressure_state();

  // ------------------------------------------------------------ phases (phases/)
  void clear_grid();
  void map_particles_to_grid(const Out& out, std::size_t begin, std::size_t end);
  void map_particles_to_grid_by_rows(const Out& out, std::size_t begin, std::size_t end);
  void compute_nodal_pressure(double t);
  void map_pore_pressure_force(const Out& out, std::size_t begin, std::size_t end);
  void apply_surface_loads(double t);
  /// Water across particle faces at time t (Problem::fluxes) added to the
  /// nodal flux; nothing without fluxes.
  void apply_boundary_fluxes(double t);
  void update_nodal_momentum(double t, double dt);
  void update_particle_velocities_and_remap(const Out& out, std::size_t begin, std::size_t end,
                                            double dt);
  void compute_remapped_nodal_velocity(double t_new, double dt);
  template <bool Fluid, bool Plastic, bool ScatterFlux = true>
  void update_particle_stress_and_fluid_flux(const Out& out, std::size_t begin, std::size_t end,
                                             double dt);
  void update_nodal_pressure(double t_new, double dt);
  void update_particle_pressure_and_position(std::size_t begin, std::size_t end, double dt);
  /// Moves particle p: x += dt v, v = sum N_i v_i (the Lagrangian nodal
  /// velocity) gathered by the caller.
  __attribute__((always_inline)) inline void displace_particle(std::size_t p, Vec v, double dt);
  /// A particle outside the grid: back onto the face if a wall holds it there.
  bool return_to_wall(std::size_t p);
  static Mat active_stress(const Voigt& s);

  // ------------------------------------------------------------ pressure projection
  // The semi-implicit scheme's phases (phases/pressure_projection.hpp).
  void map_predicted_velocity(const Out& out, std::size_t begin, std::size_t end, double dt);
  void map_predicted_fluid_flux(const Out& out, std::size_t begin, std::size_t end);
  void assemble_pressure_laplacian(std::size_t begin, std::size_t end, double dt, double* box,
                                   std::uint8_t* active, std::int64_t first);
  void map_pressure_increment_force(const Out& out, std::size_t begin, std::size_t end);

  // ------------------------------------------------------------ threads
  // Thread 0 accumulates nodal sums straight into the grid; every other
  // thread into a private buffer that is added to the grid after the phase,
  // buffers in thread order, so sums are reproducible for a thread count.

  Out scatter_of(int t) {
    NodeRange* touched = &touched_[static_cast<std::size_t>(t)];
    NodeRecord* records = records_[static_cast<std::size_t>(t)].data();
    if (t == 0) return {grid_.pointers(), touched, records};
    return {buffers_[static_cast<std::size_t>(t - 1)].pointers(), touched, records};
  }

  void setup_threads(int threads) {
    pool_ = std::make_unique<ThreadPool>(threads);
    buffers_.resize(static_cast<std::size_t>(threads - 1));
    touched_.assign(static_cast<std::size_t>(threads), NodeRange{0, grid_.count - 1});
    for (NodalSums<Dim>& b : buffers_) b.resize(static_cast<std::size_t>(grid_.count), fluid_);
    records_.resize(static_cast<std::size_t>(threads));
    if constexpr (StencilT::factorised)  // map_particles_to_grid_by_rows's scratch
      for (auto& r : records_) r.assign(static_cast<std::size_t>(grid_.count), NodeRecord{});
  }

  /// Runs phase(scatter, begin, end) over particle chunks, then adds the
  /// private buffers of the nodal sums in `fields` (a mask of nodal::bit) to
  /// the grid, in thread order, over the nodes each thread touched only,
  /// clearing them as it goes. Particles created in cell order give each
  /// thread a band of the grid, so the reduction costs about one band per
  /// extra thread, not a whole grid. Phases that scatter nothing
  /// (fields == 0) give each particle's result regardless of the thread
  /// that computes it: they take blocks dynamically, so a slower virtual CPU
  /// does less of the work.
  template <class Phase>
  void for_particles(unsigned fields, Phase&& phase) {
    auto chunk = [&](int t, std::size_t b, std::size_t e) { phase(scatter_of(t), b, e); };
    if (!fields) {
      pool_->for_blocks(particles_.size(), block_of(particles_.size(), particle_block), chunk);
      return;
    }
    pool_->for_ranges(particles_.size(), chunk);
    if (buffers_.empty()) return;
    // Every node of the buffers' bands, split over the threads.
    std::int64_t lo = grid_.count, hi = -1;
    for (std::size_t t = 1; t < touched_.size(); ++t) {
      lo = std::min(lo, touched_[t].lo);
      hi = std::max(hi, touched_[t].hi);
    }
    if (hi < lo) return;
    auto reduce = [&](int, std::size_t b, std::size_t e) {
      for (std::size_t t = 1; t < touched_.size(); ++t) {
        const auto first = std::max(b, static_cast<std::size_t>(touched_[t].lo));
        const auto last = std::min(e, static_cast<std::size_t>(touched_[t].hi + 1));
        if (first < last) grid_.add_and_clear(buffers_[t - 1], fields, first, last);
      }
    };
    const auto offset = static_cast<std::size_t>(lo);
    auto band = [&](int t, std::size_t b, std::size_t e) { reduce(t, offset + b, offset + e); };
    const auto nodes = static_cast<std::size_t>(hi - lo + 1);
    pool_->for_blocks(nodes, block_of(nodes, node_block), band);
  }

  /// Runs f(begin, end) over blocks of the nodes [0, grid count), taken by
  /// the threads dynamically (node loops whose iterations are independent:
  /// no node loop sums across nodes, so the results do not depend on the
  /// split).
  template <class F>
  void for_nodes(F&& f) {
    if (!pool_) {  // set-up, before run() starts the threads
      f(std::int64_t{0}, grid_.count);
      return;
    }
    auto chunk = [&](int, std::size_t b, std::size_t e) {
      f(static_cast<std::int64_t>(b), static_cast<std::int64_t>(e));
    };
    const auto nodes = static_cast<std::size_t>(grid_.count);
    pool_->for_blocks(nodes, block_of(nodes, node_block), chunk);
  }

  /// Block sizes of dynamically shared loops: at most a few hundred
  /// microseconds of work, and at least 16 blocks per thread, so the faster
  /// thread can take up the slack (small runs get small blocks).
  static constexpr std::size_t particle_block = 4096, node_block = 8192;
  std::size_t block_of(std::size_t n, std::size_t largest) const {
    return std::clamp<std::size_t>(n / (16 * static_cast<std::size_t>(pool_->size())), 64, largest);
  }

  /// The stencil of particle p at its current position.
  template <bool Grad = true>
  inline void stencil_of(std::size_t p, StencilT& s) const {
    s.template compute<Grad>(particles_.x[p], grid_.origin, grid_.inv_h, grid_.cells, grid_.stride,
                             box_of(p));
  }

  /// In the step: the first phase locates each particle's stencil (and
  /// records the cells), the later phases, before particles move, reuse them.
  template <bool Grad, bool Located>
  __attribute__((always_inline)) inline void stencil_in_step(std::size_t p, StencilT& s) {
    s.template compute<Grad, Located>(particles_.x[p], grid_.origin, grid_.inv_h, grid_.cells,
                                      grid_.stride, box_of(p), particles_.cell[p].data());
  }

  /// The factors of particle p's stencil (StencilT::factorised shape functions).
  template <bool Located, bool Grad = true>
  __attribute__((always_inline)) inline void axes_in_step(std::size_t p,
                                                          typename StencilT::Axes& f) {
    StencilT::template axes<Located, Grad>(particles_.x[p], grid_.origin, grid_.inv_h, grid_.cells,
                                           grid_.stride, box_of(p), particles_.cell[p].data(), f);
  }

  /// The factors axes_ahead keeps: those of the particle and of the two after it.
  using AxesAhead = typename StencilT::Axes[4];

  /// In a loop over particles [begin, end), particle p's factors (computed
  /// two particles before) after computing particle p + 2's: the chain of
  /// dependent operations of a stencil's factors then overlaps the sums of
  /// the particles before (software pipelining: one particle ahead bought
  /// 4-9 % of a 2D step, two about 2-5 % more). Nothing computed for the
  /// node-by-node shape functions (!StencilT::factorised); Grad = false:
  /// weights only.
  template <bool Located, bool Grad = true>
  __attribute__((always_inline)) inline const typename StencilT::Axes& axes_ahead(
      std::size_t p, std::size_t begin, std::size_t end, AxesAhead& ahead) {
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
      return {particles_.half_length[p], particles_.box_inverse[p]};
    else
      return shape::box_of(particles_, p);
  }

  // ------------------------------------------------------------ failures (failures.hpp)
  // Called from hot loops only on the failure path. Threads may find
  // failures in any order; the lowest particle index wins, so the report is
  // the same for any thread count.
  void record_failure(std::size_t p, std::string what, std::string hint);
  void fail_run(std::string what, std::string hint);
  void fail_nonfinite(std::size_t p, const char* what);
  void fail_left_grid(std::size_t p);
  void fail_volume(std::size_t p, double j);
  /// False (and a failure of the run naming the formula's place in the
  /// spec) when a traction or boundary value is not finite at time t.
  bool loads_finite_at(double t);
  static std::string number(double v);

  // ------------------------------------------------------------ reactions (phases/reactions.hpp)
  /// A node component whose constraint force is charged to a boundary.
  struct ReactionCharge {
    std::int64_t node;
    int axis;
    int boundary;     ///< index in Problem::boundaries
    bool prescribed;  ///< a prescribed velocity (else friction or a rigid tie)
    /// Friction: the wall's flag of the node sticking this step (null otherwise).
    const std::uint8_t* stuck;
  };
  void setup_reactions();
  /// Keeps `force` at the charged components (the semi-implicit step's
  /// pressure-increment force, gone from the grid by the time of the tally).
  void record_reaction_extra_force(const std::vector<Vec>& force);
  /// reaction_ from the constrained nodal accelerations of this step; with
  /// the forces record_reaction_extra_force kept, when `with_extra`.
  void tally_reactions(bool with_extra);

  // ------------------------------------------------------------ output (output.hpp)
  void fill_snapshot(Snapshot& snap, const std::vector<Field>& fields) const;
  void sample_series(Series& series, double t) const;
  /// Appends the excess pore pressure at time t to `c`
  /// (OutputRequest::consolidation): of every particle in the run when the
  /// request counts all, else of `counted` (job particle indices).
  void sample_consolidation(RunResult::Consolidation& c, const std::vector<std::int64_t>& counted,
                            double t) const;

  const Problem& job_;  ///< the job as given, every stage (Problem::stages)
  /// The Problem in force: stage_problem(job_, stage_) (stages.hpp).
  Problem problem_;
  std::size_t stage_ = 0;
  // Stages that add or remove bodies: the particles of bodies not in the
  // run (yet, or any more), each particle's slot by its job index (-1: not
  // in the run), the first job index of each body.
  ParticleState<Dim> dormant_;
  std::vector<std::int64_t> slot_;
  std::vector<std::int64_t> body_begin_;
  std::int64_t job_particles_ = 0;  ///< particles of every body of the job
  SetupInterrupt interrupt_;        ///< set-up's stop checks; its start is the run's start
  GridState<Dim> grid_;
  ParticleState<Dim> particles_;
  std::vector<MaterialConstants> constants_;
  std::vector<double> inv_ks_, inv_kf_;
  Constraints constraints_;
  std::vector<TractionLoad> tractions_;
  std::vector<FluxLoad> fluxes_;  ///< saturated runs only
  // Reactions (set up only when the output asks for them): per node
  // component the boundary charged with it (-1: none), the charged
  // components, a force kept per charge, the step's force of each boundary,
  // and whether the time loop samples the current step.
  std::vector<int> reaction_owner_;
  std::vector<ReactionCharge> charges_;
  std::vector<double> charge_extra_;
  std::vector<Vec3> reaction_;
  bool reactions_due_ = false;
  Vec gravity_ = Vec::Zero();
  Vec grid_max_ = Vec::Zero();
  bool fluid_ = false;
  bool plastic_ = false;               ///< any material with a return mapping
  int state_variables_ = 0;            ///< internal state variables per particle (materials/)
  std::vector<std::string> warnings_;  ///< set-up findings the result reports
  double mass_tolerance_ = 0.0;
  StableStep stable_;

  std::unique_ptr<ThreadPool> pool_;
  std::vector<NodalSums<Dim>> buffers_;           ///< threads 1.. : private nodal sums
  std::vector<NodeRange> touched_;                ///< per thread, from the step's first phase
  std::vector<std::vector<NodeRecord>> records_;  ///< per thread: particle-to-grid scratch

  std::mutex failure_mutex_;
  double damping_ = 0.0;  // local damping coefficient of the current step
  bool failed_ = false;   // written under failure_mutex_, read between phases
  std::int64_t failure_particle_ = -1;
  std::string failure_;
  std::string failure_hint_;
};

}  // namespace hmpm
