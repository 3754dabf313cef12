// simulation.hpp — the explicit u-p MPM time step (internal).
//
// One Simulation<Dim, Shape> owns the particle and grid state of a run and
// advances it with the momentum-based MUSL cycle of the seed paper (§3.4),
// extended with the fluid mass balance of the u-p formulation:
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
// equations themselves are not: darcy_inertia_growth_ratio in materials.hpp).
//
// The step reads as named phases (see `step`). No phase allocates, calls a
// virtual function or looks anything up by string.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "geostatic.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials.hpp"
#include "objective_rate.hpp"
#include "parallel.hpp"
#include "particle_layout.hpp"
#include "shape.hpp"
#include "state.hpp"

namespace hmpm {

template <int Dim, class Shape>
class Simulation {
 public:
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;

  explicit Simulation(const Problem& problem) : problem_(problem) {
    setup_grid();
    setup_materials();
    setup_particles();
    setup_boundaries();
    setup_tractions();
    setup_geostatic();
  }

  RunResult run(const RunOptions& options);

 private:
  struct VelocityConstraint {
    std::vector<std::int64_t> nodes;
    std::array<bool, 3> fixed{false, false, false};
    std::array<const FieldOfTime*, 3> fn{nullptr, nullptr, nullptr};
    int normal = 0;  ///< the prescribed axis (used with friction)
    /// Side of the material for friction: +1 when the wall is the grid's min
    /// face along `normal` (material at larger coordinates), -1 for the max
    /// face, 0 for a wall inside the grid (either side).
    int inward = 0;
    double friction = 0;  ///< Coulomb coefficient mu; inf = no slip
    /// Per node: tangential velocity cancelled by friction this step.
    /// Empty when the boundary has no friction.
    std::vector<std::uint8_t> stuck;
  };

  // ------------------------------------------------------------ set-up
  void setup_grid() {
    for (int a = 0; a < Dim; ++a) {
      grid_.cells[a] = problem_.grid.cells[a];
      grid_.origin[a] = problem_.grid.min[a];
      grid_.h[a] = (problem_.grid.max[a] - problem_.grid.min[a]) / grid_.cells[a];
      grid_.inv_h[a] = 1.0 / grid_.h[a];
    }
    for (int a = 0; a < Dim; ++a) grid_max_[a] = problem_.grid.max[a];
    grid_.count = 1;
    for (int a = 0; a < Dim; ++a) {
      grid_.stride[a] = grid_.count;
      grid_.count *= grid_.cells[a] + 1;
    }
  }

  void setup_materials() {
    for (const Material& m : problem_.materials) {
      constants_.push_back(material_constants(m, problem_.gravity_constant));
      const Hydraulic h = m.hydraulic.value_or(Hydraulic{});
      inv_ks_.push_back(std::isinf(h.solid_bulk_modulus) ? 0.0 : 1.0 / h.solid_bulk_modulus);
      inv_kf_.push_back(1.0 / h.fluid_bulk_modulus);
      fluid_ = fluid_ || m.hydraulic.has_value();
      plastic_ = plastic_ || constants_.back().model != Model::linear_elastic;
    }
    for (const ProblemIssue& w : problem_warnings(problem_))
      warnings_.push_back(w.where + ": " + w.message);
    for (int a = 0; a < Dim; ++a) gravity_[a] = problem_.gravity[a];
  }

  void setup_particles() {
    const bool gimp = std::is_same_v<Shape, shape::Gimp>;
    particles_.resize(static_cast<std::size_t>(count_particles(problem_)), fluid_, gimp);
    grid_.resize(fluid_);
    std::size_t p = 0;
    double cell_volume = 1.0;
    for (int a = 0; a < Dim; ++a) cell_volume *= grid_.h[a];
    for (const Body& body : problem_.bodies) {
      const BodyLayout layout = body_layout(problem_, body);
      const MaterialConstants& mc = constants_[static_cast<std::size_t>(body.material)];
      const int ppc = body.particles_per_cell;
      const double v0 = cell_volume / std::pow(ppc, Dim);
      for (double z : layout.coords[2])
        for (double y : layout.coords[1])
          for (double x : layout.coords[0]) {
            const Vec3 x3{x, y, z};
            for (int a = 0; a < Dim; ++a) particles_.x[p][a] = x3[a];
            particles_.x0[p] = particles_.x[p];
            particles_.volume[p] = v0;
            particles_.mass[p] = mc.mixture_density * v0;
            particles_.material[p] = static_cast<std::uint16_t>(body.material);
            if (gimp) particles_.half_length[p] = 0.5 / ppc;
            const InitialFields& init = body.initial;
            for (int a = 0; a < Dim; ++a)
              if (init.velocity[a]) particles_.v[p][a] = init.velocity[a](x3);
            for (int c = 0; c < 6; ++c)
              if (init.effective_stress[c]) particles_.stress[p][c] = init.effective_stress[c](x3);
            if (fluid_ && mc.saturated) {
              const double p0 = init.pore_pressure ? init.pore_pressure(x3) : 0.0;
              particles_.pressure[p] = p0;
              particles_.pressure_out[p] = p0;
              particles_.porosity[p] = mc.porosity;
            }
            ++p;
          }
    }
  }

  bool node_in_box(std::int64_t i, const Box& box) const {
    const Vec xn = grid_.node_position(i);
    for (int a = 0; a < Dim; ++a) {
      const double tol = 1e-9 * grid_.h[a];
      if (xn[a] < box.min[a] - tol || xn[a] > box.max[a] + tol) return false;
    }
    return true;
  }

