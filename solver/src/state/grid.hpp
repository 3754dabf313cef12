// state/grid.hpp — the grid state as a structure of arrays (internal).
//
// The grid is scratch space: cleared at the start of every step, filled by
// the particles, advanced by the grid phase, read back by the particles.
// The fields the particles scatter into (sums over particles, computed by
// several threads into private buffers and added in thread order) form ONE
// list, NodalSums::fields(): scattering, the threads' buffers, their
// reduction, sizing and clearing all loop over it. To add a nodal sum: add
// its array to NodalSums, to fields() and to nodal::Sum (same position),
// and say whether only saturated runs need it (fluid_only).
// Fixed-size Eigen types, sized once at set-up: nothing allocates per step.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

#include "state/particles.hpp"

namespace hmpm {

namespace nodal {
/// The scattered nodal fields, by position in NodalSums::fields().
enum Sum : unsigned { mass, momentum, force, remap, storage, pressure, flux, count };
/// Bit of a nodal sum in a phase's mask (the sums the phase scatters into).
constexpr unsigned bit(Sum f) {
  return 1u << f;
}
}  // namespace nodal

/// Sums over particles: per node, what particle phases scatter.
template <int Dim>
struct NodalSums {
  using Vec = VecD<Dim>;
  std::vector<double> mass;   ///< m_i
  std::vector<Vec> momentum;  ///< m_i v_i at the start of the step
  std::vector<Vec> force;     ///< internal + external force
  std::vector<Vec> remap;     ///< momentum re-mapped from updated particle velocities (MUSL)
  // Fluid phase (empty when dry).
  std::vector<double> storage;   ///< s_i = sum N Q V
  std::vector<double> pressure;  ///< p_i at the start of the step (after boundary values)
  std::vector<double> flux;      ///< right-hand side of s_i dp_i/dt

  /// The list, in the order of nodal::Sum.
  auto fields() { return std::tie(mass, momentum, force, remap, storage, pressure, flux); }
  auto fields() const { return std::tie(mass, momentum, force, remap, storage, pressure, flux); }
  /// Per field: only saturated runs need it (empty otherwise).
  static constexpr std::array<bool, nodal::count> fluid_only = {false, false, false, false,
                                                                true,  true,  true};

  /// Pointers to every field's first node (the target of a thread's scatter).
  using Pointers = std::tuple<double*, Vec*, Vec*, Vec*, double*, double*, double*>;
  Pointers pointers() {
    return std::apply([](auto&... f) { return Pointers(f.data()...); }, fields());
  }

  /// f(index, array) for every field, in list order.
  template <class F>
  void for_each(F&& f) {
    for_each_impl(std::forward<F>(f), std::make_index_sequence<nodal::count>{});
  }

  /// Sizes every field to `nodes` zeros (fluid-only fields only when `fluid`).
  void resize(std::size_t nodes, bool fluid) {
    for_each([&](auto index, auto& a) {
      if (!fluid_only[index] || fluid) a.assign(nodes, zero_of(a));
    });
  }

  /// Zeroes nodes [b, e) of every (non-empty) field.
  void clear(std::int64_t b, std::int64_t e) {
    for_each([&](auto, auto& a) {
      if (!a.empty()) std::fill(a.begin() + b, a.begin() + e, zero_of(a));
    });
  }

  /// Adds nodes [b, e) of the fields in `mask` of `from` to this, and zeroes
  /// them in `from` (a thread's buffer is zero outside a phase).
  void add_and_clear(NodalSums& from, unsigned mask, std::size_t b, std::size_t e) {
    auto sources = from.fields();
    for_each([&](auto index, auto& to) {
      if (!(mask & (1u << decltype(index)::value))) return;
      auto& src = std::get<decltype(index)::value>(sources);
      for (std::size_t i = b; i < e; ++i) {
        to[i] += src[i];
        src[i] = zero_of(src);
      }
    });
  }

  std::int64_t bytes_per_node() const {
    std::size_t per = 0;
    std::apply([&](const auto&... f) { ((per += f.empty() ? 0 : sizeof(f[0])), ...); }, fields());
    return static_cast<std::int64_t>(per);
  }

 private:
  template <class A>
  static typename A::value_type zero_of(const A&) {
    if constexpr (std::is_same_v<typename A::value_type, double>)
      return 0.0;
    else
      return A::value_type::Zero();
  }
  template <class F, std::size_t... I>
  void for_each_impl(F&& f, std::index_sequence<I...>) {
    auto all = fields();
    (f(std::integral_constant<std::size_t, I>{}, std::get<I>(all)), ...);
  }
};

/// Nodes [lo, hi] that a thread's particle chunk touches this step.
struct NodeRange {
  std::int64_t lo, hi;
};

/// One node's mass, momentum and force as two four-lane vectors, the
/// particle-to-grid phase's scratch: [m, m v (Dim lanes), 0...] and
/// [f (Dim lanes), 0...]. Every particle adds to a node with the same two
/// aligned 32-byte read-modify-writes (one pair of addresses per node), so
/// the next particle's loads are forwarded from the stores before them; the
/// phase then copies the records to the nodal sums.
struct alignas(64) NodeRecord {
  double a[4];
  double b[4];
};

/// Where one thread's particle phase scatters: the grid's own sums (thread
/// 0) or the thread's private buffer.
template <int Dim>
struct Scatter {
  typename NodalSums<Dim>::Pointers to;
  NodeRange* touched;   ///< set by the step's first phase (particles do not move before the last)
  NodeRecord* records;  ///< the thread's scratch records (zero outside the phase)
};

/// The array of nodal sum F a phase scatters into.
template <nodal::Sum F, int Dim>
inline auto* at(const Scatter<Dim>& s) {
  return std::get<F>(s.to);
}

template <int Dim>
struct GridState : NodalSums<Dim> {
  using Vec = VecD<Dim>;
  std::int64_t count = 0;
  int cells[Dim];
  std::int64_t stride[3] = {1, 1, 1};
  double origin[Dim];
  double h[Dim];
  double inv_h[Dim];

  // Computed per node by the grid phases (not scattered).
  std::vector<Vec> velocity;  ///< Lagrangian velocity after the momentum update
  std::vector<Vec> accel;     ///< (v^L - v^n) / dt, constrained components included
  std::vector<double> dp;     ///< p_i^{n+1} - p_i^n (fluid phase; empty when dry)

  Vec node_position(std::int64_t i) const {
    Vec x;
    std::int64_t r = i;
    for (int a = Dim - 1; a >= 0; --a) {
      const std::int64_t q = r / stride[a];
      r -= q * stride[a];
      x[a] = origin[a] + static_cast<double>(q) * h[a];
    }
    return x;
  }

  void resize(bool fluid) {
    const auto n = static_cast<std::size_t>(count);
    NodalSums<Dim>::resize(n, fluid);
    velocity.assign(n, Vec::Zero());
    accel.assign(n, Vec::Zero());
    if (fluid) dp.assign(n, 0.0);
  }

  std::int64_t bytes() const {
    std::size_t per = static_cast<std::size_t>(this->bytes_per_node()) + sizeof(Vec) * 2;
    if (!dp.empty()) per += sizeof(double);
    return static_cast<std::int64_t>(static_cast<std::size_t>(count) * per);
  }
};

}  // namespace hmpm
