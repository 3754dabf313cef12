// boundary/apply.hpp — applying the compiled constraints to the grid (internal).
//
// The grid phase (phases/grid.hpp) computes each node's free update; the
// functions here then impose the constraints of boundary/constraints.hpp,
// twice per step: on the Lagrangian nodal velocity and acceleration
// (apply_velocity_constraints) and on the re-mapped nodal velocity the
// strain rate is computed from (apply_remap_constraints); pore pressure
// constraints on the nodal pressure and its increment.
//
// PRECEDENCE (the one place it is decided: in_precedence_order, after
// apply_absorbing). Where several mechanisms act on the same velocity
// component of a node, they are applied in this order, each later one
// overwriting what the earlier set:
//   1. the free update of the grid phase (momentum + dt force), with the
//      dashpots of absorbing boundaries (apply_absorbing) as forces in it;
//   2. rigid ties: the tied components take the plate's velocity (summed
//      momenta over summed masses) and acceleration;
//   3. friction: the tangential components of a friction wall lose at most
//      mu |normal impulse| of the velocity left by 1-2 (so friction acts on
//      the velocity of a tied plate too);
//   4. prescribed velocity components, of any boundary: always win (a
//      symmetry plane meeting a floor keeps its own component).
// Pore pressure constraints act on the pressure field only and never
// conflict with the velocity mechanisms; two pressure boundaries on one node:
// the later in the Problem wins. A seepage face never holds a node whose
// pressure a boundary prescribes (compile_constraints leaves it out).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "boundary/constraints.hpp"
#include "state/grid.hpp"