  void setup_boundaries() {
    for (const Boundary& b : problem_.boundaries) {
      std::vector<std::int64_t> nodes;
      for (std::int64_t i = 0; i < grid_.count; ++i)
        if (b.nodes.all || node_in_box(i, b.nodes.box)) nodes.push_back(i);
      if (b.has_velocity) {
        VelocityConstraint vc;
        vc.nodes = nodes;
        for (int a = 0; a < Dim; ++a)
          if (b.velocity[a]) {
            vc.fixed[a] = true;
            vc.fn[a] = &*b.velocity[a];
            vc.normal = a;  // unique when friction is given (check_problem)
          }
        if (b.friction) {
          vc.friction = *b.friction;
          vc.stuck.assign(vc.nodes.size(), 0);
          const int n = vc.normal;
          const double tol = 1e-9 * grid_.h[n];
          if (!b.nodes.all && b.nodes.box.max[n] <= grid_.origin[n] + tol) vc.inward = 1;
          if (!b.nodes.all && b.nodes.box.min[n] >= grid_max_[n] - tol) vc.inward = -1;
        }
        velocity_bcs_.push_back(std::move(vc));
      }
      if (b.rigid[0] || b.rigid[1] || b.rigid[2]) rigid_ties_.push_back({nodes, b.rigid});
      if (b.pore_pressure && fluid_) pressure_bcs_.push_back({std::move(nodes), &*b.pore_pressure});
    }
    if (!fluid_) return;
    prescribed_axes_.assign(static_cast<std::size_t>(grid_.count), 0);
    for (const VelocityConstraint& bc : velocity_bcs_)
      for (int a = 0; a < Dim; ++a)
        if (bc.fixed[a])
          for (std::int64_t i : bc.nodes) prescribed_axes_[static_cast<std::size_t>(i)] |= std::uint8_t(1u << a);
    for (const RigidTie& tie : rigid_ties_)
      for (int a = 0; a < Dim; ++a)
        if (tie.axes[a])
          for (std::int64_t i : tie.nodes) prescribed_axes_[static_cast<std::size_t>(i)] |= std::uint8_t(1u << a);
  }

  /// Geostatic initial state (Problem::initial_state.geostatic): effective
  /// stress and pore pressure from the layered closed form at every particle.
  /// The reported pressure is the closed form; the transported pressure state
  /// is then corrected so that the nodal pressure the first step computes
  /// from it (a storage-weighted average, biased by a fraction of a cell at
  /// boundary nodes where particles lie on one side only) is the hydrostatic
  /// nodal field itself. Its interpolation then gives back the closed form at
  /// every particle, so pressure, effective stress and weight balance at
  /// every node and the ground stays at rest.
  void setup_geostatic() {
    if (!problem_.initial_state.geostatic) return;
    const GeostaticState g = geostatic_state(problem_);
    for (std::size_t p = 0; p < particles_.size(); ++p) {
      geostatic_voigt(g, p, particles_.stress[p].data());
      if (fluid_ && constants_[particles_.material[p]].saturated) {
        particles_.pressure[p] = g.pressure[p];
        particles_.pressure_out[p] = g.pressure[p];
      }
    }
    if (fluid_) balance_initial_pressure_state();
  }

  /// Richardson iteration on the particle pressure state s until the nodal
  /// pressure mapped from it interpolates back to the reported pressure at
  /// every saturated particle: s += p_out - N W s (N W is similar to a
  /// symmetric matrix with eigenvalues in [0, 1], so it converges wherever
  /// the target is an interpolated nodal field; about 100 sweeps to
  /// round-off, independent of the grid size). Set-up only.
  void balance_initial_pressure_state() {
    double scale = 0.0;
    for (double v : particles_.pressure_out) scale = std::max(scale, std::abs(v));
    if (scale == 0.0) return;
    StencilT s;
    double checkpoint = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < 500; ++iteration) {
      std::fill(grid_.storage.begin(), grid_.storage.end(), 0.0);
      std::fill(grid_.pressure.begin(), grid_.pressure.end(), 0.0);
      for (std::size_t p = 0; p < particles_.size(); ++p) {
        const std::uint16_t mat = particles_.material[p];
        if (!constants_[mat].saturated) continue;
        stencil_of<false>(p, s);
        const double n = particles_.porosity[p];
        const double qv = ((1.0 - n) * inv_ks_[mat] + n * inv_kf_[mat]) * particles_.volume[p];
        for (int k = 0; k < StencilT::N; ++k) {
          grid_.storage[s.node[k]] += s.w[k] * qv;
          grid_.pressure[s.node[k]] += s.w[k] * qv * particles_.pressure[p];
        }
      }
      compute_nodal_pressure(0.0);
      double residual = 0.0;
      for (std::size_t p = 0; p < particles_.size(); ++p) {
        if (!constants_[particles_.material[p]].saturated) continue;
        stencil_of<false>(p, s);
        double p_hat = 0.0;
        for (int k = 0; k < StencilT::N; ++k) p_hat += s.w[k] * grid_.pressure[s.node[k]];
        const double r = particles_.pressure_out[p] - p_hat;
        particles_.pressure[p] += r;
        residual = std::max(residual, std::abs(r));
      }
      if (residual <= 1e-15 * scale) break;
      // Where the target is not an interpolated nodal field (B-splines next
      // to the clamped boundary) the residual stalls: stop when 50 sweeps
      // have not halved it.
      if (iteration % 50 == 0) {
        if (residual > 0.5 * checkpoint) break;
        checkpoint = residual;
      }
    }
    std::fill(grid_.storage.begin(), grid_.storage.end(), 0.0);
    std::fill(grid_.pressure.begin(), grid_.pressure.end(), 0.0);
  }

