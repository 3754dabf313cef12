// problem/softening.cpp — the regularisation of strain softening
// (MohrCoulomb::Softening::reference_cell_size): applied once, before a run
// sets up, so every stage, the strength reduction and every particle's own
// constants see the same regularised shape factor.
#include <cmath>
#include <variant>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

double softening_cell_size(const Problem& problem) {
  const int dim = problem.dimension;
  double product = 1.0;
  for (int a = 0; a < dim; ++a)
    product *= (problem.grid.max[static_cast<std::size_t>(a)] -
                problem.grid.min[static_cast<std::size_t>(a)]) /
               problem.grid.cells[static_cast<std::size_t>(a)];
  return std::pow(product, 1.0 / dim);
}

Problem regularise_softening(const Problem& problem) {
  Problem out = problem;
  const double h = softening_cell_size(problem);
  for (Material& m : out.materials)
    if (auto* mc = std::get_if<MohrCoulomb>(&m.plasticity))
      if (mc->softening && mc->softening->reference_cell_size > 0.0 &&
          !mc->softening->regularised) {
        mc->softening->shape_factor *= h / mc->softening->reference_cell_size;
        mc->softening->regularised = true;
      }
  return out;
}

}  // namespace hmpm
