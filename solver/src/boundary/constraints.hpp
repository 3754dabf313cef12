// boundary/constraints.hpp — boundary conditions compiled to node lists (internal).
//
// Each Boundary of the Problem is compiled once, at set-up, into the
// constraints it imposes on the grid: prescribed velocity components
// (VelocityConstraint, optionally with Coulomb friction), rigid ties
// (RigidTie: nodes sharing one velocity component), dashpots
// (AbsorbingConstraint) and prescribed pore pressure (PressureConstraint). Which one wins where
// several meet at a node is decided in one place, boundary/apply.hpp. Surface loads are in
// boundary/tractions.hpp. Set-up code: allocates, never runs per step.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
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
  std::vector<Vec3> x;       ///< node positions (only with `field`)
  std::size_t boundary = 0;  ///< index in Problem::boundaries (for messages)
  /// Some node had soil at a step of the stage (check_drained_contact).
  bool reached = false;

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

/// Dashpots at a set of nodes (Boundary::absorbing): along each axis a the
/// force C_a (v_in,a(t) - v_a) + hold, implicit in v (see apply.hpp).
struct AbsorbingConstraint {
  std::vector<std::int64_t> nodes;
  /// Per node, 3 per node (axis a at 3 k + a): C = rho c_a times the node's
  /// share of the face, N s/m.
  std::vector<double> coefficient;
  std::array<const FieldOfTime*, 3> input{nullptr, nullptr, nullptr};  ///< outcrop velocity
  /// Per node, 3 per node: the force at rest, N, taken in the first step of
  /// the stage (`held` from then on; kept in checkpoints).
  std::vector<double> hold;
  bool held = false;
  std::size_t boundary = 0;  ///< index in Problem::boundaries (for its reaction)
};

/// Seepage face nodes (Boundary::seepage), less those whose pore pressure
/// a boundary prescribes (a prescribed value wins).
struct SeepageFace {
  std::vector<std::int64_t> nodes;
  std::size_t boundary = 0;  ///< index in Problem::boundaries (for messages)
  bool reached = false;      ///< as PressureConstraint::reached
};

/// Every constraint of a run.
struct Constraints {
  std::vector<VelocityConstraint> velocity;
  std::vector<RigidTie> rigid_ties;
  std::vector<PressureConstraint> pressure;
  std::vector<SeepageFace> seepage;
  std::vector<AbsorbingConstraint> absorbing;
  /// Per node: bit a set when a boundary prescribes or ties component a
  /// (the Darcy term's accelerations, phases/grid.hpp; walls that keep
  /// particles in the grid, phases/grid_to_particle.hpp).
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

/// The node's share of a face with normal axis `normal` that the soil
/// covers: its tributary region on the face (the cell size along each face
/// axis, [x - h/2, x + h/2] clipped to the grid) times the fraction of it
/// that lies under particles next to the face (those in the cells around
/// the node, each the box of its share of a cell: h_a / n along axis a, n
/// per axis from its volume), sampled on 8 points per face axis.
/// A base wider than the soil above it thereby gets dashpots where the soil
/// is, not where the selection is. 1 in 1D.
template <int Dim>
double covered_face_share(const GridState<Dim>& grid, const ParticleState<Dim>& particles,
                          const std::vector<std::pair<std::int64_t, std::size_t>>& in_cell,
                          std::int64_t i, int normal) {
  if constexpr (Dim == 1) return 1.0;
  constexpr int samples = 8;
  std::array<std::int64_t, Dim> q{};
  double area = 1.0, cell_volume = 1.0;
  std::array<double, Dim> lo{}, step{};
  for (int a = 0; a < Dim; ++a) {
    q[a] = (i / grid.stride[a]) % (grid.cells[a] + 1);
    cell_volume *= grid.h[a];
    if (a == normal) continue;
    const double x = grid.origin[a] + static_cast<double>(q[a]) * grid.h[a];
    const double from = q[a] > 0 ? x - 0.5 * grid.h[a] : x;
    const double to = q[a] < grid.cells[a] ? x + 0.5 * grid.h[a] : x;
    area *= to - from;
    lo[a] = from;
    step[a] = (to - from) / samples;
  }
  // The particles in the cells that share node i, with their half extents:
  // particles fill cells on a regular n x n (x n) pattern, n per axis from
  // the particle's volume, so each spans h_a / n along axis a.
  struct Near {
    std::size_t p;
    double per_axis;
  };
  std::vector<Near> near;
  for (int corner = 0; corner < (1 << Dim); ++corner) {
    std::int64_t cell = 0, stride = 1;
    bool inside = true;
    for (int a = 0; a < Dim; ++a) {
      const std::int64_t c = q[a] - ((corner >> a) & 1);
      inside = inside && c >= 0 && c < grid.cells[a];
      cell += c * stride;
      stride *= grid.cells[a];
    }
    if (!inside) continue;
    const auto first = std::lower_bound(in_cell.begin(), in_cell.end(),
                                        std::pair<std::int64_t, std::size_t>{cell, 0});
    for (auto it = first; it != in_cell.end() && it->first == cell; ++it)
      near.push_back({it->second, std::pow(cell_volume / particles.volume[it->second], 1.0 / Dim)});
  }
  int covered = 0, total = 0;
  const int points = Dim == 2 ? samples : samples * samples;
  for (int k = 0; k < points; ++k) {
    std::array<double, Dim> s{};
    int rest = k;
    for (int a = 0; a < Dim; ++a) {
      if (a == normal) continue;
      s[a] = lo[a] + (static_cast<double>(rest % samples) + 0.5) * step[a];
      rest /= samples;
    }
    ++total;
    const bool under = std::any_of(near.begin(), near.end(), [&](const Near& n) {
      for (int a = 0; a < Dim; ++a)
        if (a != normal && std::abs(s[a] - particles.x[n.p][a]) > 0.5 * grid.h[a] / n.per_axis)
          return false;
      return true;
    });
    if (under) ++covered;
  }
  return area * static_cast<double>(covered) / static_cast<double>(total);
}

/// The dashpots of boundary `bi`: impedances rho c of the material beyond
/// (Absorbing::material) times each node's share of the face the soil
/// covers (`in_cell`: (grid cell, particle) pairs, sorted).
template <int Dim>
AbsorbingConstraint compile_absorbing(
    const Problem& problem, std::size_t bi, const GridState<Dim>& grid,
    const ParticleState<Dim>& particles,
    const std::vector<std::pair<std::int64_t, std::size_t>>& in_cell,
    const std::vector<std::int64_t>& nodes) {
  const Boundary& b = problem.boundaries[bi];
  const Absorbing& ab = *b.absorbing;
  const MaterialConstants mc =
      material_constants(problem.materials[ab.material], problem.gravity_constant);
  const double rho = mc.mixture_density;
  const double normal_impedance = std::sqrt(rho * mc.undrained_p_modulus);
  const double shear_impedance = std::sqrt(rho * mc.shear_modulus);
  AbsorbingConstraint c;
  c.nodes = nodes;
  c.boundary = bi;
  for (int a = 0; a < Dim; ++a) c.input[a] = b.velocity[a] ? &*b.velocity[a] : nullptr;
  c.coefficient.assign(3 * nodes.size(), 0.0);
  c.hold.assign(3 * nodes.size(), 0.0);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double area = covered_face_share(grid, particles, in_cell, nodes[k], ab.normal);
    for (int a = 0; a < Dim; ++a)
      c.coefficient[3 * k + static_cast<std::size_t>(a)] =
          area * (a == ab.normal ? normal_impedance : shear_impedance);
  }
  return c;
}

}  // namespace detail