  void setup_tractions() {
    const std::vector<Vec3> x0 = initial_positions(problem_);
    for (const Traction& t : problem_.tractions) {
      TractionLoad load;
      load.source = &t;
      load.axis = t.axis;
      load.side = t.side;
      for (std::size_t p = 0; p < x0.size(); ++p) {
        bool inside = true;
        for (int a = 0; a < Dim; ++a)
          inside = inside && x0[p][a] >= t.particles.min[a] - 1e-12 &&
                   x0[p][a] <= t.particles.max[a] + 1e-12;
        if (!inside) continue;
        load.particles.push_back(static_cast<std::int64_t>(p));
        // Initial length along the face normal: the cell size over the body's
        // particles per cell, recovered from the initial volume per axis.
        load.length0.push_back(std::pow(particles_.volume[p], 1.0 / Dim));
        load.volume0.push_back(particles_.volume[p]);
      }
      tractions_.push_back(std::move(load));
    }
    // Particles of a body are not cubes when cells are not; use the cell size
    // along the normal over particles per cell when available.
    for (TractionLoad& load : tractions_)
      for (std::size_t k = 0; k < load.particles.size(); ++k) {
        const auto p = static_cast<std::size_t>(load.particles[k]);
        double ppc_volume = 1.0;
        for (int a = 0; a < Dim; ++a) ppc_volume *= grid_.h[a];
        const double n_per_axis = std::round(std::pow(ppc_volume / particles_.volume[p], 1.0 / Dim));
        load.length0[k] = grid_.h[load.axis] / std::max(n_per_axis, 1.0);
      }
  }

  // ------------------------------------------------------------ the step
  /// Advances the state from t to t + dt. Sets failure_ on the first problem.
  void step(double t, double dt) {
    damping_ = problem_.local_damping ? problem_.local_damping(t) : 0.0;
    if (!(damping_ >= 0.0 && damping_ < 1.0)) {  // checked before the step changes anything
      fail_run("local_damping is " + number(damping_) + " at t = " + number(t) + " s, outside [0, 1)",
               "keep the local_damping formula between 0 and 1 (exclusive) at all times");
      return;
    }
    clear_grid();
    for_particles(kMass | kMomentum | kForce | (fluid_ ? kStorage | kPressure : 0u),
                  [&](const Scatter& out, std::size_t b, std::size_t e) { map_particles_to_grid(out, b, e); });
    if (fluid_) {
      compute_nodal_pressure(t);
      for_particles(kForce, [&](const Scatter& out, std::size_t b, std::size_t e) {
        map_pore_pressure_force(out, b, e);
      });
    }
    apply_tractions(t);
    update_nodal_momentum(t, dt);
    for_particles(kRemap, [&](const Scatter& out, std::size_t b, std::size_t e) {
      update_particle_velocities_and_remap(out, b, e, dt);
    });
    compute_remapped_nodal_velocity(t + dt, dt);
    if (fluid_) {
      for_particles(kFlux, [&](const Scatter& out, std::size_t b, std::size_t e) {
        if (plastic_)
          update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/true>(out, b, e, dt);
        else
          update_particle_stress_and_fluid_flux</*Fluid=*/true, /*Plastic=*/false>(out, b, e, dt);
      });
      update_nodal_pressure(t + dt, dt);
      for_particles(0u, [&](const Scatter&, std::size_t b, std::size_t e) {
        update_particle_pressure_and_position(b, e, dt);
      });
    } else {
      for_particles(0u, [&](const Scatter& out, std::size_t b, std::size_t e) {
        if (plastic_)
          update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/true>(out, b, e, dt);
        else
          update_particle_stress_and_fluid_flux</*Fluid=*/false, /*Plastic=*/false>(out, b, e, dt);
      });
    }
  }

  // ------------------------------------------------------------ threads
  // Thread 0 accumulates nodal sums straight into the grid; every other
  // thread into a private buffer that is added to the grid after the phase,
  // buffers in thread order, so sums are reproducible for a thread count.
  enum : unsigned { kMass = 1, kMomentum = 2, kForce = 4, kRemap = 8, kStorage = 16, kPressure = 32, kFlux = 64 };

  /// Nodes [lo, hi] that a thread's particle chunk touches this step.
  struct NodeRange {
    std::int64_t lo, hi;
  };

  struct Scatter {
    double* mass;
    Vec* momentum;
    Vec* force;
    Vec* remap;
    double* storage;
    double* pressure;
    double* flux;
    NodeRange* touched;  ///< set by the step's first phase (particles do not move before the last)
  };

  /// A thread's private nodal sums. Zero outside a phase: the reduction
  /// that adds them to the grid also clears what it added.
  struct ScatterBuffer {
    std::vector<double> mass, storage, pressure, flux;
    std::vector<Vec> momentum, force, remap;
  };

  Scatter scatter_of(int t) {
    NodeRange* touched = &touched_[static_cast<std::size_t>(t)];
    if (t == 0)
      return {grid_.mass.data(), grid_.momentum.data(), grid_.force.data(), grid_.remap.data(),
              grid_.storage.data(), grid_.pressure.data(), grid_.flux.data(), touched};
    ScatterBuffer& b = buffers_[static_cast<std::size_t>(t - 1)];
    return {b.mass.data(), b.momentum.data(), b.force.data(), b.remap.data(),
            b.storage.data(), b.pressure.data(), b.flux.data(), touched};
  }

  void setup_threads(int threads) {
    pool_ = std::make_unique<ThreadPool>(threads);
    buffers_.resize(static_cast<std::size_t>(threads - 1));
    touched_.assign(static_cast<std::size_t>(threads), NodeRange{0, grid_.count - 1});
    const auto n = static_cast<std::size_t>(grid_.count);
    for (ScatterBuffer& b : buffers_) {
      b.mass.assign(n, 0.0); b.momentum.assign(n, Vec::Zero()); b.force.assign(n, Vec::Zero());
      b.remap.assign(n, Vec::Zero());
      if (fluid_) { b.storage.assign(n, 0.0); b.pressure.assign(n, 0.0); b.flux.assign(n, 0.0); }
    }
  }

