// schemes/semi_implicit_scheme.hpp — the semi-implicit u-p scheme
// (internal): explicit momentum, implicit pore pressure.
//
// An incremental pressure projection (Chorin type, after Kularathna et al.
// 2021) inside the explicit scheme's MUSL cycle. The predictor is the
// explicit step up to the nodal momentum, with the pressure p^n: velocity
// v*, acceleration a*. The pressure increment dp = p^{n+1} - p^n then
// solves the mass balance at t + dt,
//   Q dp/dt = -div v^{n+1} - div w^{n+1},
// with the increment's own effect substituted: v^{n+1} = v* - dt grad dp/rho
// and, through Darcy's rho_f a term, w^{n+1} = w* - k/gw (1 - rho_f/rho)
// grad dp, w* = -k/gw (grad p^n - rho_f b + rho_f a*). On the grid:
//   [S + L_c] dp = dt F(v*, w*),
//   S_ii = sum_p N_i Q V (the explicit storage), L_c,ij = sum_p c_p V_p
//   grad N_i . grad N_j, c_p = dt^2/rho_p + dt k/gw (1 - rho_f/rho_p),
// F the explicit scheme's flux sum_p V (grad N_i . w* - N_i div v*), v*
// the predicted velocity as the strain update will see it: the particles'
// velocities advanced with a* and re-mapped to the nodes (MUSL), so the
// pressure follows the same divergence as the skeleton (with the plain
// nodal v*, one particle per cell left a 1-1.5 % error next to a drained
// face: the nodal and the re-mapped divergence differ there). The
// matrix is symmetric positive definite (rho_f < rho). Prescribed-pressure
// nodes take dp = p(t + dt) - p^n, moved to the right-hand side. The
// corrector adds the force of dp, sum_p V dp_hat grad N_i, to the nodal
// momentum and re-applies the velocity constraints; the rest of the step is
// the explicit MUSL step with dp in place of the explicit increment. Only
// the skeleton's wave then limits dt (semi_implicit_rules.cpp). Dry runs:
// the explicit step.
//
// Linear algebra: linear/pressure_system.hpp (Eigen sparse LDL^T or
// conjugate gradients with incomplete Cholesky). The Laplacian is assembled
// over the particles into a per-node box of couplings, threaded like the
// explicit phases (private boxes over each thread's band of nodes, added in
// thread order), as are the predicted re-map, the flux and the corrector's
// force.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "boundary/apply.hpp"
#include "linear/pressure_system.hpp"
#include "phases/grid.hpp"
#include "phases/grid_to_particle.hpp"
#include "phases/particle_to_grid.hpp"
#include "phases/pore_pressure.hpp"
#include "phases/pressure_projection.hpp"
#include "phases/reactions.hpp"
#include "phases/stress_and_flux.hpp"
#include "schemes/state_step.hpp"
#include "schemes/time_scheme.hpp"
#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
class SemiImplicitScheme final : public TimeScheme {
 public:
  using Context = StepContext<Dim, Shape>;
  using Out = Scatter<Dim>;
  using Vec = VecD<Dim>;
  using Box = CouplingBox<Dim, Shape::K>;

  explicit SemiImplicitScheme(Context c) : c_(c) {
    if (!c_.model.fluid) return;
    const auto n = static_cast<std::size_t>(c_.grid.count);
    box_.assign(n * Box::size, 0.0);
    active_.assign(n, 0);
    prescribed_.assign(n, 0);
    unknown_.assign(n, -1);
    node_of_.assign(n, 0);
    rhs_.assign(n, 0.0);
    x_.assign(n, 0.0);
    last_dp_.assign(n, 0.0);
    for (const PressureConstraint& bc : c_.model.constraints.pressure)
      for (std::int64_t i : bc.nodes) prescribed_[static_cast<std::size_t>(i)] = 1;
    for (const SeepageFace& face : c_.model.constraints.seepage)
      seepage_.insert(seepage_.end(), face.nodes.begin(), face.nodes.end());
    for (int o = 0; o < Box::size; ++o)
      node_offset_[static_cast<std::size_t>(o)] = Box::node_offset(o, c_.grid.stride);
  }

