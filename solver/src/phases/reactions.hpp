// phases/reactions.hpp — the force each boundary exerts on the soil
// (OutputRequest::reactions_interval, RunResult::reactions) (internal).
//
// A boundary's reaction is the sum, over the node components it constrains,
// of the nodal force that enforces its constraint: what must be added to the
// physical nodal forces (internal stress and pore pressure, tractions,
// gravity) for the node to move as the constraint makes it move. In the
// explicit and semi-implicit steps, at a node component i, a:
//   prescribed velocity (also a friction wall's normal,
//   and its tangential components where it sticks):      R = m a_c - f
//   friction (slipping, tangential), rigid ties and
//   absorbing boundaries (the dashpot and the force at rest): R = m a_c - f_damped
// with a_c the constrained nodal acceleration the particles receive, f =
// f_int + f_p + f_traction + m g (+ the pressure increment's force in the
// semi-implicit step) and f_damped f with the step's local damping. A
// prescribed component (and a sticking friction node, whose tangential
// velocity is set to the wall's) replaces the free update, damping
// included, so damping never enters its reaction; slipping friction and ties
// only modify the free (damped) update, so their reaction is the
// modification alone. The sum of
// the reactions of a rigid tie is zero (a massless plate) up to damping.
// Because the particles' momentum changes by sum m a_c dt, the reactions,
// the weight and the tractions balance the rate of momentum: at rest the
// reactions balance the loads to round-off. The quasi-static step computes
// the residual at the constrained degrees of freedom of its converged state
// instead (schemes/quasi_static_scheme.hpp).
//
// Which boundary a node component is charged to (owner): the mechanism
// applied last in the order of precedence of boundary/apply.hpp, i.e. a
// prescribed velocity over friction over a rigid tie over a dashpot, and
// among two of the
// same kind the later boundary in the Problem. Set-up builds the list of
// charged components once; each step that the time loop samples
// (reactions_due_) sums over it: no allocation, proportional to the
// boundary nodes, not to the particles.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "simulation.hpp"

namespace hmpm {

template <int Dim>
void setup_reactions(ReactionTally& tally, const Constraints& constraints, std::int64_t node_count,
                     std::size_t boundaries) {
  const auto nodes = static_cast<std::size_t>(node_count);
  std::vector<int>& owner = tally.owner;
  owner.assign(nodes * Dim, -1);
  std::vector<std::uint8_t> prescribed(nodes * Dim, 0);
  std::vector<const std::uint8_t*> stuck(nodes * Dim, nullptr);
  auto charge = [&](std::int64_t i, int a, std::size_t b, bool fixed, const std::uint8_t* flag) {
    const std::size_t d = static_cast<std::size_t>(i) * Dim + static_cast<std::size_t>(a);
    owner[d] = static_cast<int>(b);
    prescribed[d] = fixed ? 1 : 0;
    stuck[d] = flag;
  };
  for (const AbsorbingConstraint& ab : constraints.absorbing)
    for (int a = 0; a < Dim; ++a)
      for (std::int64_t i : ab.nodes) charge(i, a, ab.boundary, false, nullptr);
  for (const RigidTie& tie : constraints.rigid_ties)
    for (int a = 0; a < Dim; ++a)
      if (tie.axes[a])
        for (std::int64_t i : tie.nodes) charge(i, a, tie.boundary, false, nullptr);
  for (const VelocityConstraint& bc : constraints.velocity)
    if (bc.has_friction())
      for (int a = 0; a < Dim; ++a)
        if (a != bc.normal)
          for (std::size_t k = 0; k < bc.nodes.size(); ++k)
            charge(bc.nodes[k], a, bc.boundary, false, &bc.stuck[k]);
  for (const VelocityConstraint& bc : constraints.velocity)
    for (int a = 0; a < Dim; ++a)
      if (bc.fixed[a])
        for (std::int64_t i : bc.nodes) charge(i, a, bc.boundary, true, nullptr);
  tally.charges.clear();
  for (std::size_t d = 0; d < nodes * Dim; ++d)
    if (owner[d] >= 0)
      tally.charges.push_back({static_cast<std::int64_t>(d / Dim), static_cast<int>(d % Dim),
                               owner[d], prescribed[d] != 0, stuck[d]});
  tally.extra.assign(tally.charges.size(), 0.0);
  tally.force.assign(boundaries, Vec3{0.0, 0.0, 0.0});
}

template <int Dim, class Shape>
void record_reaction_extra_force(StepContext<Dim, Shape>& ctx,
                                 const std::vector<VecD<Dim>>& force) {
  for (std::size_t c = 0; c < ctx.reactions.charges.size(); ++c)
    ctx.reactions.extra[c] = force[static_cast<std::size_t>(ctx.reactions.charges[c].node)]
                                  [ctx.reactions.charges[c].axis];
}

template <int Dim, class Shape>
void tally_reactions(StepContext<Dim, Shape>& ctx, bool with_extra) {
  for (Vec3& r : ctx.reactions.force) r = {0.0, 0.0, 0.0};
  const double alpha = ctx.damping;
  for (std::size_t c = 0; c < ctx.reactions.charges.size(); ++c) {
    const ReactionCharge& ch = ctx.reactions.charges[c];
    const std::int64_t i = ch.node;
    const int a = ch.axis;
    const double m = ctx.grid.mass[i];
    const double f = ctx.grid.force[i][a] + m * ctx.model.gravity[a];
    double r = m * ctx.grid.accel[i][a] - f;
    if (!ch.prescribed && !(ch.stuck && *ch.stuck)) {
      // The free update these components started from was damped (a
      // sticking friction node replaces it, as a prescribed component
      // does), and a node without mass was left at rest unconstrained.
      if (m <= ctx.model.mass_tolerance) continue;
      const double v0 = ctx.grid.momentum[i][a] / m;
      r += alpha * std::abs(f) * (v0 > 0 ? 1.0 : (v0 < 0 ? -1.0 : 0.0));
    }
    if (with_extra) r -= ctx.reactions.extra[c];
    ctx.reactions.force[static_cast<std::size_t>(ch.boundary)][static_cast<std::size_t>(a)] += r;
  }
}

}  // namespace hmpm