  /// Runs phase(scatter, begin, end) over particle chunks, then adds the
  /// private buffers of `fields` to the grid, in thread order, over the
  /// nodes each thread touched only, clearing them as it goes. Particles
  /// created in cell order give each thread a band of the grid, so the
  /// reduction costs about one band per extra thread, not a whole grid.
  /// Phases that scatter nothing (fields == 0) give each particle's result
  /// regardless of the thread that computes it: they take blocks
  /// dynamically, so a slower virtual CPU does less of the work.
  template <class Phase>
  void for_particles(unsigned fields, Phase&& phase) {
    auto chunk = [&](int t, std::size_t b, std::size_t e) { phase(scatter_of(t), b, e); };
    if (!fields) {
      pool_->for_blocks(particles_.size(), block_of(particles_.size(), kParticleBlock), chunk);
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
        ScatterBuffer& buf = buffers_[t - 1];
        const auto first = std::max(b, static_cast<std::size_t>(touched_[t].lo));
        const auto last = std::min(e, static_cast<std::size_t>(touched_[t].hi + 1));
        for (std::size_t i = first; i < last; ++i) {
          if (fields & kMass) { grid_.mass[i] += buf.mass[i]; buf.mass[i] = 0.0; }
          if (fields & kMomentum) { grid_.momentum[i] += buf.momentum[i]; buf.momentum[i].setZero(); }
          if (fields & kForce) { grid_.force[i] += buf.force[i]; buf.force[i].setZero(); }
          if (fields & kRemap) { grid_.remap[i] += buf.remap[i]; buf.remap[i].setZero(); }
          if (fields & kStorage) { grid_.storage[i] += buf.storage[i]; buf.storage[i] = 0.0; }
          if (fields & kPressure) { grid_.pressure[i] += buf.pressure[i]; buf.pressure[i] = 0.0; }
          if (fields & kFlux) { grid_.flux[i] += buf.flux[i]; buf.flux[i] = 0.0; }
        }
      }
    };
    const auto offset = static_cast<std::size_t>(lo);
    auto band = [&](int t, std::size_t b, std::size_t e) { reduce(t, offset + b, offset + e); };
    const auto nodes = static_cast<std::size_t>(hi - lo + 1);
    pool_->for_blocks(nodes, block_of(nodes, kNodeBlock), band);
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
    pool_->for_blocks(nodes, block_of(nodes, kNodeBlock), chunk);
  }

  /// Block sizes of dynamically shared loops: at most a few hundred
  /// microseconds of work, and at least 16 blocks per thread, so the faster
  /// thread can take up the slack (small runs get small blocks).
  static constexpr std::size_t kParticleBlock = 4096, kNodeBlock = 8192;
  std::size_t block_of(std::size_t n, std::size_t largest) const {
    return std::clamp<std::size_t>(n / (16 * static_cast<std::size_t>(pool_->size())), 64, largest);
  }

  /// The stencil of particle p at its current position.
  template <bool Grad = true>
  inline void stencil_of(std::size_t p, StencilT& s) const {
    s.template compute<Grad>(particles_.x[p], grid_.origin, grid_.inv_h, grid_.cells, grid_.stride,
              particles_.half_length.empty() ? 0.0 : particles_.half_length[p]);
  }

  /// In the step: the first phase locates each particle's stencil (and
  /// records the cells), the later phases, before particles move, reuse them.
  template <bool Grad, bool Located>
  inline void stencil_in_step(std::size_t p, StencilT& s) {
    s.template compute<Grad, Located>(particles_.x[p], grid_.origin, grid_.inv_h, grid_.cells,
                                      grid_.stride,
                                      particles_.half_length.empty() ? 0.0 : particles_.half_length[p],
                                      particles_.cell[p].data());
  }

  void clear_grid() {
    for_nodes([&](std::int64_t b, std::int64_t e) {
      std::fill(grid_.mass.begin() + b, grid_.mass.begin() + e, 0.0);
      std::fill(grid_.momentum.begin() + b, grid_.momentum.begin() + e, Vec::Zero());
      std::fill(grid_.force.begin() + b, grid_.force.begin() + e, Vec::Zero());
      std::fill(grid_.remap.begin() + b, grid_.remap.begin() + e, Vec::Zero());
      if (fluid_) {
        std::fill(grid_.storage.begin() + b, grid_.storage.begin() + e, 0.0);
        std::fill(grid_.pressure.begin() + b, grid_.pressure.begin() + e, 0.0);
        std::fill(grid_.flux.begin() + b, grid_.flux.begin() + e, 0.0);
      }
    });
  }

  /// Total stress divergence term of one particle: f_i -= V sigma grad N_i,
  /// with sigma the (3D) effective stress restricted to the active axes.
  static inline Mat active_stress(const Voigt& s) {
    Mat m;
    if constexpr (Dim == 1) {
      m(0, 0) = s[0];
    } else if constexpr (Dim == 2) {
      m << s[0], s[3], s[3], s[1];
    } else {
      m << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
    }
    return m;
  }

  /// Phase 1: mass, momentum and effective-stress forces, and the fluid
  /// storage and storage-weighted pressure, from particles to nodes. (The
  /// body force sum_p N_ip m_p g is m_i g: update_nodal_momentum adds it.)
  void map_particles_to_grid(const Scatter& out, std::size_t begin, std::size_t end) {
    StencilT s;
    NodeRange touched{grid_.count, -1};
    // Local copies: Eigen's vector stores may alias anything for the
    // compiler, which otherwise reloads these pointers at every node.
    double* const mass_out = out.mass;
    Vec* const momentum_out = out.momentum;
    Vec* const force_out = out.force;
    for (std::size_t p = begin; p < end; ++p) {
      stencil_in_step<true, false>(p, s);
      touched.lo = std::min(touched.lo, s.node[0]);  // stencil nodes are in increasing order
      touched.hi = std::max(touched.hi, s.node[StencilT::N - 1]);
      const double m = particles_.mass[p];
      const double vol = particles_.volume[p];
      const Vec mv = m * particles_.v[p];
      const Mat vol_sig = vol * active_stress(particles_.stress[p]);
      for (int k = 0; k < StencilT::N; ++k) {
        const std::int64_t i = s.node[k];
        const double w = s.w[k];
        mass_out[i] += w * m;
        momentum_out[i] += w * mv;
        force_out[i].noalias() -= vol_sig * s.grad(k);
      }
      if (fluid_) {
        const std::uint16_t mat = particles_.material[p];
        if (!constants_[mat].saturated) continue;
        const double n = particles_.porosity[p];
        const double qv = ((1.0 - n) * inv_ks_[mat] + n * inv_kf_[mat]) * vol;
        const double qvp = qv * particles_.pressure[p];
        for (int k = 0; k < StencilT::N; ++k) {
          out.storage[s.node[k]] += s.w[k] * qv;
          out.pressure[s.node[k]] += s.w[k] * qvp;
        }
      }
    }
    *out.touched = touched;
  }

  /// Nodal pressure = storage-weighted average of particle pressures, then
  /// prescribed values at time t.
  void compute_nodal_pressure(double t) {
    for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i)
        grid_.pressure[i] = grid_.storage[i] > 0 ? grid_.pressure[i] / grid_.storage[i] : 0.0;
    });
    for (const PressureConstraint& bc : pressure_bcs_) {
      const double value = (*bc.fn)(t);
      for (std::int64_t i : bc.nodes) grid_.pressure[i] = value;
    }
  }

  /// Phase 2 (saturated): the pore pressure interpolated from the nodes,
  /// p_hat = sum N_j p_j, enters the total stress: f_i += V p_hat grad N_i.
  void map_pore_pressure_force(const Scatter& out, std::size_t begin, std::size_t end) {
    StencilT s;
    for (std::size_t p = begin; p < end; ++p) {
      if (!constants_[particles_.material[p]].saturated) continue;
      stencil_in_step<true, true>(p, s);
      double p_hat = 0.0;
      for (int k = 0; k < StencilT::N; ++k) p_hat += s.w[k] * grid_.pressure[s.node[k]];
      const double vp = particles_.volume[p] * p_hat;
      for (int k = 0; k < StencilT::N; ++k)
        out.force[s.node[k]] += vp * s.grad(k);
    }
  }

  /// Surface loads, mapped at the loaded face of each selected particle.
  void apply_tractions(double t) {
    StencilT s;
    for (const TractionLoad& load : tractions_) {
      Vec traction;
      for (int a = 0; a < Dim; ++a)
        traction[a] = load.source->traction[a] ? load.source->traction[a](t) : 0.0;
      for (std::size_t k = 0; k < load.particles.size(); ++k) {
        const auto p = static_cast<std::size_t>(load.particles[k]);
        const double stretch = std::pow(particles_.volume[p] / load.volume0[k], 1.0 / Dim);
        const double area = particles_.volume[p] / load.length0[k];
        Vec face = particles_.x[p];
        face[load.axis] += load.side * 0.5 * load.length0[k] * stretch;
        s.compute(face, grid_.origin, grid_.inv_h, grid_.cells, grid_.stride,
                  particles_.half_length.empty() ? 0.0 : particles_.half_length[p]);
        for (int n = 0; n < StencilT::N; ++n) grid_.force[s.node[n]] += s.w[n] * area * traction;
      }
    }
  }

  /// Grid update: momentum += dt (f + m g) (with local damping), then
  /// prescribed velocities at t + dt. Gives the Lagrangian nodal velocity and the
  /// nodal acceleration used by the particles.
  void update_nodal_momentum(double t, double dt) {
    const double alpha = damping_;
    for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) {
        const double m = grid_.mass[i];
        if (m <= mass_tolerance_) {
          grid_.velocity[i].setZero();
          grid_.accel[i].setZero();
          continue;
        }
        Vec f = grid_.force[i] + m * gravity_;
        const Vec v0 = grid_.momentum[i] / m;
        if (alpha > 0)
          for (int a = 0; a < Dim; ++a)
            f[a] -= alpha * std::abs(f[a]) * (v0[a] > 0 ? 1.0 : (v0[a] < 0 ? -1.0 : 0.0));
        grid_.accel[i] = f / m;
        grid_.velocity[i] = v0 + dt * grid_.accel[i];
      }
    });
    for (const RigidTie& tie : rigid_ties_)
      for (int a = 0; a < Dim; ++a) {
        if (!tie.axes[a]) continue;
        // The plate's velocity and acceleration: summed momenta and forces
        // (after damping) over summed masses. Every tied node takes both, so
        // particles see the rigid-body acceleration, not the jump that
        // projecting each node's own start velocity onto the plate's would
        // add (that jump, divided by dt, would also enter Darcy's rho_f a).
        double mass = 0.0, momentum = 0.0, momentum0 = 0.0;
        for (std::int64_t i : tie.nodes) {
          mass += grid_.mass[i];
          momentum += grid_.mass[i] * grid_.velocity[i][a];
          momentum0 += grid_.momentum[i][a];
        }
        if (!(mass > 0.0)) continue;
        const double v = momentum / mass, accel = (momentum - momentum0) / (mass * dt);
        for (std::int64_t i : tie.nodes) {
          if (grid_.mass[i] <= mass_tolerance_) continue;
          grid_.velocity[i][a] = v;
          grid_.accel[i][a] = accel;
        }
      }
    // Friction first, from the trial velocity, so that components prescribed
    // by any boundary (a symmetry plane meeting a floor) win afterwards.
    for (VelocityConstraint& bc : velocity_bcs_)
      if (!bc.stuck.empty()) apply_friction(bc, t, dt);
    for (const VelocityConstraint& bc : velocity_bcs_) {
      for (int a = 0; a < Dim; ++a) {
        if (!bc.fixed[a]) continue;
        const double v_old = (*bc.fn[a])(t), v_new = (*bc.fn[a])(t + dt);
        for (std::int64_t i : bc.nodes) {
          grid_.velocity[i][a] = v_new;
          grid_.accel[i][a] = (v_new - v_old) / dt;
        }
        // A friction wall gives its nodes' particles the full normal change
        // (see apply_friction), so the normal impulse is counted once.
        if (!bc.stuck.empty() && a == bc.normal)
          for (std::int64_t i : bc.nodes)
            if (grid_.mass[i] > mass_tolerance_)
              grid_.accel[i][a] = (v_new - grid_.momentum[i][a] / grid_.mass[i]) / dt;
      }
    }
  }

  /// Phase 3: FLIP update of particle velocities, v_p += dt sum N_i a_i, and
  /// re-mapping of the updated momentum (MUSL, Eq. 26).
  void update_particle_velocities_and_remap(const Scatter& out, std::size_t begin, std::size_t end,
                                            double dt) {
    StencilT s;
    for (std::size_t p = begin; p < end; ++p) {
      stencil_in_step<false, true>(p, s);
      Vec a = Vec::Zero();
      for (int k = 0; k < StencilT::N; ++k) a += s.w[k] * grid_.accel[s.node[k]];
      particles_.v[p] += dt * a;
      const Vec mv = particles_.mass[p] * particles_.v[p];
      for (int k = 0; k < StencilT::N; ++k) out.remap[s.node[k]] += s.w[k] * mv;
    }
  }

  /// Coulomb friction at the nodes of a boundary whose normal component
  /// (axis bc.normal) is prescribed and whose other components are free.
  /// The wall's normal impulse per unit mass is the normal velocity change
  /// it imposes on the node's trial velocity, dv_n = v_n(t + dt) - v_n^L.
  /// (For these boundaries the particles then receive that full change, see
  /// update_nodal_momentum, so particle velocities the wall has stopped are
  /// not mapped back and counted again the next step.) Friction takes at
  /// most mu |dv_n| off the tangential velocity (only the compressive part
  /// at a grid face, where the material's side is known), relative to a
  /// wall at rest tangentially, and never reverses it. A node whose
  /// tangential velocity is cancelled sticks (it also keeps zero tangential
  /// velocity in the re-mapped field). mu = inf: no slip. The normal
  /// component itself is set by the caller's loop.
  void apply_friction(VelocityConstraint& bc, double t, double dt) {
    const int n = bc.normal;
    const double vn_new = (*bc.fn[n])(t + dt);
    for (std::size_t k = 0; k < bc.nodes.size(); ++k) {
      const std::int64_t i = bc.nodes[k];
      const double m = grid_.mass[i];
      bc.stuck[k] = 0;
      if (m <= mass_tolerance_) continue;
      Vec& v = grid_.velocity[i];
      Vec vt = v;
      vt[n] = 0.0;
      const double slip = vt.norm();
      const double impulse = vn_new - v[n];
      const double dvn = bc.inward == 0 ? std::abs(impulse) : std::max(bc.inward * impulse, 0.0);
      const bool stick = slip <= 0.0 || std::isinf(bc.friction) || bc.friction * dvn >= slip;
      const double keep = stick ? 0.0 : 1.0 - bc.friction * dvn / slip;
      const Vec v_start = grid_.momentum[i] / m;
      for (int a = 0; a < Dim; ++a) {
        if (a == n) continue;
        v[a] *= keep;
        grid_.accel[i][a] = (v[a] - v_start[a]) / dt;
      }
      bc.stuck[k] = stick ? 1 : 0;
    }
  }

  void compute_remapped_nodal_velocity(double t_new, double dt) {
    for (RigidTie& tie : rigid_ties_)
      for (int a = 0; a < Dim; ++a) {
        if (!tie.axes[a]) continue;
        double mass = 0.0, momentum = 0.0;
        for (std::int64_t i : tie.nodes) {
          mass += grid_.mass[i];
          momentum += grid_.remap[i][a];
        }
        tie.remapped[a] = mass > 0.0 ? momentum / mass : 0.0;
      }
    for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) {
        const double m = grid_.mass[i];
        grid_.remap[i] = m > mass_tolerance_ ? Vec(grid_.remap[i] / m) : Vec::Zero();
      }
    });
    for (const RigidTie& tie : rigid_ties_)
      for (int a = 0; a < Dim; ++a) {
        if (!tie.axes[a]) continue;
        for (std::int64_t i : tie.nodes)
          if (grid_.mass[i] > mass_tolerance_) grid_.remap[i][a] = tie.remapped[a];
      }
    for (const VelocityConstraint& bc : velocity_bcs_)
      for (std::size_t k = 0; k < bc.stuck.size(); ++k)
        if (bc.stuck[k])
          for (int a = 0; a < Dim; ++a)
            if (a != bc.normal) grid_.remap[bc.nodes[k]][a] = 0.0;
    for (const VelocityConstraint& bc : velocity_bcs_)
      for (int a = 0; a < Dim; ++a) {
        if (!bc.fixed[a]) continue;
        const double v = (*bc.fn[a])(t_new);
        for (std::int64_t i : bc.nodes) grid_.remap[i][a] = v;
      }
    if (!fluid_) return;
    // Darcy's rho_f a takes the acceleration of the re-mapped field,
    // (v_remap - v^n) / dt, at free components: it has passed through the
    // same particle-grid smoothing as the velocities the mass balance sees,
    // so the elastic part of rho_f a is never stronger than the pressure
    // diffusion that balances it (docs/verification.md). Prescribed and
    // rigid components keep the acceleration of update_nodal_momentum.
    const double inv_dt = 1.0 / dt;
    for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) {
        const double m = grid_.mass[i];
        if (m <= mass_tolerance_) continue;
        const std::uint8_t fixed = prescribed_axes_[static_cast<std::size_t>(i)];
        for (int a = 0; a < Dim; ++a)
          if (!(fixed & (1u << a)))
            grid_.accel[i][a] = (grid_.remap[i][a] - grid_.momentum[i][a] / m) * inv_dt;
      }
    });
  }

  /// Phase 4: strain increment from the re-mapped nodal velocities, stress
  /// update, volume and porosity; the fluid flux of the mass balance,
  /// -N V div v + V grad N . w, is scattered to the nodes (Fluid: runs with
  /// a saturated material). In dry runs (!Fluid) the particles also move
  /// with the Lagrangian nodal velocity; in saturated runs the last phase
  /// moves them.
  template <bool Fluid, bool Plastic>
  void update_particle_stress_and_fluid_flux(const Scatter& out, std::size_t begin, std::size_t end,
                                             double dt) {
    StencilT s;
    for (std::size_t p = begin; p < end; ++p) {
      stencil_in_step<true, true>(p, s);
      Mat grad_v = Mat::Zero();
      for (int k = 0; k < StencilT::N; ++k)
        grad_v.noalias() += grid_.remap[s.node[k]] * s.grad(k).transpose();
      const double vol = particles_.volume[p];
      const std::uint16_t mat = particles_.material[p];
      const MaterialConstants& mc = constants_[mat];
      if (Fluid && mc.saturated) {
        const double div_v = grad_v.trace();
        Vec grad_p = Vec::Zero(), a = Vec::Zero();
        for (int k = 0; k < StencilT::N; ++k) {
          grad_p += grid_.pressure[s.node[k]] * s.grad(k);
          a += s.w[k] * grid_.accel[s.node[k]];
        }
        const Vec w = -mc.permeability_over_gamma *
                      (grad_p - mc.fluid_density * gravity_ + mc.darcy_inertia_density * a);
        particles_.darcy[p] = w;
        for (int k = 0; k < StencilT::N; ++k)
          out.flux[s.node[k]] +=
              vol * (s.grad(k).dot(w) - s.w[k] * div_v);
      }
      Voigt de = Voigt::Zero();
      for (int a = 0; a < Dim; ++a) de[a] = grad_v(a, a) * dt;
      if constexpr (Dim >= 2) de[3] = 0.5 * (grad_v(0, 1) + grad_v(1, 0)) * dt;
      if constexpr (Dim == 3) {
        de[4] = 0.5 * (grad_v(1, 2) + grad_v(2, 1)) * dt;
        de[5] = 0.5 * (grad_v(2, 0) + grad_v(0, 2)) * dt;
      }
      const double tr = de[0] + de[1] + de[2];
      Voigt& sig = particles_.stress[p];
      if constexpr (Dim >= 2) rotate_jaumann<Dim>(sig, grad_v, dt);
      // Constants copied first: the stores to sig could alias mc for the compiler.
      const double lambda_tr = mc.lambda * tr, two_g = 2.0 * mc.shear_modulus;
      // Below 3D the shear increments yz and zx (in 1D also xy) are zero:
      // the loops end before them (components 0..kEnd-1 can change).
      constexpr int kEnd = Dim == 1 ? 3 : (Dim == 2 ? 4 : 6);
      for (int c = 0; c < 3; ++c) sig[c] += lambda_tr + two_g * de[c];
      for (int c = 3; c < kEnd; ++c) sig[c] += two_g * de[c];
      if constexpr (Plastic) return_to_yield_surface(sig, mc);
      for (int c = 0; c < kEnd; ++c) particles_.strain[p][c] += de[c];
      const Mat f = Mat::Identity() + dt * grad_v;  // a plain matrix: its determinant inlines
      const double j = f.determinant();
      if (!(j > 0.0)) fail_volume(p, j);
      particles_.volume[p] = vol * j;
      if (Fluid && mc.saturated) particles_.porosity[p] = 1.0 - (1.0 - particles_.porosity[p]) / j;
      if constexpr (!Fluid) move_particle(p, s, dt);
    }
  }

  /// Grid: ds p/dt from the scattered flux; free nodes advance, prescribed
  /// nodes take their value at t + dt.
  void update_nodal_pressure(double t_new, double dt) {
    for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i)
        grid_.dp[i] = grid_.storage[i] > 0 ? dt * grid_.flux[i] / grid_.storage[i] : 0.0;
    });
    for (const PressureConstraint& bc : pressure_bcs_) {
      const double value = (*bc.fn)(t_new);
      for (std::int64_t i : bc.nodes) grid_.dp[i] = value - grid_.pressure[i];
    }
  }

  /// Phase 5 (saturated): particle pressure state += sum N dp_i (FLIP);
  /// reported pressure = sum N p_i^{n+1}; particles move.
  void update_particle_pressure_and_position(std::size_t begin, std::size_t end, double dt) {
    StencilT s;
    for (std::size_t p = begin; p < end; ++p) {
      stencil_in_step<false, true>(p, s);
      if (constants_[particles_.material[p]].saturated) {
        double dp = 0.0, p_new = 0.0;  // weights only: this pass needs no gradient
        for (int k = 0; k < StencilT::N; ++k) {
          const std::int64_t i = s.node[k];
          dp += s.w[k] * grid_.dp[i];
          p_new += s.w[k] * (grid_.pressure[i] + grid_.dp[i]);
        }
        particles_.pressure[p] += dp;
        particles_.pressure_out[p] = p_new;
        if (!std::isfinite(p_new)) fail_nonfinite(p, "pore pressure");
      }
      move_particle(p, s, dt);
    }
  }

  /// Moves the particle with the Lagrangian nodal velocity. One test per
  /// axis catches both failures: a non-finite position (the comparisons are
  /// false for NaN) and a position outside the grid. A non-finite particle
  /// velocity, stress or force makes the nodal velocities, hence the
  /// position, non-finite in the same or the next step.
  __attribute__((always_inline)) inline void move_particle(std::size_t p, const StencilT& s, double dt) {
    Vec dx = Vec::Zero();
    for (int k = 0; k < StencilT::N; ++k) dx += s.w[k] * grid_.velocity[s.node[k]];
    dx *= dt;
    Vec& x = particles_.x[p];
    x += dx;
    bool inside = true;
    for (int a = 0; a < Dim; ++a) inside &= (x[a] >= grid_.origin[a]) & (x[a] <= grid_max_[a]);
    if (!inside) [[unlikely]] {
      if (!x.allFinite() || !particles_.v[p].allFinite())
        fail_nonfinite(p, "velocity");
      else
        fail_left_grid(p);
    }
  }

  /// Plastic correction of the elastic trial stress (effective stress, so
  /// dry and saturated alike): closed-form return mapping of the material's
  /// model; linear-elastic materials in a run with plastic ones pass through.
  static inline void return_to_yield_surface(Voigt& sig, const MaterialConstants& mc) {
    switch (mc.model) {
      case Model::mohr_coulomb:
        constitutive::return_mohr_coulomb(sig, mc.elastic, mc.mohr_coulomb);
        break;
      case Model::drucker_prager:
        constitutive::return_drucker_prager(sig, mc.elastic, mc.drucker_prager);
        break;
      case Model::linear_elastic:
        break;
    }
  }

  // ------------------------------------------------------------ failures
  // Called from hot loops only on the failure path. Threads may find
  // failures in any order; the lowest particle index wins, so the report is
  // the same for any thread count.
  void record_failure(std::size_t p, std::string what, std::string hint) {
    std::lock_guard<std::mutex> lock(failure_mutex_);
    const auto index = static_cast<std::int64_t>(p);
    if (failed_ && failure_particle_ <= index) return;  // also keeps a fail_run (-1)
    failed_ = true;
    failure_particle_ = index;
    failure_ = std::move(what);
    failure_hint_ = std::move(hint);
  }
  /// A failure of the whole run, not of a particle (reported without one).
  void fail_run(std::string what, std::string hint) {
    std::lock_guard<std::mutex> lock(failure_mutex_);
    failed_ = true;
    failure_particle_ = -1;
    failure_ = std::move(what);
    failure_hint_ = std::move(hint);
  }
  void fail_nonfinite(std::size_t p, const char* what) {
    std::string hint = "reduce time.dt or time.courant (the stable step estimate is " +
                       number(stable_.limit) +
                       " s), and check moduli, densities and loads for unrealistic values";
    if (!warnings_.empty())
      hint += "; see the warnings: a material is where the u-p equations with Darcy's rho_f a "
              "term grow (stiffer fluid_bulk_modulus or hydraulic.darcy_inertia = false)";
    record_failure(p, std::string("the ") + what + " became non-finite: the run diverged", std::move(hint));
  }
  void fail_left_grid(std::size_t p) {
    record_failure(p, "the particle left the grid",
                   "enlarge grid.min/grid.max so the grid contains the motion, or restrain the "
                   "body with boundaries");
  }
  void fail_volume(std::size_t p, double j) {
    record_failure(p,
                   "the particle volume became " +
                       std::string(j <= 0 ? "negative or zero" : "non-finite") +
                       " (volume ratio " + number(j) + " in one step)",
                   "reduce time.dt or time.courant, refine the grid, or use a gimp/bspline "
                   "shape_function for large deformations");
  }

  static std::string number(double v) {
    std::ostringstream o;
    o.precision(6);
    o << v;
    return o.str();
  }

  // ------------------------------------------------------------ output
  void fill_snapshot(Snapshot& snap, const std::vector<Field>& fields) const;
  void sample_series(Series& series, double t) const;

  /// Nodes sharing one velocity component per marked axis (rigid plate).
  struct RigidTie {
    std::vector<std::int64_t> nodes;
    std::array<bool, 3> axes{false, false, false};
    std::array<double, 3> remapped{0.0, 0.0, 0.0};  ///< scratch: tied re-mapped velocity
  };
  struct PressureConstraint {
    std::vector<std::int64_t> nodes;
    const FieldOfTime* fn = nullptr;
  };
  struct TractionLoad {
    const Traction* source = nullptr;
    int axis = 0;
    int side = 1;
    std::vector<std::int64_t> particles;
    std::vector<double> length0;
    std::vector<double> volume0;
  };

  const Problem& problem_;
  GridState<Dim> grid_;
  ParticleState<Dim> particles_;
  std::vector<MaterialConstants> constants_;
  std::vector<double> inv_ks_, inv_kf_;
  std::vector<VelocityConstraint> velocity_bcs_;
  std::vector<PressureConstraint> pressure_bcs_;
  std::vector<RigidTie> rigid_ties_;
  std::vector<TractionLoad> tractions_;
  Vec gravity_ = Vec::Zero();
  Vec grid_max_ = Vec::Zero();
  bool fluid_ = false;
  bool plastic_ = false;        ///< any material with a return mapping
  std::vector<std::string> warnings_;  ///< set-up findings the result reports
  /// Per node (saturated runs): bit a set when a boundary prescribes or ties component a.
  std::vector<std::uint8_t> prescribed_axes_;
  double mass_tolerance_ = 0.0;
  StableStep stable_;

  std::unique_ptr<ThreadPool> pool_;
  std::vector<ScatterBuffer> buffers_;
  std::vector<NodeRange> touched_;  ///< per thread, from the step's first phase

  std::mutex failure_mutex_;
  double damping_ = 0.0;  // local damping coefficient of the current step
  bool failed_ = false;  // written under failure_mutex_, read between phases
  std::int64_t failure_particle_ = -1;
  std::string failure_;
  std::string failure_hint_;
};

}  // namespace hmpm

#include "simulation_run.hpp"
