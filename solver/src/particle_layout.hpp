// particle_layout.hpp — where a body's particles go (internal).
//
// A body fills the grid cells lying entirely inside its box with n particles
// per axis per cell at sub-cell centres. The coordinates per axis are sorted,
// so iterating z, then y, then x gives the contract's numbering (x fastest).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

struct BodyLayout {
  std::array<std::vector<double>, 3> coords;  ///< particle coordinates per axis
  std::int64_t count = 0;
};

BodyLayout body_layout(const Problem& problem, const Body& body);

/// Smallest cell size over the active axes, m.
double min_cell_size(const Problem& problem);

}  // namespace hmpm
