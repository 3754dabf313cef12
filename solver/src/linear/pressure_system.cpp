// linear/pressure_system.cpp — factorisation and solves of PressureSystem.
#include "linear/pressure_system.hpp"

#include <algorithm>
#include <cstring>

namespace hmpm {

void PressureSystem::begin(int n, std::int64_t max_entries) {
  if (a_.rows() != n || a_.cols() != n) a_.resize(n, n);
  a_.resizeNonZeros(static_cast<Eigen::Index>(max_entries));  // keeps the capacity
  entries_ = 0;
  column_ = 0;
  a_.outerIndexPtr()[0] = 0;
}

PressureSystem::Outcome PressureSystem::solve(const Eigen::Ref<const Eigen::VectorXd>& b,
                                              Eigen::Ref<Eigen::VectorXd> x, LinearSolver choice,
                                              double tolerance, int dim) {
  a_.resizeNonZeros(static_cast<Eigen::Index>(entries_));
  const int n = size();
  Outcome out;
  const std::int64_t limit = dim >= 3 ? direct_limit_3d : direct_limit_2d;
  out.direct = choice == LinearSolver::direct || (choice == LinearSolver::automatic && n <= limit);
  if (out.direct) {
    const auto* outer = a_.outerIndexPtr();
    const auto* inner = a_.innerIndexPtr();
    const bool same = analysed_ && static_cast<int>(analysed_outer_.size()) == n + 1 &&
                      static_cast<std::int64_t>(analysed_inner_.size()) == entries_ &&
                      std::equal(outer, outer + n + 1, analysed_outer_.begin()) &&
                      std::equal(inner, inner + entries_, analysed_inner_.begin());
    if (!same) {
      direct_.analyzePattern(a_);
      analysed_outer_.assign(outer, outer + n + 1);
      analysed_inner_.assign(inner, inner + entries_);
      analysed_ = true;
    }
    direct_.factorize(a_);
    if (direct_.info() != Eigen::Success) {
      out.ok = false;
      return out;
    }
    x = direct_.solve(b);
    out.ok = x.allFinite();
    return out;
  }
  iterative_.setTolerance(tolerance);
  iterative_.setMaxIterations(std::max(100, 2 * n));
  iterative_.compute(a_);
  if (iterative_.info() != Eigen::Success) {
    out.ok = false;
    return out;
  }
  x = iterative_.solveWithGuess(b, x);
  // Eigen counts the iterations after the first (0: converged in one, as
  // with an incomplete Cholesky factor that drops no fill).
  out.iterations = static_cast<int>(iterative_.iterations());
  out.residual = iterative_.error();
  out.ok = iterative_.info() == Eigen::Success && x.allFinite();
  return out;
}

}  // namespace hmpm
