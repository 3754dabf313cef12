// particle_layout.hpp — where a body's particles go (internal; problem/layout.cpp).
//
// A box body fills the grid cells lying entirely inside its box with n
// particles per axis per cell at sub-cell centres; a polygon or prism body
// the sub-cell centres inside it (or on its boundary); a points body has its
// given particles. Positions run z, then y, then x (x fastest: the
// contract's numbering), a points body in its given order. The bodies are
// laid out together: a position inside an earlier body's shape belongs to
// that body (first listed wins), so no place holds two particles.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

struct BodyLayout {
  std::vector<Vec3> positions;  ///< in the contract's numbering
  std::vector<double> volumes;  ///< initial volume per particle
  std::int64_t count = 0;       ///< how many (positions.size() when they are kept)
  /// The space the particles fill, per axis (sub-cells; each point's own
  /// cube for a points body); meaningless when count is 0.
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  /// Positions the body lost to earlier bodies: (earlier body, how many).
  std::vector<std::pair<std::size_t, std::int64_t>> lost;
};

/// What body_layouts keeps: every position and volume, or only the counts,
/// the filled extents and the losses (no per-particle storage: the checks
/// and estimates that only count call it on million-particle jobs).
enum class LayoutDetail { positions, counts };

/// Every body's particles, in order, with overlaps given to the first body.
std::vector<BodyLayout> body_layouts(const Problem& problem,
                                     LayoutDetail detail = LayoutDetail::positions);

/// Smallest cell size over the active axes, m.
double min_cell_size(const Problem& problem);

/// Cell size along axis `a`, m.
double cell_size(const Problem& problem, int a);

/// Volume of one cell (area in 2D, length in 1D).
double cell_volume(const Problem& problem);

}  // namespace hmpm
