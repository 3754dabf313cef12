// schemes/quasi_static_scheme.hpp — the quasi-static implicit u-p scheme
// (internal).
//
// No inertia; backward Euler in time; Newton iterations; updated-Lagrangian
// MPM (each step maps the particles to a fresh grid, solves on it, moves the
// particles and forgets the grid). Unknowns of the step t -> t + dt: the
// nodal displacement increment du and the nodal pore pressure p = p^{n+1},
// both with the grid's shape functions N (equal order). With material-point
// integration over the configuration at the start of the step (x^n, V^n):
//
//   R_u = sum_p [ N m_p g - V_p B^T (sigma'(du) - p_hat m) ] + tractions(t + dt)    = 0
//   R_p = sum_p V_p [ N Q (p_hat - p_p^n) + N div du
//                     + dt grad N . (k/gamma_w)(grad p_hat - rho_f g) ]
//         + tau sum_cells int (dp - Pi dp) (q - Pi q) dV                            = 0
//
// p_hat = N p, dp = p - p^n (p^n the nodal projection of the particle
// pressures), sigma'(du) = sigma'^n + Jaumann spin + D : sym(grad du)
// followed by the material's return mapping. The last term is the
// polynomial pressure projection (Bochev & Dohrmann 2006; in MPM Zhao &
// Choo 2020): Pi the volume-weighted mean over the particles of a cell
// (particles sharing one stencil anchor), tau = 1 / (2G) times
// time.implicit.pressure_stabilisation. It acts like a compressibility
// 1/(2G), of the order of the skeleton's own compliance, on the part of the
// pressure increment that varies inside a cell (the equal-order checkerboard
// mode), and is zero on cell-wise constant increments and at steady state.
//
// The Jacobian, with the equations scaled to comparable sizes (E_ref the
// largest constrained modulus, unknowns du and p / E_ref, rows R_u / E_ref
// and R_p), is the symmetric indefinite
//   [ K / E_ref      -C              ]   K = sum V B^T D B, C = sum V B^T m N
//   [ -C^T           -E_ref (S + dt H + tau P) ]
// with D the elastic stiffness at elastic points and the algorithmic
// (consistent) tangent d sigma / d eps of the return mapping at plastic
// points (materials/material.hpp return_with_tangent; tensor shear strains,
// so K = sum V Bhat^T D B with B the tensor-strain and Bhat the engineering
// (work-conjugate) strain-displacement matrix; plane strain takes the xx,
// yy, xy rows and columns). Newton then converges quadratically; the
// non-associated tangents are unsymmetric (the solvers are LU/BiCGSTAB).
// The Jaumann spin of sigma^n (the start stress rotated by the increment's
// spin) is linearised in runs with a return-mapping soil (its term
// d(W sigma - sigma W)/du, unsymmetric): without it Newton converges only
// linearly, at a rate of about |sigma|/K per iteration, which soft clays
// under their own weight make 1e-2 (Cam-Clay embankment: 151 -> 132 Newton
// iterations in all, docs/schemes.md). Elastic runs leave it out (their
// symmetric factor serves every iteration of a step). Left out: the change of the particle
// volumes (small in a step). time.implicit.elastic_tangent (tests only)
// takes the elastic D everywhere: linear convergence.
//
// Boundary conditions: prescribed velocity components give prescribed
// increments (the trapezoidal integral of the velocity over the step),
// rigid ties share one degree of freedom per tied axis (prescribed
// components win, as in boundary/apply.hpp), friction walls are refused by
// the scheme's checks (quasi_static_rules.cpp: there is no Coulomb slip
// here; were one to reach the scheme, only its normal component would be
// prescribed), prescribed pore pressures take their value at t + dt.
//
// Threads: the residual and Jacobian assembly takes one fixed chunk of
// particles per solver thread, each extra thread into private copies of the
// residual and the matrix values (same pattern; sized once per step), added
// in thread order after the loop: reproducible at a given thread count,
// round-off between counts. The particle update takes blocks dynamically
// (no sums). The per-step set-up and the linear solve are serial.
//
// A step whose Newton iterations do not converge within max_iterations is
// halved and retried, up to max_cutbacks halvings; then the run fails with
// the residual reached and what to change.
//
// Collapse (time.on_collapse; docs/job-spec.md "Collapse"). In a run with
// plastic soil, the last halving failing means the loads at the end of the
// step have no equilibrium state the soil can carry that the Newton
// iterations can reach from the last one: past a limit load the tangent
// stiffness is singular and no step, however short, converges. The run
// then reports a collapse at the last converged time (its load, the
// particles that yielded in the last converged step, the largest
// displacement). A run that crawls towards a limit load (each step
// converging only after cut-backs, as a wall whose head keeps moving
// does) spends cut-backs without a step converging at its first length in
// between: 4 max_cutbacks of them in a row is a collapse as well (stop, or
// a warning and the run goes on).
//
// Strength reduction (strength_reduce(), Problem::strength_reduction):
// the same Newton iterations with reduced material constants, the loads
// held at their values at the job's end, no prescribed increments and the
// pore pressures held at their projection (drained strength with the pore
// pressures of the state reached).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "boundary/apply.hpp"
#include "boundary/tractions.hpp"
#include "linear/up_system.hpp"
#include "materials/material.hpp"
#include "objective_rate.hpp"
#include "phases/pore_pressure.hpp"
#include "schemes/quasi_static_plan.hpp"
#include "schemes/time_scheme.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
class QuasiStaticScheme final : public TimeScheme {
 public:
  using Context = StepContext<Dim, Shape>;
  using Vec = VecD<Dim>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;
  using StencilT = shape::Stencil<Dim, Shape>;
  static constexpr int N = StencilT::N;
  static constexpr int L = N * (Dim + 1);  ///< local unknowns of one particle

  explicit QuasiStaticScheme(Context c) : c_(c) {
    const Problem& pr = c_.model.problem;
    if (!pr.time.dt) {
      growth_ = quasi_static_growth(pr);
      nominal_ = growth_.initial;
    }
    for (const MaterialConstants& mc : c_.model.constants)
      e_ref_ = std::max(e_ref_, mc.constrained_modulus);
    if (!(e_ref_ > 0)) e_ref_ = 1.0;
    for (const SeepageFace& face : c_.model.constraints.seepage)
      seepage_.insert(seepage_.end(), face.nodes.begin(), face.nodes.end());
    held_.assign(static_cast<std::size_t>(c_.grid.count), 0);
    yielded_.assign(c_.particles.size(), 0);
  }

  StableStep stable_step(const Problem& problem) const override {
    return quasi_static_scheme_rules().stable_step(problem);
  }

