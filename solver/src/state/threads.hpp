// state/threads.hpp — the threads of a run and their private nodal sums
// (internal).
//
// Thread 0 accumulates nodal sums straight into the grid; every other
// thread into a private buffer that is added to the grid after the phase,
// buffers in thread order, so sums are reproducible for a thread count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "parallel.hpp"
#include "shape.hpp"
#include "state/grid.hpp"

namespace hmpm {

template <int Dim, class Shape>
struct Threads {
  using StencilT = shape::Stencil<Dim, Shape>;

  std::unique_ptr<ThreadPool> pool;
  std::vector<NodalSums<Dim>> buffers;           ///< threads 1.. : private nodal sums
  std::vector<NodeRange> touched;                ///< per thread, from the step's first phase
  std::vector<std::vector<NodeRecord>> records;  ///< per thread: particle-to-grid scratch

  /// Block sizes of dynamically shared loops: at most a few hundred
  /// microseconds of work, and at least 16 blocks per thread, so the faster
  /// thread can take up the slack (small runs get small blocks).
  static constexpr std::size_t particle_block = 4096, node_block = 8192;
  std::size_t block_of(std::size_t n, std::size_t largest) const {
    return std::clamp<std::size_t>(n / (16 * static_cast<std::size_t>(pool->size())), 64, largest);
  }

  void start(int threads, const GridState<Dim>& grid, bool fluid) {
    pool = std::make_unique<ThreadPool>(threads);
    buffers.resize(static_cast<std::size_t>(threads - 1));
    touched.assign(static_cast<std::size_t>(threads), NodeRange{0, grid.count - 1});
    for (NodalSums<Dim>& b : buffers) b.resize(static_cast<std::size_t>(grid.count), fluid);
    records.resize(static_cast<std::size_t>(threads));
    if constexpr (StencilT::factorised)  // map_particles_to_grid_by_rows's scratch
      for (auto& r : records) r.assign(static_cast<std::size_t>(grid.count), NodeRecord{});
  }

  Scatter<Dim> scatter_of(GridState<Dim>& grid, int t) {
    NodeRange* const range = &touched[static_cast<std::size_t>(t)];
    NodeRecord* const scratch = records[static_cast<std::size_t>(t)].data();
    if (t == 0) return {grid.pointers(), range, scratch};
    return {buffers[static_cast<std::size_t>(t - 1)].pointers(), range, scratch};
  }

  /// Runs phase(scatter, begin, end) over `particles` in chunks, then adds
  /// the private buffers of the nodal sums in `fields` (a mask of
  /// nodal::bit) to the grid, in thread order, over the nodes each thread
  /// touched only, clearing them as it goes. Particles created in cell order
  /// give each thread a band of the grid, so the reduction costs about one
  /// band per extra thread, not a whole grid. Phases that scatter nothing
  /// (fields == 0) give each particle's result regardless of the thread
  /// that computes it: they take blocks dynamically, so a slower virtual CPU
  /// does less of the work.
  template <class Phase>
  void for_particles(GridState<Dim>& grid, std::size_t particles, unsigned fields, Phase&& phase) {
    auto chunk = [&](int t, std::size_t b, std::size_t e) { phase(scatter_of(grid, t), b, e); };
    if (!fields) {
      pool->for_blocks(particles, block_of(particles, particle_block), chunk);
      return;
    }
    pool->for_ranges(particles, chunk);
    if (buffers.empty()) return;
    // Every node of the buffers' bands, split over the threads.
    std::int64_t lo = grid.count, hi = -1;
    for (std::size_t t = 1; t < touched.size(); ++t) {
      lo = std::min(lo, touched[t].lo);
      hi = std::max(hi, touched[t].hi);
    }
    if (hi < lo) return;
    auto reduce = [&](int, std::size_t b, std::size_t e) {
      for (std::size_t t = 1; t < touched.size(); ++t) {
        const auto first = std::max(b, static_cast<std::size_t>(touched[t].lo));
        const auto last = std::min(e, static_cast<std::size_t>(touched[t].hi + 1));
        if (first < last) grid.add_and_clear(buffers[t - 1], fields, first, last);
      }
    };
    const auto offset = static_cast<std::size_t>(lo);
    auto band = [&](int t, std::size_t b, std::size_t e) { reduce(t, offset + b, offset + e); };
    const auto nodes = static_cast<std::size_t>(hi - lo + 1);
    pool->for_blocks(nodes, block_of(nodes, node_block), band);
  }

  /// Runs f(begin, end) over blocks of the nodes [0, count), taken by the
  /// threads dynamically (node loops whose iterations are independent: no
  /// node loop sums across nodes, so the results do not depend on the
  /// split).
  template <class F>
  void for_nodes(std::int64_t count, F&& f) {
    if (!pool) {  // set-up, before run() starts the threads
      f(std::int64_t{0}, count);
      return;
    }
    auto chunk = [&](int, std::size_t b, std::size_t e) {
      f(static_cast<std::int64_t>(b), static_cast<std::int64_t>(e));
    };
    const auto nodes = static_cast<std::size_t>(count);
    pool->for_blocks(nodes, block_of(nodes, node_block), chunk);
  }
};

}  // namespace hmpm