  StableStep stable_step(const Problem& problem) const override {
    return semi_implicit_scheme_rules().stable_step(problem);
  }

  /// With an automatic dt and a soil whose stiffness follows its state
  /// (StableStep::follows_state): the stable step at the particles' state
  /// now (schemes/state_step.hpp).
  double next_dt(double /*t*/) override {
    return state_stable_dt(c_.model.problem, c_.model.stable, c_.model.constants, c_.particles,
                           /*undrained=*/false);
  }

  void step(double t, double dt) override {
    if (!set_local_damping(t)) return;
    hmpm::clear_grid(c_);
    map_particles_to_grid();
    if (c_.model.fluid) {
      hmpm::compute_nodal_pressure(c_, t);
      map_pore_pressure_force();
    }
    hmpm::apply_surface_loads(c_, t);
    hmpm::update_nodal_momentum(c_, t, dt);  // the predictor v*, a*
    if (c_.model.fluid) {
      if (!solve_pressure_increment(t, dt)) return;
      correct_nodal_momentum(t, dt);
    }
    // Reactions with the corrector's pressure-increment force (kept by
    // correct_nodal_momentum) among the nodal forces.
    if (c_.reactions.due) hmpm::tally_reactions(c_, /*with_extra=*/c_.model.fluid);
    update_particle_velocities_and_remap(dt);
    hmpm::compute_remapped_nodal_velocity(c_, t + dt, dt);
    update_particle_stress(dt);
    if (c_.model.fluid) update_particle_pressure_and_position(dt);
  }

  void report(RunResult& result) const override {
    result.iterations.solves += solves_;
    result.iterations.linear += linear_iterations_;
  }

  /// The last increment (the iterative solver's initial guess) and the counters.
  void save(checkpoint::Writer& w) const override {
    w.array(last_dp_);
    w.pod(solves_);
    w.pod(linear_iterations_);
  }
  void load(checkpoint::Reader& r) override {
    r.array(last_dp_, static_cast<std::int64_t>(last_dp_.size()), "pressure increment");
    solves_ = r.pod<std::int64_t>();
    linear_iterations_ = r.pod<std::int64_t>();
  }

 private:
  bool set_local_damping(double t) {
    const Problem& problem = c_.model.problem;
    c_.damping = problem.local_damping ? problem.local_damping(t) : 0.0;
    if (c_.damping >= 0.0 && c_.damping < 1.0) return true;
    c_.failures.fail_run(
        "local_damping is " + number(c_.damping) + " at t = " + number(t) + " s, outside [0, 1)",
        "keep the local_damping formula between 0 and 1 (exclusive) at all times");
    return false;
  }