  /// The nominal step (grown geometrically), shortened to land on the next
  /// output instant, or stretched by up to a quarter to reach it.
  double next_dt(double t) override {
    double h = nominal_;
    const OutputRequest& out = c_.model.problem.output;
    const ConsolidationRequest& c = out.consolidation;
    // (first instant, interval) of each output's samples
    const std::pair<double, double> samples[] = {{0.0, out.series_interval},
                                                 {0.0, out.snapshot_interval},
                                                 {0.0, out.reactions_interval},
                                                 {0.0, out.profile_interval},
                                                 {c.from, c.interval}};
    for (const auto& [first, interval] : samples) {
      if (!(interval > 0)) continue;
      const double next =
          t < first - 1e-9 * interval
              ? first
              : first + (std::floor((t - first) / interval + 1e-9) + 1.0) * interval;
      if (t + 1.25 * h >= next - 1e-9 * interval) h = std::min(h * 1.25, next - t);
    }
    // The profiles' listed times (isochrones), the next one after t.
    const auto listed = std::upper_bound(out.profile_times.begin(), out.profile_times.end(),
                                         t + 1e-9 * std::max(h, t));
    if (listed != out.profile_times.end() && t + 1.25 * h >= *listed - 1e-9 * h)
      h = std::min(h * 1.25, *listed - t);
    nominal_ = std::min(growth_.max, nominal_ * growth_.growth);
    return h;
  }

  void step(double t, double dt) override {
    const ImplicitControl& c = c_.model.problem.time.implicit;
    const double t_end = t + dt;
    double t_cur = t, h = dt;
    int cuts = 0;
    while (t_cur < t_end - 1e-12 * dt) {
      const double hh = std::min(h, t_end - t_cur);
      if (attempt(t_cur, hh)) {
        t_cur += hh;
        continue;
      }
      if (c_.failures.failed) return;
      if (cuts >= c.max_cutbacks && c_.model.plastic) {
        collapse(t_cur, "no_convergence", cuts, hh);
        return;
      }
      if (cuts >= c.max_cutbacks) {
        std::ostringstream what;
        what << "the quasi-static Newton iterations did not converge in " << c.max_iterations
             << " iterations after " << cuts << " cut-backs (step length down to " << number(hh)
             << " s): residual reached |R_u|/|f| = " << number(last_ru_)
             << ", |R_p|/|terms| = " << number(last_rp_) << " (tolerance " << number(c.tolerance)
             << ")";
        c_.failures.fail_run(what.str(),
                             "start with a smaller step (time.dt, or time.dt.initial with growth), "
                             "loosen time.implicit.tolerance, or allow more "
                             "time.implicit.max_iterations or time.implicit.max_cutbacks");
        return;
      }
      ++cuts;
      ++cutbacks_;
      h = 0.5 * hh;
      // A crawl: cut-backs in a row without a step that converged at its
      // first length (in this call or a step before).
      if (++crawl_ >= 4L * std::max(1, c.max_cutbacks) && c_.model.plastic &&
          !c_.failures.collapse.found) {
        collapse(t_cur, "cutbacks_in_a_row", crawl_, h);
        if (c_.failures.failed) return;
      }
    }
    if (cuts == 0) crawl_ = 0;
    // After cut-backs the next steps start again from the length that worked.
    if (cuts > 0 && !c_.model.problem.time.dt) nominal_ = std::min(nominal_, h);
  }

  /// Strength reduction: one attempt to reach equilibrium with the material
  /// constants `reduced` (kept by reference until the next call), the loads
  /// at `load_time`, in up to `max_iterations` Newton iterations, each with
  /// a backtracking line search (backtrack()). True when it converged (the
  /// particles then take the state); false with nothing changed, or after
  /// a converged state lost a particle (a failure in c_.failures; the
  /// particles have moved: the caller puts back its copy).
  bool strength_reduce(const std::vector<MaterialConstants>& reduced, double load_time,
                       int max_iterations) {
    if (!reducing_) prepared_ = false;  // every pressure is held from now on
    reducing_ = true;
    reduce_iterations_ = std::max(1, max_iterations);
    constants_ = &reduced;
    return attempt(load_time, 1.0);
  }

  /// Line-search halvings of strength-reduction trials (backtrack()).
  std::int64_t backtracks() const { return backtracks_; }

  /// The largest particle displacement |x - x0|, m.
  double max_displacement() const {
    double m = 0.0;
    const auto& parts = c_.particles;
    for (std::size_t p = 0; p < parts.size(); ++p)
      m = std::max(m, (parts.x[p] - parts.x0[p]).norm());
    return m;
  }

  void report(RunResult& result) const override {
    result.iterations.nonlinear = nonlinear_;
    result.iterations.linear = system_.linear_iterations;
    result.iterations.solves = system_.solves;
    result.iterations.cutbacks = cutbacks_;
    result.iterations.max_nonlinear = max_nonlinear_;
    result.iterations.worst_residuals = worst_;
  }

  /// The step plan (nominal length; growth and limits come from the
  /// problem), the counters and the worst step's residuals. Between steps
  /// nothing else lasts: each step prepares its grid and system afresh.
  void save(checkpoint::Writer& w) const override {
    w.pod(nominal_);
    w.pod(nonlinear_);
    w.pod(cutbacks_);
    w.pod(max_nonlinear_);
    w.array(worst_);
    w.pod(system_.linear_iterations);
    w.pod(system_.solves);
  }
  void load(checkpoint::Reader& r) override {
    nominal_ = r.pod<double>();
    nonlinear_ = r.pod<std::int64_t>();
    cutbacks_ = r.pod<std::int64_t>();
    max_nonlinear_ = r.pod<int>();
    r.array(worst_, -1, "residual history");
    system_.linear_iterations = r.pod<std::int64_t>();
    system_.solves = r.pod<std::int64_t>();
    prepared_ = false;
  }