/// Compiles the boundaries of `problem` on `grid` (whose upper corner is
/// `grid_max`) for the particles in the run. Pressure constraints only when `fluid` (a saturated
/// run). `problem` must outlive the result (the constraints point to its fields).
template <int Dim>
Constraints compile_constraints(const Problem& problem, const GridState<Dim>& grid,
                                const VecD<Dim>& grid_max, bool fluid,
                                const ParticleState<Dim>& particles) {
  Constraints c;
  // (cell, particle) of every particle, sorted: the particles of a cell,
  // for the absorbing boundaries' face shares (memory per particle, not
  // per cell).
  std::vector<std::pair<std::int64_t, std::size_t>> in_cell;
  if (std::any_of(problem.boundaries.begin(), problem.boundaries.end(),
                  [](const Boundary& b) { return b.absorbing.has_value(); })) {
    in_cell.reserve(particles.size());
    for (std::size_t p = 0; p < particles.size(); ++p) {
      std::int64_t cell = 0, stride = 1;
      for (int a = 0; a < Dim; ++a) {
        const auto k = std::clamp<std::int64_t>(
            static_cast<std::int64_t>(
                std::floor((particles.x[p][a] - grid.origin[a]) * grid.inv_h[a])),
            0, grid.cells[a] - 1);
        cell += k * stride;
        stride *= grid.cells[a];
      }
      in_cell.emplace_back(cell, p);
    }
    std::sort(in_cell.begin(), in_cell.end());
  }
  for (std::size_t bi = 0; bi < problem.boundaries.size(); ++bi) {
    const Boundary& b = problem.boundaries[bi];
    std::vector<std::int64_t> nodes;
    for (std::int64_t i = 0; i < grid.count; ++i)
      if (node_selected(problem, b.nodes, detail::node_position3(grid, i))) nodes.push_back(i);
    if (b.absorbing) {
      c.absorbing.push_back(
          detail::compile_absorbing(problem, bi, grid, particles, in_cell, nodes));
    } else if (b.has_velocity) {
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
    if (b.seepage && fluid) c.seepage.push_back({nodes, bi, false});
    if (b.pore_pressure && fluid) {
      PressureConstraint pc{std::move(nodes), &*b.pore_pressure, nullptr, {}, bi, false};
      if (b.pore_pressure_field) {
        pc.field = &b.pore_pressure_field;
        for (std::int64_t i : pc.nodes) pc.x.push_back(detail::node_position3(grid, i));
      }
      c.pressure.push_back(std::move(pc));
    }
  }
  if (fluid && !c.seepage.empty()) {
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