  /// Assembles and solves [S + L_c] dp = dt F into grid dp; false (a
  /// failure of the run) when the solve fails. Nodal remap holds the
  /// predicted re-mapped velocity while F is scattered, then is zeroed
  /// again (the step's re-map proper comes later).
  bool solve_pressure_increment(double t, double dt) {
    auto& grid = c_.grid;
    dt_ = dt;
    c_.for_particles(nodal::bit(nodal::remap), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_predicted_velocity(c_, out, b, e, dt);
    });
    const double tol = c_.model.mass_tolerance;
    c_.for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) {
        const double m = grid.mass[i];
        grid.remap[i] = m > tol ? Vec(grid.remap[i] / m) : Vec::Zero();
      }
    });
    apply_remap_constraints(c_.model.constraints, grid, tol, t + dt);
    c_.for_particles(nodal::bit(nodal::flux), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_predicted_fluid_flux(c_, out, b, e);
    });
    hmpm::apply_boundary_fluxes(c_, t + dt);
    c_.for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) grid.remap[i].setZero();
    });
    assemble_laplacian(dt);
    add_surface_pressures(t + dt);
    std::fill(grid.dp.begin(), grid.dp.end(), 0.0);
    apply_pressure_increment_constraints(c_.model.constraints, grid, t + dt);
    // Seepage faces: an active set. Every face node starts free (no water
    // enters a free node); a node the solve would raise above p = 0 is held
    // there (dp = -p: the water that would raise it leaves) and the system
    // solved again, until no free face node rises above zero: per step the
    // complementarity p <= 0, outflow >= 0 of the explicit scheme's rule.
    bool ok = solve_once();
    for (std::size_t round = 0; ok && round < seepage_.size(); ++round) {
      bool changed = false;
      for (std::int64_t i : seepage_) {
        const auto u = static_cast<std::size_t>(i);
        if (prescribed_[u] || grid.pressure[u] + grid.dp[u] <= 0.0) continue;
        prescribed_[u] = 1;
        grid.dp[u] = -grid.pressure[u];
        changed = true;
      }
      if (!changed) break;
      ok = solve_once();
    }
    // Seepage faces of particles (surface_pressures): an active set too. A
    // face lets water out while the pressure at its particle is positive;
    // one that would take water in leaves the system, one whose particle
    // rises above zero joins it, until none changes.
    for (std::size_t round = 0; ok && round <= surface_.size(); ++round) {
      bool changed = false;
      for (SurfaceParticle& sp : surface_) {
        if (!sp.seepage) continue;
        const bool out = sp.p_bar + interpolate(sp.p, grid.dp) > 0.0;
        if (out == sp.active) continue;
        sp.active = out;
        add_surface_term(sp, out ? 1.0 : -1.0);
        changed = true;
      }
      if (!changed) break;
      ok = solve_once();
    }
    for (std::int64_t i : seepage_) prescribed_[static_cast<std::size_t>(i)] = 0;
    // The coupling boxes and activity flags, cleared for the next step.
    for (std::size_t u = 0; u < active_.size(); ++u) {
      if (!active_[u]) continue;
      active_[u] = 0;
      std::fill(box_.data() + u * Box::size, box_.data() + (u + 1) * Box::size, 0.0);
    }
    return ok;
  }

  /// A particle a surface pressure selects (boundary/surface_pressures.hpp):
  /// its conductance, face pressure, pressure p^n at the particle, and
  /// whether its terms are in the system.
  struct SurfaceParticle {
    std::size_t p = 0;
    double c = 0.0, p_face = 0.0, p_bar = 0.0;
    VecD<Dim> face = VecD<Dim>::Zero();
    bool seepage = false, active = false;
  };

  /// sum N_i f_i at particle p.
  double interpolate(std::size_t p, const std::vector<double>& f) const {
    typename Context::StencilT s;
    c_.template stencil_in_step<false, true>(p, s);
    double v = 0.0;
    for (int k = 0; k < Context::StencilT::N; ++k)
      v += s.w[k] * f[static_cast<std::size_t>(s.node[k])];
    return v;
  }

  /// Surface pressures at t + dt (boundary/surface_pressures.hpp): the
  /// exchange C w (p_face - p_bar^n) into the right-hand side (as flux)
  /// and C dt N N^T into the couplings (implicit in the increment, zero at
  /// steady state); seepage faces start active where p_bar^n > 0.
  void add_surface_pressures(double t) {
    surface_.clear();
    if (c_.model.surface_pressures.empty()) return;
    for_surface_particles<Dim>(
        c_.model.surface_pressures, c_.particles, c_.model.constants, t,
        [&](std::size_t p, double c, double p_face, bool seepage, const Vec& face) {
          SurfaceParticle sp{p, c, p_face, 0.0, face, seepage, false};
          sp.p_bar = interpolate(p, c_.grid.pressure);
          sp.active = !seepage || sp.p_bar > 0.0;
          if (sp.active) add_surface_term(sp, 1.0);
          surface_.push_back(sp);
        });
  }

  /// Adds (sign 1) or takes out (-1) a surface particle's terms.
  void add_surface_term(const SurfaceParticle& sp, double sign) {
    static constexpr auto offsets = Box::offsets();
    typename Context::StencilT s;
    c_.template stencil_in_step<false, true>(sp.p, s);
    const double q = sign * sp.c * (sp.p_face - sp.p_bar), cdt = sign * sp.c * dt_;
    double w[Context::StencilT::N];
    face_weights<Dim, Shape>(s, sp.face, c_.grid, c_.particles, sp.p, w);
    for (int k = 0; k < Context::StencilT::N; ++k) {
      const std::int64_t i = s.node[k];
      const auto u = static_cast<std::size_t>(i);
      active_[u] = 1;
      c_.grid.flux[u] += w[k] * q;
      double* const row = box_.data() + u * Box::size;
      const auto& off = offsets[static_cast<std::size_t>(k)];
      for (int l = 0; l < Context::StencilT::N; ++l)
        if (s.node[l] >= i) row[off[static_cast<std::size_t>(l)]] += cdt * s.w[k] * s.w[l];
    }
  }

  /// Numbers the unknowns (active free nodes), assembles the system from
  /// the coupling boxes (kept: a seepage face may ask for another solve)
  /// and solves it into grid dp; false (a failure of the run) when the
  /// solve fails.
  bool solve_once() {
    auto& grid = c_.grid;
    const double dt = dt_;
    // Unknowns: active, free nodes with a positive diagonal, in node order.
    const std::int64_t count = grid.count;
    int n = 0;
    for (std::int64_t i = 0; i < count; ++i) {
      const auto u = static_cast<std::size_t>(i);
      const bool unknown = active_[u] && !prescribed_[u] &&
                           grid.storage[u] + box_[u * Box::size + Box::center] > 0.0;
      unknown_[u] = unknown ? n : -1;
      if (unknown) node_of_[static_cast<std::size_t>(n++)] = i;
    }
    std::fill(rhs_.begin(), rhs_.begin() + n, 0.0);
    system_.begin(n, static_cast<std::int64_t>(n) * (Box::center + 1));
    for (std::int64_t i = 0; i < count; ++i) {
      const auto u = static_cast<std::size_t>(i);
      if (!active_[u]) continue;
      double* const row = box_.data() + u * Box::size;
      const int c = unknown_[u];
      if (c >= 0) {
        rhs_[static_cast<std::size_t>(c)] += dt * grid.flux[u];
        system_.add(c, grid.storage[u] + row[Box::center]);
      }
      for (int o = Box::center + 1; o < Box::size; ++o) {
        const double v = row[o];
        if (v == 0.0) continue;
        const std::int64_t j = i + node_offset_[static_cast<std::size_t>(o)];
        const int cj = unknown_[static_cast<std::size_t>(j)];
        if (c >= 0 && cj >= 0)
          system_.add(cj, v);
        else if (c >= 0 && prescribed_[static_cast<std::size_t>(j)])
          rhs_[static_cast<std::size_t>(c)] -= v * grid.dp[static_cast<std::size_t>(j)];
        else if (cj >= 0 && prescribed_[u])
          rhs_[static_cast<std::size_t>(cj)] -= v * grid.dp[u];
      }
      if (c >= 0) system_.end_column();
    }
    if (n == 0) return true;
    for (int c = 0; c < n; ++c)
      x_[static_cast<std::size_t>(c)] =
          last_dp_[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(c)])];
    Eigen::Map<const Eigen::VectorXd> b(rhs_.data(), n);
    Eigen::Map<Eigen::VectorXd> x(x_.data(), n);
    if (!b.allFinite()) {
      c_.failures.fail_run(
          "the predicted velocity or fluid flux became non-finite: the run diverged",
          failure_hint(true));
      return false;
    }
    const ImplicitControl& control = c_.model.problem.time.implicit;
    const PressureSystem::Outcome r =
        system_.solve(b, x, control.linear_solver, control.linear_tolerance, Dim);
    ++solves_;
    linear_iterations_ += r.iterations;
    if (!r.ok) {
      std::string what = "the pore pressure system of the semi-implicit step could not be solved (";
      if (r.direct) {
        what += "the sparse LDL^T factorisation failed or gave a non-finite increment";
      } else {
        what += "conjugate gradients reached a relative residual of ";
        what += number(r.residual);
        what += " after ";
        what += std::to_string(r.iterations);
        what += " iterations";
      }
      what += ")";
      c_.failures.fail_run(std::move(what), failure_hint(r.direct));
      return false;
    }
    for (int c = 0; c < n; ++c) {
      const auto i = static_cast<std::size_t>(node_of_[static_cast<std::size_t>(c)]);
      grid.dp[i] = x_[static_cast<std::size_t>(c)];
      last_dp_[i] = grid.dp[i];
    }
    return true;
  }

  /// What to change when the pressure step fails (direct: no advice on
  /// the linear solver).
  std::string failure_hint(bool direct) const {
    std::string hint = "reduce time.dt or time.courant (the stable step estimate is ";
    hint += number(c_.model.stable.limit);
    hint += " s), and check moduli, densities, permeabilities and loads for unrealistic values";
    if (!direct) hint += ", or ask for the direct linear solver";
    return hint;
  }

  /// v^{n+1} = v* + dt f_dp/m, a^{n+1} = a* + f_dp/m, then the velocity
  /// constraints of the step again (the increment's force acts like any
  /// other force: prescribed components keep their values, ties and
  /// friction see the corrected velocity).
  void correct_nodal_momentum(double t, double dt) {
    auto& grid = c_.grid;
    c_.for_particles(nodal::bit(nodal::remap), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_pressure_increment_force(c_, out, b, e);
    });
    if (c_.reactions.due) hmpm::record_reaction_extra_force(c_, grid.remap);
    const double tol = c_.model.mass_tolerance;
    c_.for_nodes([&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i) {
        const double m = grid.mass[i];
        if (m > tol) {
          const Vec da = grid.remap[i] / m;
          grid.accel[i] += da;
          grid.velocity[i] += dt * da;
        }
        grid.remap[i].setZero();
      }
    });
    apply_velocity_constraints(c_.model.constraints, grid, tol, t, dt);
  }

  // The particle phases, as in the explicit scheme.
  void map_particles_to_grid() {
    using namespace nodal;
    const unsigned sums = bit(mass) | bit(momentum) | bit(force) |
                          (c_.model.fluid ? bit(storage) | bit(pressure) : 0u);
    c_.for_particles(sums, [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_particles_to_grid(c_, out, b, e);
    });
  }
  void map_pore_pressure_force() {
    c_.for_particles(nodal::bit(nodal::force), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::map_pore_pressure_force(c_, out, b, e);
    });
  }
  void update_particle_velocities_and_remap(double dt) {
    c_.for_particles(nodal::bit(nodal::remap), [&](const Out& out, std::size_t b, std::size_t e) {
      hmpm::update_particle_velocities_and_remap(c_, out, b, e, dt);
    });
  }
  void update_particle_stress(double dt) {
    c_.for_particles(0u, [&](const Out& out, std::size_t b, std::size_t e) {
      if (c_.model.fluid) {
        if (c_.model.plastic)
          hmpm::update_particle_stress_and_fluid_flux<true, true, false>(c_, out, b, e, dt);
        else
          hmpm::update_particle_stress_and_fluid_flux<true, false, false>(c_, out, b, e, dt);
      } else {
        if (c_.model.plastic)
          hmpm::update_particle_stress_and_fluid_flux<false, true>(c_, out, b, e, dt);
        else
          hmpm::update_particle_stress_and_fluid_flux<false, false>(c_, out, b, e, dt);
      }
    });
  }
  void update_particle_pressure_and_position(double dt) {
    c_.for_particles(0u, [&](const Out&, std::size_t b, std::size_t e) {
      hmpm::update_particle_pressure_and_position(c_, b, e, dt);
    });
  }

  /// The Laplacian into box_ and active_, over one fixed chunk of particles
  /// per thread (the chunks of the step's first phase, whose band of nodes
  /// Threads::touched records): thread 0 straight into box_, thread t >
  /// 0 into a private box over its band, added to box_ after the loop,
  /// node by node in thread order, and cleared: the sums are reproducible
  /// for a given thread count.
  void assemble_laplacian(double dt) {
    const std::size_t threads = c_.threads.touched.size();
    bands_.resize(threads);
    for (std::size_t t = 1; t < threads; ++t) {
      const NodeRange r = c_.threads.touched[t];
      Band& band = bands_[t];
      band.first = r.lo;
      const auto nodes = static_cast<std::size_t>(std::max<std::int64_t>(0, r.hi - r.lo + 1));
      if (band.active.size() < nodes) {  // grows to the largest band, then stays
        band.box.resize(nodes * Box::size, 0.0);
        band.active.resize(nodes, 0);
      }
    }
    auto chunk = [&](int t, std::size_t b, std::size_t e) {
      if (t == 0) {
        hmpm::assemble_pressure_laplacian(c_, b, e, dt, box_.data(), active_.data(), 0);
        return;
      }
      Band& band = bands_[static_cast<std::size_t>(t)];
      hmpm::assemble_pressure_laplacian(c_, b, e, dt, band.box.data(), band.active.data(),
                                        band.first);
    };
    c_.threads.pool->for_ranges(c_.particles.size(), chunk);
    if (threads < 2) return;
    std::int64_t lo = c_.grid.count, hi = -1;
    for (std::size_t t = 1; t < threads; ++t) {
      lo = std::min(lo, c_.threads.touched[t].lo);
      hi = std::max(hi, c_.threads.touched[t].hi);
    }
    if (hi < lo) return;
    auto reduce = [&](int, std::size_t b, std::size_t e) {
      for (std::size_t t = 1; t < threads; ++t) {
        Band& band = bands_[t];
        const std::int64_t first = std::max(lo + static_cast<std::int64_t>(b), band.first);
        const std::int64_t last =
            std::min(lo + static_cast<std::int64_t>(e), c_.threads.touched[t].hi + 1);
        for (std::int64_t i = first; i < last; ++i) {
          const auto u = static_cast<std::size_t>(i), v = static_cast<std::size_t>(i - band.first);
          if (!band.active[v]) continue;
          band.active[v] = 0;
          active_[u] = 1;
          double* const to = box_.data() + u * Box::size;
          double* const from = band.box.data() + v * Box::size;
          for (int o = 0; o < Box::size; ++o) {
            to[o] += from[o];
            from[o] = 0.0;
          }
        }
      }
    };
    const auto nodes = static_cast<std::size_t>(hi - lo + 1);
    c_.threads.pool->for_blocks(nodes, c_.threads.block_of(nodes, Threads<Dim, Shape>::node_block),
                                reduce);
  }

  Context c_;
  PressureSystem system_;
  // Per node (saturated runs): the Laplacian's couplings (zero between
  // steps), a saturated stencil touched it this step, a prescribed pressure,
  // its unknown (-1: none), the right-hand side and solution (first n
  // entries), the last increment (the iterative solver's initial guess).
  std::vector<double> box_;
  std::vector<std::uint8_t> active_, prescribed_;
  std::vector<int> unknown_;
  std::vector<std::int64_t> node_of_;
  std::vector<double> rhs_, x_, last_dp_;
  std::vector<std::int64_t> seepage_;     ///< seepage face nodes (an active set each step)
  std::vector<SurfaceParticle> surface_;  ///< the step's surface-pressure particles
  double dt_ = 0.0;                       ///< the step's length, for solve_once
  std::array<std::int64_t, Box::size> node_offset_{};
  struct Band {
    std::int64_t first = 0;            ///< its lowest node
    std::vector<double> box;           ///< as box_, from node `first`
    std::vector<std::uint8_t> active;  ///< as active_, from node `first`
  };
  std::vector<Band> bands_;  ///< per thread (1..) of assemble_laplacian
  std::int64_t solves_ = 0, linear_iterations_ = 0;
};

}  // namespace hmpm