 private:
  // ------------------------------------------------------------ the step's grid
  /// Stencils, active nodes, the projection of the particle pressures, the
  /// cells of the stabilisation and the sparsity pattern, for the particles
  /// where they are now (once per step; cut-backs reuse them).
  void prepare() {
    auto& grid = c_.grid;
    auto& parts = c_.particles;
    const auto nodes = static_cast<std::size_t>(grid.count);
    const std::size_t np = parts.size();
    weight_.assign(nodes, 0.0);
    weight_fluid_.assign(nodes, 0.0);
    pn_.assign(nodes, 0.0);
    double vmax = 0.0;
    StencilT s;
    keys_.resize(np);
    for (std::size_t p = 0; p < np; ++p) {
      c_.template stencil_in_step<true, false>(p, s);
      const double vol = parts.volume[p];
      vmax = std::max(vmax, vol);
      const bool sat = c_.model.fluid && (*constants_)[parts.material[p]].saturated;
      for (int k = 0; k < N; ++k) {
        weight_[s.node[k]] += s.w[k] * vol;
        if (sat) {
          weight_fluid_[s.node[k]] += s.w[k] * vol;
          pn_[s.node[k]] += s.w[k] * vol * parts.pressure_out[p];
        }
      }
      keys_[p] = {s.node[0], static_cast<std::int64_t>(p)};
    }
    tiny_ = 1e-12 * vmax;
    for (std::size_t i = 0; i < nodes; ++i)
      pn_[i] = weight_fluid_[i] > tiny_ ? pn_[i] / weight_fluid_[i] : 0.0;
    // Degrees of freedom: prescribed components, then rigid ties, then free.
    udof_.assign(nodes * Dim, -1);
    pdof_.assign(nodes, -1);
    ufixed_.assign(nodes * Dim, 0);
    for (const VelocityConstraint& bc : c_.model.constraints.velocity)
      for (int a = 0; a < Dim; ++a)
        if (bc.fixed[a])
          for (std::int64_t i : bc.nodes) ufixed_[static_cast<std::size_t>(i) * Dim + a] = 1;
    std::int64_t n = 0;
    for (const RigidTie& tie : c_.model.constraints.rigid_ties)
      for (int a = 0; a < Dim; ++a) {
        if (!tie.axes[a]) continue;
        std::int64_t shared = -1;
        for (std::int64_t i : tie.nodes) {
          const std::size_t d = static_cast<std::size_t>(i) * Dim + a;
          if (ufixed_[d] || !(weight_[static_cast<std::size_t>(i)] > tiny_) || udof_[d] >= 0)
            continue;
          if (shared < 0) shared = n++;
          udof_[d] = shared;
        }
      }
    pfixed_.assign(nodes, 0);
    for (const PressureConstraint& bc : c_.model.constraints.pressure)
      for (std::int64_t i : bc.nodes) pfixed_[static_cast<std::size_t>(i)] = 1;
    for (std::int64_t i : seepage_)
      if (held_[static_cast<std::size_t>(i)]) pfixed_[static_cast<std::size_t>(i)] = 1;
    if (reducing_) std::fill(pfixed_.begin(), pfixed_.end(), 1);
    for (std::size_t i = 0; i < nodes; ++i) {
      if (!(weight_[i] > tiny_)) continue;
      for (int a = 0; a < Dim; ++a) {
        const std::size_t d = i * Dim + a;
        if (!ufixed_[d] && udof_[d] < 0) udof_[d] = n++;
      }
      if (weight_fluid_[i] > tiny_ && !pfixed_[i]) pdof_[i] = n++;
    }
    unknowns_ = n;
    // Stabilisation cells: particles grouped by stencil anchor.
    std::sort(keys_.begin(), keys_.end());
    cell_nodes_.clear();
    cell_matrix_.clear();
    for (std::size_t b = 0; b < np;) {
      std::size_t e = b;
      while (e < np && keys_[e].first == keys_[b].first) ++e;
      add_cell(b, e);
      b = e;
    }
    // Pattern: every pair of unknowns in one particle's stencil (the cells'
    // pairs are a subset).
    system_.begin_pattern(unknowns_);
    std::int64_t dofs[L];
    for (std::size_t p = 0; p < np; ++p) {
      c_.template stencil_in_step<false, true>(p, s);
      local_dofs(s, dofs);
      for (int r = 0; r < L; ++r) {
        if (dofs[r] < 0) continue;
        for (int c = 0; c < L; ++c)
          if (dofs[c] >= 0) system_.add_pattern(dofs[r], dofs[c]);
      }
    }
    system_.finish_pattern(c_.model.problem.time.implicit.linear_solver,
                           c_.model.problem.time.implicit.linear_tolerance, Dim);
    rhs_.resize(unknowns_);
    ref_.resize(unknowns_);
    // Private sums of threads 1.. (zero between assemblies; no allocation
    // once the vectors have reached the largest pattern).
    partial_.resize(c_.threads.pool ? static_cast<std::size_t>(c_.threads.pool->size() - 1) : 0);
    for (Partial& w : partial_) {
      w.rhs.assign(static_cast<std::size_t>(unknowns_), 0.0);
      w.ref.assign(static_cast<std::size_t>(unknowns_), 0.0);
      w.values.assign(static_cast<std::size_t>(system_.nonzeros()), 0.0);
    }
    x_.resize(unknowns_);
    du_.assign(nodes * Dim, 0.0);
    p_.assign(nodes, 0.0);
    prepared_ = true;
  }

