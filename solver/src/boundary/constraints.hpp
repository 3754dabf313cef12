// boundary/constraints.hpp — boundary conditions compiled to node lists (internal).
//
// Each Boundary of the Problem is compiled once, at set-up, into the
// constraints it imposes on the grid: prescribed velocity components
// (VelocityConstraint, optionally with Coulomb friction), rigid ties
// (RigidTie: nodes sharing one velocity component) and prescribed pore
// pressure (PressureConstraint). Which one wins where several meet at a node
// is decided in one place, boundary/apply.hpp. Surface loads are in
// boundary/tractions.hpp. Set-up code: allocates, never runs per step.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "state/grid.hpp"

namespace hmpm {

/// Velocity components prescribed at a set of nodes, optionally with friction.
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
  std::size_t boundary = 0;  ///< index in Problem::boundaries (for its reaction)

  bool has_friction() const { return !stuck.empty(); }
};

/// Nodes sharing one velocity component per marked axis (rigid plate).
struct RigidTie {
  std::vector<std::int64_t> nodes;
  std::array<bool, 3> axes{false, false, false};
  std::array<double, 3> remapped{0.0, 0.0, 0.0};  ///< scratch: tied re-mapped velocity
  std::size_t boundary = 0;                       ///< index in Problem::boundaries
};

/// Pore pressure prescribed at a set of nodes: fn(t), or, when `field` is
/// set, field(x[k], t) at nodes[k].
struct PressureConstraint {
  std::vector<std::int64_t> nodes;
  const FieldOfTime* fn = nullptr;
  const FieldOfSpaceTime* field = nullptr;
  std::vector<Vec3> x;  ///< node positions (only with `field`)

  /// Calls set(node, value) for every node at time t.
  template <class Set>
  void for_values(double t, Set&& set) const {
    if (field) {
      for (std::size_t k = 0; k < nodes.size(); ++k) set(nodes[k], (*field)(x[k], t));
      return;
    }
    const double value = (*fn)(t);
    for (std::int64_t i : nodes) set(i, value);
  }
};

/// Seepage face nodes (Boundary::seepage), less those whose pore pressure
/// a boundary prescribes (a prescribed value wins).
struct SeepageFace {
  std::vector<std::int64_t> nodes;
};

/// Every constraint of a run.
struct Constraints {
  std::vector<VelocityConstraint> velocity;
  std::vector<RigidTie> rigid_ties;
  std::vector<PressureConstraint> pressure;
  std::vector<SeepageFace> seepage;
  /// Per node (saturated runs): bit a set when a boundary prescribes or ties
  /// component a. Empty in dry runs.
  std::vector<std::uint8_t> prescribed_axes;
};

namespace detail {

template <int Dim>
Vec3 node_position3(const GridState<Dim>& grid, std::int64_t i) {
  const VecD<Dim> xn = grid.node_position(i);
  Vec3 x{0.0, 0.0, 0.0};
  for (int a = 0; a < Dim; ++a) x[a] = xn[a];
  return x;
}

}  // namespace detail

/// Compiles the boundaries of `problem` on `grid` (whose upper corner is
/// `grid_max`). Pressure constraints only when `fluid` (a saturated run).
/// `problem` must outlive the result (the constraints point to its fields).
template <int Dim>
Constraints compile_constraints(const Problem& problem, const GridState<Dim>& grid,
                                const VecD<Dim>& grid_max, bool fluid) {
  Constraints c;
  for (std::size_t bi = 0; bi < problem.boundaries.size(); ++bi) {
    const Boundary& b = problem.boundaries[bi];
    std::vector<std::int64_t> nodes;
    for (std::int64_t i = 0; i < grid.count; ++i)
      if (node_selected(problem, b.nodes, detail::node_position3(grid, i))) nodes.push_back(i);
    if (b.has_velocity) {
      VelocityConstraint vc;
      vc.nodes = nodes;
      vc.boundary = bi;
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
        const double tol = 1e-9 * grid.h[n];
        const bool by_box = !b.nodes.all && !b.nodes.polygon;  // a polygon wall: either side
        if (by_box && b.nodes.box.max[n] <= grid.origin[n] + tol) vc.inward = 1;
        if (by_box && b.nodes.box.min[n] >= grid_max[n] - tol) vc.inward = -1;
      }
      c.velocity.push_back(std::move(vc));
    }
    if (b.rigid[0] || b.rigid[1] || b.rigid[2])
      c.rigid_ties.push_back({nodes, b.rigid, {0.0, 0.0, 0.0}, bi});
    if (b.seepage && fluid) c.seepage.push_back({nodes});
    if (b.pore_pressure && fluid) {
      PressureConstraint pc{std::move(nodes), &*b.pore_pressure, nullptr, {}};
      if (b.pore_pressure_field) {
        pc.field = &b.pore_pressure_field;
        for (std::int64_t i : pc.nodes) pc.x.push_back(detail::node_position3(grid, i));
      }
      c.pressure.push_back(std::move(pc));
    }
  }
  if (!fluid) return c;
  if (!c.seepage.empty()) {
    std::vector<std::uint8_t> prescribed(static_cast<std::size_t>(grid.count), 0);
    for (const PressureConstraint& bc : c.pressure)
      for (std::int64_t i : bc.nodes) prescribed[static_cast<std::size_t>(i)] = 1;
    for (SeepageFace& face : c.seepage)
      std::erase_if(face.nodes,
                    [&](std::int64_t i) { return prescribed[static_cast<std::size_t>(i)]; });
  }
  c.prescribed_axes.assign(static_cast<std::size_t>(grid.count), 0);
  for (const VelocityConstraint& bc : c.velocity)
    for (int a = 0; a < Dim; ++a)
      if (bc.fixed[a])
        for (std::int64_t i : bc.nodes)
          c.prescribed_axes[static_cast<std::size_t>(i)] |= std::uint8_t(1u << a);
  for (const RigidTie& tie : c.rigid_ties)
    for (int a = 0; a < Dim; ++a)
      if (tie.axes[a])
        for (std::int64_t i : tie.nodes)
          c.prescribed_axes[static_cast<std::size_t>(i)] |= std::uint8_t(1u << a);
  return c;
}

}  // namespace hmpm