namespace hmpm {

/// Calls tie(RigidTie&), friction(VelocityConstraint&) and
/// prescribed(VelocityConstraint&) over every constraint, in the order of
/// precedence above (later calls overwrite earlier ones).
template <class Tie, class Friction, class Prescribed>
inline void in_precedence_order(Constraints& c, Tie&& tie, Friction&& friction,
                                Prescribed&& prescribed) {
  for (RigidTie& t : c.rigid_ties) tie(t);
  for (VelocityConstraint& bc : c.velocity)
    if (bc.has_friction()) friction(bc);
  for (VelocityConstraint& bc : c.velocity) prescribed(bc);
}

/// Coulomb friction at the nodes of a boundary whose normal component
/// (axis bc.normal) is prescribed and whose other components are free.
/// The wall's normal impulse per unit mass is the normal velocity change
/// it imposes on the node's trial velocity, dv_n = v_n(t + dt) - v_n^L.
/// (For these boundaries the particles then receive that full change, see
/// apply_velocity_constraints, so particle velocities the wall has stopped
/// are not mapped back and counted again the next step.) Friction takes at
/// most mu |dv_n| off the tangential velocity (only the compressive part
/// at a grid face, where the material's side is known), relative to a
/// wall at rest tangentially, and never reverses it. A node whose
/// tangential velocity is cancelled sticks (it also keeps zero tangential
/// velocity in the re-mapped field). mu = inf: no slip. The normal
/// component itself is set by the prescribed step of the precedence.
template <int Dim>
inline void apply_friction(VelocityConstraint& bc, GridState<Dim>& grid, double mass_tolerance,
                           double t, double dt) {
  using Vec = VecD<Dim>;
  const int n = bc.normal;
  const double vn_new = (*bc.fn[n])(t + dt);
  for (std::size_t k = 0; k < bc.nodes.size(); ++k) {
    const std::int64_t i = bc.nodes[k];
    const double m = grid.mass[i];
    bc.stuck[k] = 0;
    if (m <= mass_tolerance) continue;
    Vec& v = grid.velocity[i];
    Vec vt = v;
    vt[n] = 0.0;
    const double slip = vt.norm();
    const double impulse = vn_new - v[n];
    const double dvn = bc.inward == 0 ? std::abs(impulse) : std::max(bc.inward * impulse, 0.0);
    const bool stick = slip <= 0.0 || std::isinf(bc.friction) || bc.friction * dvn >= slip;
    const double keep = stick ? 0.0 : 1.0 - bc.friction * dvn / slip;
    const Vec v_start = grid.momentum[i] / m;
    for (int a = 0; a < Dim; ++a) {
      if (a == n) continue;
      v[a] *= keep;
      grid.accel[i][a] = (v[a] - v_start[a]) / dt;
    }
    bc.stuck[k] = stick ? 1 : 0;
  }
}

/// Dashpots (absorbing boundaries) in the free update of the step t -> t +
/// dt, implicit in the new velocity so that no node mass limits dt:
///   m (v - v0) / dt = f + hold + C (v_in(t + dt) - v)
///   =>  v = (m v_free + dt (hold + C v_in)) / (m + dt C),
/// v_free = v0 + dt f / m the free update (after local damping), hold the
/// node's force at rest: -(f + m g) of the first step of the stage (so
/// a column at rest stays at rest; the dynamic part of the load is what the
/// dashpot sees). The acceleration the particles receive is (v - v0) / dt.
/// Explicit scheme only (the semi-implicit corrector would need the
/// dashpots in its pressure system; check_problem refuses the pair).
template <int Dim>
inline void apply_absorbing(Constraints& c, GridState<Dim>& grid, const VecD<Dim>& gravity,
                            double mass_tolerance, double t, double dt) {
  for (AbsorbingConstraint& ab : c.absorbing) {
    double v_in[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < Dim; ++a)
      if (ab.input[a]) v_in[a] = (*ab.input[a])(t + dt);
    for (std::size_t k = 0; k < ab.nodes.size(); ++k) {
      const std::int64_t i = ab.nodes[k];
      const double m = grid.mass[i];
      double* hold = &ab.hold[3 * k];
      const double* coefficient = &ab.coefficient[3 * k];
      if (!ab.held)
        for (int a = 0; a < Dim; ++a)
          hold[a] = m > mass_tolerance ? -(grid.force[i][a] + m * gravity[a]) : 0.0;
      if (m <= mass_tolerance) continue;
      for (int a = 0; a < Dim; ++a) {
        const double v0 = grid.momentum[i][a] / m;
        const double v = (m * grid.velocity[i][a] + dt * (hold[a] + coefficient[a] * v_in[a])) /
                         (m + dt * coefficient[a]);
        grid.velocity[i][a] = v;
        grid.accel[i][a] = (v - v0) / dt;
      }
    }
    ab.held = true;
  }
}

/// Constraints on the Lagrangian nodal velocity and acceleration of the step
/// t -> t + dt (after the grid phase's free update), in precedence order.
template <int Dim>
inline void apply_velocity_constraints(Constraints& c, GridState<Dim>& grid, double mass_tolerance,
                                       double t, double dt) {
  in_precedence_order(
      c,
      [&](RigidTie& tie) {
        for (int a = 0; a < Dim; ++a) {
          if (!tie.axes[a]) continue;
          // The plate's velocity and acceleration: summed momenta and forces
          // (after damping) over summed masses. Every tied node takes both, so
          // particles see the rigid-body acceleration, not the jump that
          // projecting each node's own start velocity onto the plate's would
          // add (that jump, divided by dt, would also enter Darcy's rho_f a).
          double mass = 0.0, momentum = 0.0, momentum0 = 0.0;
          for (std::int64_t i : tie.nodes) {
            mass += grid.mass[i];
            momentum += grid.mass[i] * grid.velocity[i][a];
            momentum0 += grid.momentum[i][a];
          }
          if (!(mass > 0.0)) continue;
          const double v = momentum / mass, accel = (momentum - momentum0) / (mass * dt);
          for (std::int64_t i : tie.nodes) {
            if (grid.mass[i] <= mass_tolerance) continue;
            grid.velocity[i][a] = v;
            grid.accel[i][a] = accel;
          }
        }
      },
      [&](VelocityConstraint& bc) { apply_friction(bc, grid, mass_tolerance, t, dt); },
      [&](VelocityConstraint& bc) {
        for (int a = 0; a < Dim; ++a) {
          if (!bc.fixed[a]) continue;
          const double v_old = (*bc.fn[a])(t), v_new = (*bc.fn[a])(t + dt);
          for (std::int64_t i : bc.nodes) {
            grid.velocity[i][a] = v_new;
            grid.accel[i][a] = (v_new - v_old) / dt;
          }
          // A friction wall gives its nodes' particles the full normal change
          // (see apply_friction), so the normal impulse is counted once.
          if (bc.has_friction() && a == bc.normal)
            for (std::int64_t i : bc.nodes)
              if (grid.mass[i] > mass_tolerance)
                grid.accel[i][a] = (v_new - grid.momentum[i][a] / grid.mass[i]) / dt;
        }
      });
}

/// Rigid ties, before the re-mapped momenta become velocities: each tie's
/// re-mapped velocity, summed momenta over summed masses.
template <int Dim>
inline void gather_rigid_ties(Constraints& c, const GridState<Dim>& grid) {
  for (RigidTie& tie : c.rigid_ties)
    for (int a = 0; a < Dim; ++a) {
      if (!tie.axes[a]) continue;
      double mass = 0.0, momentum = 0.0;
      for (std::int64_t i : tie.nodes) {
        mass += grid.mass[i];
        momentum += grid.remap[i][a];
      }
      tie.remapped[a] = mass > 0.0 ? momentum / mass : 0.0;
    }
}

/// Constraints on the re-mapped nodal velocity at t_new (after
/// gather_rigid_ties and the division by mass), in precedence order: tied
/// components take the tie's velocity, stuck friction nodes keep zero
/// tangential velocity, prescribed components their value at t_new.
template <int Dim>
inline void apply_remap_constraints(Constraints& c, GridState<Dim>& grid, double mass_tolerance,
                                    double t_new) {
  in_precedence_order(
      c,
      [&](RigidTie& tie) {
        for (int a = 0; a < Dim; ++a) {
          if (!tie.axes[a]) continue;
          for (std::int64_t i : tie.nodes)
            if (grid.mass[i] > mass_tolerance) grid.remap[i][a] = tie.remapped[a];
        }
      },
      [&](VelocityConstraint& bc) {
        for (std::size_t k = 0; k < bc.stuck.size(); ++k)
          if (bc.stuck[k])
            for (int a = 0; a < Dim; ++a)
              if (a != bc.normal) grid.remap[bc.nodes[k]][a] = 0.0;
      },
      [&](VelocityConstraint& bc) {
        for (int a = 0; a < Dim; ++a) {
          if (!bc.fixed[a]) continue;
          const double v = (*bc.fn[a])(t_new);
          for (std::int64_t i : bc.nodes) grid.remap[i][a] = v;
        }
      });
}

/// Prescribed nodal pore pressure at time t.
template <int Dim>
inline void apply_pressure_constraints(const Constraints& c, GridState<Dim>& grid, double t) {
  for (const PressureConstraint& bc : c.pressure)
    bc.for_values(t, [&](std::int64_t i, double value) { grid.pressure[i] = value; });
}

/// Prescribed nodes' pressure increment: to their value at t_new.
template <int Dim>
inline void apply_pressure_increment_constraints(const Constraints& c, GridState<Dim>& grid,
                                                 double t_new) {
  for (const PressureConstraint& bc : c.pressure)
    bc.for_values(t_new,
                  [&](std::int64_t i, double value) { grid.dp[i] = value - grid.pressure[i]; });
}

/// Seepage faces on the nodal pressure at the start of a step: a face node
/// never holds a positive pressure (water there drains: p = 0).
template <int Dim>
inline void apply_seepage_pressure(const Constraints& c, GridState<Dim>& grid) {
  for (const SeepageFace& face : c.seepage)
    for (std::int64_t i : face.nodes) grid.pressure[i] = std::min(grid.pressure[i], 0.0);
}

/// Seepage faces on the explicit pressure increment: a node whose pressure
/// would rise above zero is held at zero (the water that would have raised
/// it leaves through the face); one that stays at or below zero is left
/// free (no water enters). Explicit in time, this is the exact
/// complementarity p <= 0, outflow >= 0, p * outflow = 0 of each step.
template <int Dim>
inline void apply_seepage_increment(const Constraints& c, GridState<Dim>& grid) {
  for (const SeepageFace& face : c.seepage)
    for (std::int64_t i : face.nodes)
      if (grid.pressure[i] + grid.dp[i] > 0.0) grid.dp[i] = -grid.pressure[i];
}

}  // namespace hmpm