  /// The projection term tau (M - m m^T / V) of the saturated particles
  /// keys_[b, e) (one stencil anchor).
  void add_cell(std::size_t b, std::size_t e) {
    auto& parts = c_.particles;
    const double factor = c_.model.problem.time.implicit.pressure_stabilisation;
    if (!c_.model.fluid || !(factor > 0)) return;
    Eigen::Matrix<double, N, N> m = Eigen::Matrix<double, N, N>::Zero();
    Eigen::Matrix<double, N, 1> mv = Eigen::Matrix<double, N, 1>::Zero();
    double vol = 0.0, tau = 0.0;
    StencilT s;
    for (std::size_t k = b; k < e; ++k) {
      const auto p = static_cast<std::size_t>(keys_[k].second);
      const MaterialConstants& mc = (*constants_)[parts.material[p]];
      if (!mc.saturated) continue;
      c_.template stencil_in_step<false, true>(p, s);
      const double v = parts.volume[p];
      for (int i = 0; i < N; ++i) {
        mv[i] += v * s.w[i];
        for (int j = 0; j < N; ++j) m(i, j) += v * s.w[i] * s.w[j];
      }
      vol += v;
      tau = std::max(tau, factor / (2.0 * elastic_of(mc, parts.varying, p).shear));
    }
    if (!(vol > 0)) return;
    m -= mv * mv.transpose() / vol;
    m *= tau;
    for (int i = 0; i < N; ++i) cell_nodes_.push_back(s.node[i]);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) cell_matrix_.push_back(m(i, j));
  }

  /// Unknown of each local slot (node k: components 0..Dim-1, then the
  /// pressure at Dim), -1 where the value is prescribed or the node inactive.
  void local_dofs(const StencilT& s, std::int64_t* dofs) const {
    for (int k = 0; k < N; ++k) {
      const auto i = static_cast<std::size_t>(s.node[k]);
      for (int a = 0; a < Dim; ++a) dofs[k * (Dim + 1) + a] = udof_[i * Dim + a];
      dofs[k * (Dim + 1) + Dim] = pdof_[i];
    }
  }

  // ------------------------------------------------------------ one attempt
  /// Newton iterations for the step t -> t + h. True when converged (the
  /// particles are then updated); false otherwise, with nothing changed.
  bool attempt(double t, double h) {
    if (!prepared_) {
      prepare();
      if (c_.model.fluid)
        check_drained_contact(c_.model.constraints, c_.failures, t, [this](std::int64_t i) {
          return weight_fluid_[static_cast<std::size_t>(i)] > tiny_;
        });
      if (c_.failures.failed) return false;
    }
    auto& grid = c_.grid;
    const auto nodes = static_cast<std::size_t>(grid.count);
    // Prescribed values and the initial guess (du = 0, p = p^n).
    std::fill(du_.begin(), du_.end(), 0.0);
    for (const VelocityConstraint& bc : c_.model.constraints.velocity)
      for (int a = 0; a < Dim; ++a)
        if (bc.fixed[a]) {
          const double d = reducing_ ? 0.0 : 0.5 * ((*bc.fn[a])(t) + (*bc.fn[a])(t + h)) * h;
          for (std::int64_t i : bc.nodes) du_[static_cast<std::size_t>(i) * Dim + a] = d;
        }
    for (std::size_t i = 0; i < nodes; ++i) p_[i] = pn_[i];
    if (!reducing_) {
      for (const PressureConstraint& bc : c_.model.constraints.pressure)
        bc.for_values(t + h,
                      [&](std::int64_t i, double v) { p_[static_cast<std::size_t>(i)] = v; });
      for (std::int64_t i : seepage_)
        if (held_[static_cast<std::size_t>(i)]) p_[static_cast<std::size_t>(i)] = 0.0;
    }
    // External nodal forces at t + h: tractions (gravity is per particle).
    for (std::size_t i = 0; i < nodes; ++i) grid.force[i].setZero();
    apply_dead_loads(reducing_ ? t : t + h);
    // Water across faces at t + h (backward Euler), on the initial face areas.
    if (!c_.model.fluxes.empty() && !reducing_) {
      std::fill(grid.flux.begin(), grid.flux.end(), 0.0);
      // The nodes the saturated particles reach (free or prescribed).
      apply_fluxes<Dim, Shape, /*DeadLoad=*/true>(
          c_.model.fluxes, c_.particles, grid, t + h,
          [this](std::int64_t i) { return weight_fluid_[static_cast<std::size_t>(i)] > tiny_; });
    }
    // Surface pressures at t + h (boundary/surface_pressures.hpp).
    surface_.clear();
    for_surface_particles<Dim>(
        c_.model.surface_pressures, c_.particles, c_.model.constants, t + h,
        [&](std::size_t p, double cond, double p_face, bool seepage, const Vec& face) {
          surface_.push_back({p, cond, p_face, seepage, face});
        });
    const ImplicitControl& c = c_.model.problem.time.implicit;
    const int max_iterations = reducing_ ? reduce_iterations_ : c.max_iterations;
    history_.resize(static_cast<std::size_t>(std::max(max_iterations, c.max_iterations)) + 1);
    for (int it = 0;; ++it) {
      const bool converged = assemble(h, /*jacobian=*/it < max_iterations);
      history_[static_cast<std::size_t>(it)] = std::max(last_ru_, last_rp_);
      if (converged) {
        // Seepage faces: an active set. Each step starts with every face
        // node free (no water enters a free node); a converged step that
        // raises a free face node above p = 0 holds it there (its water
        // leaves) and is solved again, until no free face node is above
        // zero: the explicit scheme's rule, p <= 0, outflow >= 0, per step.
        bool held = false;
        for (std::int64_t i : seepage_) {
          const auto u = static_cast<std::size_t>(i);
          if (held_[u] || pdof_[u] < 0 || !(p_[u] > 0.0)) continue;
          held_[u] = 1;
          held = true;
        }
        if (held) {
          prepared_ = false;  // the held nodes leave the unknowns
          return attempt(t, h);
        }
        if (it > max_nonlinear_ || worst_.empty())
          worst_.assign(history_.begin(), history_.begin() + it + 1);
        max_nonlinear_ = std::max(max_nonlinear_, it);
        if (c_.reactions.due) tally_reactions();
        commit(h);
        if (!seepage_.empty()) {
          std::fill(held_.begin(), held_.end(), 0);
          prepared_ = false;
        }
        return !c_.failures.failed;
      }
      if (it >= max_iterations) return false;
      const double r0 = reducing_ ? rhs_.squaredNorm() : 0.0;
      if (!system_.solve(rhs_, x_)) return false;
      ++nonlinear_;
      add_correction(1.0);
      if (reducing_) backtrack(h, r0);
    }
  }

  /// du and p move by `s` times the Newton correction x_.
  void add_correction(double s) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(c_.grid.count); ++i) {
      for (int a = 0; a < Dim; ++a) {
        const std::int64_t d = udof_[i * Dim + a];
        if (d >= 0) du_[i * Dim + a] += s * x_[d];
      }
      if (pdof_[i] >= 0) p_[i] += s * e_ref_ * x_[pdof_[i]];
    }
  }

  /// Strength-reduction trials only: a backtracking line search on the
  /// squared residual |R|^2 (r0 before the correction). While the
  /// correction just added raises it, the correction is halved, up to
  /// max_backtracks times (the last length is kept either way). Near the
  /// factor of safety the points of the coming shear band switch between
  /// elastic and plastic from one iteration to the next, and full Newton
  /// corrections overshoot there: the residual wanders between 1e-4 and
  /// 6e-3 without falling, and a trial F well below the mechanism's
  /// fails (measured on the slopes of tests/api/check_strength_reduction.py
  /// at 0.25 m cells, the slide moved 4.4 mm: F 4 % below Bishop's). Time steps keep full
  /// corrections: the same search made gravity loading's steps stall (their cut-backs serve
  /// instead).
  void backtrack(double h, double r0) {
    constexpr int max_backtracks = 6;
    double s = 1.0;
    for (int k = 0; k < max_backtracks; ++k) {
      assemble(h, /*jacobian=*/false);
      if (rhs_.squaredNorm() <= r0) return;
      add_correction(-0.5 * s);
      s *= 0.5;
      ++backtracks_;
    }
  }

  /// Surface loads at time t as dead loads: each loaded particle face keeps
  /// its initial area (boundary/tractions.hpp; the explicit schemes' area
  /// follows the particle volume, which in uniaxial compression lowers the
  /// load by the top particle's strain; Terzaghi's and Mandel's loads are
  /// fixed forces).
  void apply_dead_loads(double t) {
    apply_tractions<Dim, Shape, /*DeadLoad=*/true>(
        c_.model.tractions, c_.particles, c_.grid, t,
        [this](std::int64_t i) { return weight_[static_cast<std::size_t>(i)] > tiny_; });
  }

  /// The particle's strain increment and trial-then-returned stress for the
  /// current du; grad du in `g`. With `d_alg`, the algorithmic tangent of
  /// the return too (d sigma / d eps, tensor shear strains); the return
  /// value then says whether the point was plastic (d_alg is only written
  /// when it was; elastic points take the elastic stiffness).
  /// Models with state (Cam-Clay) read their state at the step's start and
  /// write the new one only when `commit` (the converged step). Cam-Clay,
  /// whose elasticity depends on the stress, always reports its tangent.
  bool particle_stress(std::size_t p, const StencilT& s, Mat& g, Voigt& de, Voigt& sig,
                       constitutive::Tangent* d_alg = nullptr, double* plastic = nullptr,
                       bool commit = false) const {
    g.setZero();
    for (int k = 0; k < N; ++k) {
      const auto i = static_cast<std::size_t>(s.node[k]);
      Vec u;
      for (int a = 0; a < Dim; ++a) u[a] = du_[i * Dim + a];
      g.noalias() += u * s.grad(k).transpose();
    }
    de.setZero();
    for (int a = 0; a < Dim; ++a) de[a] = g(a, a);
    if constexpr (Dim >= 2) de[3] = 0.5 * (g(0, 1) + g(1, 0));
    if constexpr (Dim == 3) {
      de[4] = 0.5 * (g(1, 2) + g(2, 1));
      de[5] = 0.5 * (g(2, 0) + g(0, 2));
    }
    const MaterialConstants& mc = (*constants_)[c_.particles.material[p]];
    sig = c_.particles.stress[p];
    if constexpr (Dim >= 2) rotate_jaumann<Dim>(sig, g, 1.0);
    const double tr = de[0] + de[1] + de[2];
    const VaryingConstants& varying = c_.particles.varying;
    const constitutive::Elastic& el = elastic_of(mc, varying, p);
    if (elastic_trial_outside(mc.model)) {
      for (int c = 0; c < 3; ++c) sig[c] += el.lambda * tr + 2.0 * el.shear * de[c];
      for (int c = 3; c < 6; ++c) sig[c] += 2.0 * el.shear * de[c];
    }
    if (!c_.model.plastic) return false;
    const InternalState state{c_.particles.internal.data(), p, commit};
    if (d_alg && mc.model != Model::linear_elastic)
      return return_with_tangent(sig, de, mc, el, varying, p, state, *d_alg) > 0.0 ||
             !elastic_trial_outside(mc.model);
    const double norm = return_to_yield_surface(sig, de, mc, el, varying, p, state);
    if (plastic) *plastic = norm;
    return false;
  }

  /// The Voigt components of a Dim-dimensional strain (plane strain in 2D:
  /// xx, yy, xy; 1D: xx).
  static constexpr int NC = Dim == 1 ? 1 : (Dim == 2 ? 3 : 6);
  static constexpr int component(int i) { return Dim == 2 && i == 2 ? 3 : i; }

  /// The strain-displacement matrix of a node with shape gradient gk, shear
  /// rows times `shear`: 1/2 gives B, the tensor strain of a unit nodal
  /// displacement (eps_xy = (g_y u_x + g_x u_y) / 2); 1 gives Bhat, its work
  /// conjugate (the internal force V sigma grad N, where sigma_xy acts on
  /// both x and y). The stiffness block of nodes k, l: V Bhat_k^T D B_l.
  static Eigen::Matrix<double, NC, Dim> strain_of(const Vec& gk, double shear) {
    Eigen::Matrix<double, NC, Dim> b = Eigen::Matrix<double, NC, Dim>::Zero();
    for (int a = 0; a < Dim; ++a) b(a, a) = gk[a];
    if constexpr (Dim == 2) {
      b(2, 0) = shear * gk[1];
      b(2, 1) = shear * gk[0];
    }
    if constexpr (Dim == 3) {
      b(3, 0) = shear * gk[1];  // xy
      b(3, 1) = shear * gk[0];
      b(4, 1) = shear * gk[2];  // yz
      b(4, 2) = shear * gk[1];
      b(5, 2) = shear * gk[0];  // zx
      b(5, 0) = shear * gk[2];
    }
    return b;
  }

  /// Residual (rhs_ = scaled R, ref_ = the sums of the magnitudes of its
  /// terms) and, when `jacobian`, the Jacobian. True when converged.
  bool assemble(double h, bool jacobian) {
    auto& parts = c_.particles;
    auto& grid = c_.grid;
    rhs_.setZero();
    ref_.setZero();
    if (jacobian) system_.zero_values();
    const double inv_e = 1.0 / e_ref_;
    // Tractions.
    for (std::size_t i = 0; i < static_cast<std::size_t>(grid.count); ++i)
      for (int a = 0; a < Dim; ++a) {
        const std::int64_t d = udof_[i * Dim + a];
        if (d < 0) continue;
        rhs_[d] += grid.force[i][a] * inv_e;
        ref_[d] += std::abs(grid.force[i][a]) * inv_e;
      }
    // Water across faces: the mass balance loses h times the inflow.
    if (!c_.model.fluxes.empty())
      for (std::size_t i = 0; i < static_cast<std::size_t>(grid.count); ++i) {
        const std::int64_t d = pdof_[i];
        if (d < 0) continue;
        rhs_[d] -= h * grid.flux[i];
        ref_[d] += std::abs(h * grid.flux[i]);
      }
    // The particles, in one fixed chunk per thread: thread 0 adds into
    // rhs_, ref_ and the matrix, thread t > 0 into its private copies
    // (partial_), which are then added in thread order, entry by entry, and
    // cleared: the sums are reproducible for a given thread count.
    auto chunk = [&](int t, std::size_t b, std::size_t e) {
      if (t == 0) {
        assemble_particles(b, e, h, jacobian, rhs_.data(), ref_.data(),
                           jacobian ? system_.values() : nullptr);
        return;
      }
      Partial& w = partial_[static_cast<std::size_t>(t - 1)];
      assemble_particles(b, e, h, jacobian, w.rhs.data(), w.ref.data(),
                         jacobian ? w.values.data() : nullptr);
    };
    if (partial_.empty()) {
      chunk(0, 0, parts.size());
    } else {
      c_.threads.pool->for_ranges(parts.size(), chunk);
      double* values = system_.values();
      const auto unknowns = static_cast<std::size_t>(unknowns_);
      const auto entries = static_cast<std::size_t>(system_.nonzeros());
      auto reduce = [&](int, std::size_t b, std::size_t e) {
        for (Partial& w : partial_) {
          if (b < unknowns)
            for (std::size_t k = b; k < std::min(e, unknowns); ++k) {
              rhs_[static_cast<Eigen::Index>(k)] += w.rhs[k];
              ref_[static_cast<Eigen::Index>(k)] += w.ref[k];
              w.rhs[k] = 0.0;
              w.ref[k] = 0.0;
            }
          if (!jacobian) continue;
          for (std::size_t k = b; k < std::min(e, entries); ++k) {
            values[k] += w.values[k];
            w.values[k] = 0.0;
          }
        }
      };
      const std::size_t n = std::max(unknowns, jacobian ? entries : 0);
      c_.threads.pool->for_blocks(n, c_.threads.block_of(n, Threads<Dim, Shape>::node_block),
                                  reduce);
    }
    // Pressure stabilisation on the increment p - p^n.
    const std::size_t cells = cell_nodes_.size() / N;
    for (std::size_t cc = 0; cc < cells; ++cc) {
      const std::int64_t* nd = &cell_nodes_[cc * N];
      const double* mm = &cell_matrix_[cc * N * N];
      for (int i = 0; i < N; ++i) {
        const std::int64_t di = pdof_[static_cast<std::size_t>(nd[i])];
        if (di < 0) continue;
        double r = 0.0, ra = 0.0;
        for (int j = 0; j < N; ++j) {
          const auto nj = static_cast<std::size_t>(nd[j]);
          const double term = mm[i * N + j] * (p_[nj] - pn_[nj]);
          r += term;
          ra += std::abs(term);
          const std::int64_t dj = pdof_[nj];
          if (jacobian && dj >= 0 && mm[i * N + j] != 0.0)
            system_.add(di, dj, -e_ref_ * mm[i * N + j]);
        }
        rhs_[di] += r;
        ref_[di] += ra;
      }
    }
    // Surface pressures: the mass balance loses h times each face's
    // outflow C (p_bar - p_face), at the face's weights (a seepage
    // face only while p_bar > 0: a semi-smooth Newton step).
    for (const SurfaceParticle& sp : surface_) {
      StencilT s;
      c_.template stencil_in_step<false, true>(sp.p, s);
      double p_bar = 0.0;
      for (int k = 0; k < N; ++k) p_bar += s.w[k] * p_[static_cast<std::size_t>(s.node[k])];
      if (sp.seepage && !(p_bar > 0.0)) continue;
      const double out = h * sp.c * (p_bar - sp.p_face);
      double w[N];
      face_weights<Dim, Shape>(s, sp.face, c_.grid, c_.particles, sp.p, w);
      for (int k = 0; k < N; ++k) {
        const std::int64_t dk = pdof_[static_cast<std::size_t>(s.node[k])];
        if (dk < 0) continue;
        rhs_[dk] += w[k] * out;
        ref_[dk] += std::abs(w[k] * out);
        if (!jacobian) continue;
        for (int l = 0; l < N; ++l) {
          const std::int64_t dl = pdof_[static_cast<std::size_t>(s.node[l])];
          if (dl >= 0) system_.add(dk, dl, -e_ref_ * h * sp.c * w[k] * s.w[l]);
        }
      }
    }
    // Convergence: each block's residual against the size of its terms.
    double ru = 0, fu = 0, rp = 0, fp = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(grid.count); ++i) {
      for (int a = 0; a < Dim; ++a) {
        const std::int64_t d = udof_[i * Dim + a];
        if (d < 0) continue;
        ru += rhs_[d] * rhs_[d];
        fu += ref_[d] * ref_[d];
      }
      const std::int64_t d = pdof_[i];
      if (d >= 0) {
        rp += rhs_[d] * rhs_[d];
        fp += ref_[d] * ref_[d];
      }
    }
    last_ru_ = fu > 0 ? std::sqrt(ru / fu) : 0.0;
    last_rp_ = fp > 0 ? std::sqrt(rp / fp) : 0.0;
    const double tol = c_.model.problem.time.implicit.tolerance;
    return last_ru_ <= tol && last_rp_ <= tol;
  }

  /// The particles [begin, end) of assemble(): their residual terms added
  /// to rhs and ref and, when `jacobian`, their Jacobian entries to values
  /// (laid out as UpSystem::values()).
  void assemble_particles(std::size_t begin, std::size_t end, double h, bool jacobian, double* rhs,
                          double* ref, double* values) {
    auto& parts = c_.particles;
    const double inv_e = 1.0 / e_ref_;
    const Vec gravity = c_.model.gravity;
    StencilT s;
    std::int64_t dofs[L];
    Eigen::Matrix<double, L, L> a_loc;
    constitutive::Tangent d_alg;
    Eigen::Matrix<double, NC, Dim> db[N];  // tangent times the strain of node l
    const bool consistent_off = c_.model.problem.time.implicit.elastic_tangent;
    // The spin's term where the tangent changes in the step anyway (a soil
    // with a return mapping: the Jacobian is then factorised every
    // iteration, and unsymmetric terms cost an LU instead of an LDL^T);
    // elastic runs keep the symmetric system, whose factor serves every
    // iteration of a step (the term only adds iterations there).
    const bool geometric = Dim >= 2 && jacobian && !consistent_off && c_.model.plastic;
    for (std::size_t p = begin; p < end; ++p) {
      c_.template stencil_in_step<true, true>(p, s);
      local_dofs(s, dofs);
      const MaterialConstants& mc = (*constants_)[parts.material[p]];
      const bool sat = c_.model.fluid && mc.saturated;
      Mat g;
      Voigt de, sig;
      const bool plastic =
          particle_stress(p, s, g, de, sig, jacobian && !consistent_off ? &d_alg : nullptr);
      const double vol = parts.volume[p], m = parts.mass[p];
      const Mat vs = vol * active_stress<Dim>(sig);
      double p_hat = 0.0, div = g.trace();
      Vec grad_p = Vec::Zero();
      if (sat)
        for (int k = 0; k < N; ++k) {
          const double pk = p_[static_cast<std::size_t>(s.node[k])];
          p_hat += s.w[k] * pk;
          grad_p += pk * s.grad(k);
        }
      const double storage = sat ? (1.0 - parts.porosity[p]) * c_.model.inv_ks[parts.material[p]] +
                                       parts.porosity[p] * c_.model.inv_kf[parts.material[p]]
                                 : 0.0;
      const double kg = sat ? permeability_of(mc, parts.varying, p) : 0.0;
      const Vec flow = grad_p - mc.fluid_density * gravity;
      const double p_old = sat ? parts.pressure_out[p] : 0.0;
      for (int k = 0; k < N; ++k) {
        const Vec gk = s.grad(k);
        const Vec fs = vs * gk, fp = (vol * p_hat) * gk, fg = (s.w[k] * m) * gravity;
        for (int a = 0; a < Dim; ++a) {
          const std::int64_t d = dofs[k * (Dim + 1) + a];
          if (d < 0) continue;
          rhs[d] += (fg[a] - fs[a] + fp[a]) * inv_e;
          ref[d] += (std::abs(fg[a]) + std::abs(fs[a]) + std::abs(fp[a])) * inv_e;
        }
        const std::int64_t dp = dofs[k * (Dim + 1) + Dim];
        if (sat && dp >= 0) {
          const double r1 = vol * s.w[k] * storage * (p_hat - p_old);
          const double r2 = vol * s.w[k] * div;
          const double r3 = h * vol * kg * gk.dot(flow);
          rhs[dp] += r1 + r2 + r3;
          // The Darcy term by its two parts: at rest under gravity they
          // cancel (hydrostatic p), and a reference of their sum alone
          // would be round-off, which Newton cannot beat.
          ref[dp] += std::abs(r1) + std::abs(r2) +
                     h * vol * kg *
                         (std::abs(gk.dot(grad_p)) + mc.fluid_density * std::abs(gk.dot(gravity)));
        }
      }
      if (!jacobian) continue;
      // Local Jacobian, scaled as in the file comment: the elastic
      // stiffness (lambda, G), or at plastic points the algorithmic tangent.
      const constitutive::Elastic& el = elastic_of(mc, parts.varying, p);
      const double lam = el.lambda * vol * inv_e, sh = el.shear * vol * inv_e;
      // The Jaumann spin's term: the start stress rotated by the
      // increment's spin is linear in it (objective_rate.hpp), and the
      // rotation is deviatoric, so it enters the update as a change ds of
      // the trial deviator: ds at elastic points, d_alg ds / (2G) at plastic
      // ones (G the step's shear modulus; the trial is s_n + 2G de).
      Mat spin_stress[spin_count<Dim> > 0 ? spin_count<Dim> : 1];
      if (geometric) {
        Voigt dsdw[spin_count<Dim> > 0 ? spin_count<Dim> : 1];
        jaumann_derivatives<Dim>(parts.stress[p], dsdw);
        double g_step = 0.0;
        if (plastic)
          g_step = mc.model == Model::modified_cam_clay
                       ? constitutive::cam_clay_step_shear_modulus(
                             mc.cam_clay, parts.stress[p],
                             parts.internal[constitutive::ModifiedCamClayModel::void_ratio_slot][p])
                       : el.shear;
        for (int w = 0; w < spin_count<Dim>; ++w) {
          const Voigt ds = plastic ? Voigt(d_alg * dsdw[w] / (2.0 * g_step)) : dsdw[w];
          spin_stress[w] = (vol * inv_e) * active_stress<Dim>(ds);
        }
      }
      if (plastic) {
        Eigen::Matrix<double, NC, NC> dr;
        for (int i = 0; i < NC; ++i)
          for (int j = 0; j < NC; ++j) dr(i, j) = d_alg(component(i), component(j)) * vol * inv_e;
        for (int l = 0; l < N; ++l) db[l].noalias() = dr * strain_of(s.grad(l), 0.5);
      }
      for (int k = 0; k < N; ++k) {
        const Vec gk = s.grad(k);
        Eigen::Matrix<double, NC, Dim> bk = Eigen::Matrix<double, NC, Dim>::Zero();
        if (plastic) bk = strain_of(gk, 1.0);
        // The spin term's stress per node k (independent of l).
        Vec spin_k[spin_count<Dim> > 0 ? spin_count<Dim> : 1];
        if (geometric)
          for (int w = 0; w < spin_count<Dim>; ++w) spin_k[w] = spin_stress[w] * gk;
        for (int l = 0; l < N; ++l) {
          const Vec gl = s.grad(l);
          const double gg = gk.dot(gl);
          if (plastic) {
            const Eigen::Matrix<double, Dim, Dim> kl = bk.transpose() * db[l];
            for (int a = 0; a < Dim; ++a)
              for (int b = 0; b < Dim; ++b) a_loc(k * (Dim + 1) + a, l * (Dim + 1) + b) = kl(a, b);
          } else {
            for (int a = 0; a < Dim; ++a)
              for (int b = 0; b < Dim; ++b)
                a_loc(k * (Dim + 1) + a, l * (Dim + 1) + b) =
                    lam * gk[a] * gl[b] + sh * (gk[b] * gl[a] + (a == b ? gg : 0.0));
          }
          if (geometric)
            for (int w = 0; w < spin_count<Dim>; ++w) {
              const Vec& t = spin_k[w];
              for (int b = 0; b < Dim; ++b) {
                const double cw = spin_gradient<Dim>(w, b, gl);
                if (cw == 0.0) continue;
                for (int a = 0; a < Dim; ++a)
                  a_loc(k * (Dim + 1) + a, l * (Dim + 1) + b) += t[a] * cw;
              }
            }
          for (int a = 0; a < Dim; ++a) {
            a_loc(k * (Dim + 1) + a, l * (Dim + 1) + Dim) = sat ? -vol * gk[a] * s.w[l] : 0.0;
            a_loc(k * (Dim + 1) + Dim, l * (Dim + 1) + a) = sat ? -vol * s.w[k] * gl[a] : 0.0;
          }
          a_loc(k * (Dim + 1) + Dim, l * (Dim + 1) + Dim) =
              sat ? -e_ref_ * vol * (storage * s.w[k] * s.w[l] + h * kg * gg) : 0.0;
        }
      }
      for (int r = 0; r < L; ++r) {
        if (dofs[r] < 0) continue;
        for (int c = 0; c < L; ++c)
          if (dofs[c] >= 0 && a_loc(r, c) != 0.0)
            values[system_.offset(dofs[r], dofs[c])] += a_loc(r, c);
      }
    }
  }

  /// The force each boundary exerts on the soil in the converged state
  /// (before commit moves the particles): minus the residual R_u (external
  /// minus internal force, phases/reactions.hpp) at the node components
  /// charged to it. At a prescribed component that is the force holding the
  /// prescribed increment; at a tied one (summed over the tie) and at a
  /// friction wall's tangential one (frictionless here) it is the Newton
  /// residual, zero within the tolerance. Serial over the particles, on
  /// the steps the time loop samples only.
  void tally_reactions() {
    auto& parts = c_.particles;
    const auto& grid = c_.grid;
    const std::vector<int>& owner = c_.reactions.owner;
    std::vector<Vec3>& reaction = c_.reactions.force;
    for (Vec3& r : reaction) r = {0.0, 0.0, 0.0};
    for (const auto& ch : c_.reactions.charges)  // the tractions at t + h
      reaction[static_cast<std::size_t>(ch.boundary)][static_cast<std::size_t>(ch.axis)] -=
          grid.force[ch.node][ch.axis];
    const Vec gravity = c_.model.gravity;
    StencilT s;
    for (std::size_t p = 0; p < parts.size(); ++p) {
      c_.template stencil_in_step<true, true>(p, s);
      Mat g;
      Voigt de, sig;
      particle_stress(p, s, g, de, sig);
      const bool sat = c_.model.fluid && (*constants_)[parts.material[p]].saturated;
      const double vol = parts.volume[p], m = parts.mass[p];
      const Mat vs = vol * active_stress<Dim>(sig);
      double p_hat = 0.0;
      if (sat)
        for (int k = 0; k < N; ++k) p_hat += s.w[k] * p_[static_cast<std::size_t>(s.node[k])];
      for (int k = 0; k < N; ++k) {
        const auto i = static_cast<std::size_t>(s.node[k]);
        const Vec gk = s.grad(k);
        const Vec fs = vs * gk, fp = (vol * p_hat) * gk, fg = (s.w[k] * m) * gravity;
        for (int a = 0; a < Dim; ++a) {
          const int b = owner[i * Dim + static_cast<std::size_t>(a)];
          if (b >= 0)
            reaction[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)] -=
                fg[a] - fs[a] + fp[a];
        }
      }
    }
  }

  /// The converged step: particles take the stress, strain, volume,
  /// porosity, pressure and Darcy velocity of du and p, and move by N du.
  void commit(double h) {
    // Each particle's update is its own (no sums): blocks on any thread.
    c_.for_particles(0u, [&](const auto&, std::size_t begin, std::size_t end) {
      commit_particles(begin, end, h);
    });
    prepared_ = false;
  }

  void commit_particles(std::size_t begin, std::size_t end, double h) {
    auto& parts = c_.particles;
    auto& grid = c_.grid;
    StencilT s;
    for (std::size_t p = begin; p < end; ++p) {
      c_.template stencil_in_step<true, true>(p, s);
      Mat g;
      Voigt de, sig;
      double plastic = 0.0;
      particle_stress(p, s, g, de, sig, nullptr, &plastic, /*commit=*/true);
      parts.stress[p] = sig;
      if (plastic > 0.0) parts.plastic_strain[p] += equivalent_plastic_strain(plastic);
      yielded_[p] = plastic > 0.0 ? 1 : 0;
      parts.strain[p] += de;
      Mat f = Mat::Identity() + g;
      const double j = f.determinant();
      if (!(j > 0.0)) c_.failures.volume(p, j);
      parts.volume[p] *= j;
      const MaterialConstants& mc = (*constants_)[parts.material[p]];
      Vec dx = Vec::Zero();
      for (int k = 0; k < N; ++k) {
        const auto i = static_cast<std::size_t>(s.node[k]);
        for (int a = 0; a < Dim; ++a) dx[a] += s.w[k] * du_[i * Dim + a];
      }
      if (c_.model.fluid && mc.saturated) parts.porosity[p] = 1.0 - (1.0 - parts.porosity[p]) / j;
      if (c_.model.fluid && mc.saturated && !reducing_) {
        double p_hat = 0.0;
        Vec grad_p = Vec::Zero();
        for (int k = 0; k < N; ++k) {
          const double pk = p_[static_cast<std::size_t>(s.node[k])];
          p_hat += s.w[k] * pk;
          grad_p += pk * s.grad(k);
        }
        parts.pressure[p] = p_hat;
        parts.pressure_out[p] = p_hat;
        parts.darcy[p] =
            -permeability_of(mc, parts.varying, p) * (grad_p - mc.fluid_density * c_.model.gravity);
        if (!std::isfinite(p_hat)) c_.failures.nonfinite(p, "pore pressure");
      }
      parts.v[p] = dx / h;
      Vec& x = parts.x[p];
      x += dx;
      bool inside = x.allFinite();
      for (int a = 0; a < Dim; ++a)
        inside = inside && x[a] >= grid.origin[a] && x[a] <= c_.model.grid_max[a];
      if (!inside) {
        if (!x.allFinite())
          c_.failures.nonfinite(p, "displacement");
        else
          c_.failures.left_grid(p);
      }
    }
  }

  /// A collapse at t (the last converged time): the report in the
  /// failures (the first one), and the run stopped or warned as
  /// time.on_collapse says. `count` cut-backs, the step down to `h`.
  void collapse(double t, const char* criterion, std::int64_t count, double h) {
    RunResult::Collapse found;
    RunResult::Collapse& k = c_.failures.collapse.found ? found : c_.failures.collapse;
    k.found = true;
    k.time = t;
    k.criterion = criterion;
    // The load level: the resultant of the surface loads at t.
    auto& grid = c_.grid;
    for (std::size_t i = 0; i < static_cast<std::size_t>(grid.count); ++i) grid.force[i].setZero();
    apply_dead_loads(t);
    k.load = {0.0, 0.0, 0.0};
    for (std::size_t i = 0; i < static_cast<std::size_t>(grid.count); ++i)
      for (int a = 0; a < Dim; ++a) k.load[static_cast<std::size_t>(a)] += grid.force[i][a];
    // Where it yields: the particles plastic in the last converged step.
    const auto& parts = c_.particles;
    k.yielding = 0;
    for (std::size_t p = 0; p < parts.size() && p < yielded_.size(); ++p) {
      if (!yielded_[p]) continue;
      for (int a = 0; a < Dim; ++a) {
        const auto u = static_cast<std::size_t>(a);
        k.yield_min[u] = k.yielding ? std::min(k.yield_min[u], parts.x[p][a]) : parts.x[p][a];
        k.yield_max[u] = k.yielding ? std::max(k.yield_max[u], parts.x[p][a]) : parts.x[p][a];
      }
      ++k.yielding;
    }
    k.max_displacement = max_displacement();
    const bool stop = collapse_action(c_.model.problem.time) == CollapseAction::stop;
    const bool impossible = std::string(criterion) == "no_convergence";
    k.stopped = stop || impossible;
    if (&k == &found) c_.failures.collapse.stopped = k.stopped;  // reported before, going on
    std::ostringstream what;
    what << "the soil collapses: at t = " << number(t) << " s ";
    if (impossible)
      what << "the Newton iterations do not converge even after " << count
           << " cut-backs (step down to " << number(h) << " s)";
    else
      what << count << " cut-backs in a row, none of the steps converging at its first length "
           << "(step down to " << number(h) << " s)";
    what << ": a limit load; surface loads " << vector_text(k.load) << " N";
    if (Dim < 3) what << (Dim == 2 ? "/m" : "/m^2");
    what << ", largest displacement " << number(k.max_displacement) << " m, " << k.yielding
         << " particles yielding";
    if (k.yielding > 0)
      what << " in " << vector_text(k.yield_min) << " .. " << vector_text(k.yield_max);
    k.message = what.str();
    if (k.stopped)
      c_.failures.fail_run(
          k.message, impossible && !stop
                         ? "past a limit load the quasi-static scheme has no state to go on to "
                           "(time.on_collapse 'continue' cannot apply); lower the loads below the "
                           "limit, or prescribe a displacement (a velocity) instead of a load to "
                           "follow the soil past it"
                         : "lower the loads below the limit, prescribe a displacement (a velocity) "
                           "instead of a load to follow the soil past it, or set "
                           "time.on_collapse to 'continue'");
  }

  /// "(x, y)" of the first Dim components.
  static std::string vector_text(const Vec3& v) {
    std::string s = "(";
    for (int a = 0; a < Dim; ++a) s += (a ? ", " : "") + number(v[static_cast<std::size_t>(a)]);
    return s + ")";
  }

  Context c_;
  /// The material constants in force: the model's, or those of a strength
  /// reduction (strength_reduce()).
  const std::vector<MaterialConstants>* constants_ = &c_.model.constants;
  bool reducing_ = false;
  int reduce_iterations_ = 0;    ///< Newton iterations of a strength-reduction trial
  std::int64_t backtracks_ = 0;  ///< line-search halvings (backtrack())
  std::int64_t crawl_ = 0;       ///< cut-backs since a step converged at its first length
  /// Per particle: plastic in the last converged step (the collapse report).
  std::vector<std::uint8_t> yielded_;
  StepGrowth growth_;
  double nominal_ = 0.0;
  double e_ref_ = 0.0;
  /// prepare(): a node's summed particle weight below this counts as none.
  double tiny_ = 0.0;
  bool prepared_ = false;
  std::vector<std::int64_t> seepage_;  ///< seepage face nodes
  /// A particle a surface pressure selects, in the step being attempted.
  struct SurfaceParticle {
    std::size_t p;
    double c, p_face;  ///< conductance, face pressure at t + h
    bool seepage;
    Vec face;  ///< the face's centre
  };
  std::vector<SurfaceParticle> surface_;
  std::vector<std::uint8_t> held_;  ///< per node: a face node held at p = 0 this step
  std::int64_t unknowns_ = 0;

  std::vector<double> weight_, weight_fluid_, pn_, du_, p_;
  std::vector<std::int64_t> udof_, pdof_;
  std::vector<std::uint8_t> ufixed_, pfixed_;
  std::vector<std::pair<std::int64_t, std::int64_t>> keys_;  ///< (stencil anchor, particle)
  std::vector<std::int64_t> cell_nodes_;                     ///< N per stabilisation cell
  std::vector<double> cell_matrix_;                          ///< N x N per cell
  Eigen::VectorXd rhs_, ref_, x_;
  UpSystem system_;
  struct Partial {
    std::vector<double> rhs, ref, values;  ///< as rhs_, ref_, UpSystem::values()
  };
  std::vector<Partial> partial_;  ///< threads 1.. of assemble()

  double last_ru_ = 0.0, last_rp_ = 0.0;
  std::vector<double> history_, worst_;  ///< residuals of this step / of the worst one
  std::int64_t nonlinear_ = 0, cutbacks_ = 0;
  int max_nonlinear_ = 0;
};

}  // namespace hmpm
