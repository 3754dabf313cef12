// linear/up_system.hpp — the sparse linear system of the quasi-static u-p
// Newton iterations (internal).
//
// One system per time step: the sparsity pattern (which degrees of freedom
// share a particle stencil) is set once per step, when the particles have
// moved and the grid has been reset; the values are refilled in that pattern
// at every Newton iteration (no allocation), and the direct solver's symbolic
// analysis (fill-reducing ordering) is done once per pattern. Two solvers:
// Eigen's SparseLU (direct) and BiCGSTAB with an incomplete LU (ILUT)
// preconditioner (iterative). The matrix is the symmetric indefinite
// saddle-point Jacobian of schemes/quasi_static_scheme.hpp, scaled so that
// both blocks have the same size (see there).
#pragma once

#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

class UpSystem {
 public:
  /// Unknowns above which LinearSolver::automatic takes the iterative solver
  /// (docs/schemes.md gives the measurements behind it).
  static constexpr std::int64_t automatic_iterative_above = 200000;

  /// Starts a new pattern of n unknowns (the triplet list keeps its capacity).
  void begin_pattern(std::int64_t n);
  /// Marks entry (r, c) as possibly non-zero.
  void add_pattern(std::int64_t r, std::int64_t c) {
    pattern_.emplace_back(static_cast<int>(r), static_cast<int>(c), 0.0);
  }
  /// Compresses the pattern; the solver chosen for `which` (automatic: by
  /// size) analyses it on the first solve.
  void finish_pattern(LinearSolver which, double linear_tolerance);

  /// Zeroes the values (pattern kept).
  void zero_values();
  /// Adds v to entry (r, c), which must be in the pattern.
  void add(std::int64_t r, std::int64_t c, double v) {
    matrix_.coeffRef(static_cast<int>(r), static_cast<int>(c)) += v;
  }

  /// The values of the pattern's entries (column-major, compressed), and
  /// the position in them of entry (r, c), which must be in the pattern:
  /// threaded assembly adds into private copies of the values and sums them
  /// into values() in thread order (schemes/quasi_static_scheme.hpp).
  double* values() { return matrix_.valuePtr(); }
  std::int64_t nonzeros() const { return matrix_.nonZeros(); }
  std::int64_t offset(std::int64_t r, std::int64_t c) const {
    const int* inner = matrix_.innerIndexPtr();
    const int* outer = matrix_.outerIndexPtr();
    return std::lower_bound(inner + outer[c], inner + outer[c + 1], static_cast<int>(r)) - inner;
  }

  /// Solves A x = b with the current values. False when the factorisation
  /// or the iterative solve failed (message in error()).
  bool solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

  std::int64_t size() const { return n_; }
  bool iterative() const { return iterative_; }
  const char* error() const { return error_; }

  std::int64_t linear_iterations = 0;  ///< iterative solves: summed iterations
  std::int64_t solves = 0;
  double factor_seconds = 0.0, solve_seconds = 0.0;  ///< cumulated (benchmarks)

 private:
  struct Solvers;
  Solvers* solvers();

  std::int64_t n_ = 0;
  bool iterative_ = false;
  bool analysed_ = false;
  double tolerance_ = 1e-12;
  const char* error_ = "";
  std::vector<Eigen::Triplet<double>> pattern_;
  Eigen::SparseMatrix<double> matrix_;
  struct SolversDeleter {
    void operator()(Solvers* s) const;
  };
  std::unique_ptr<Solvers, SolversDeleter> solvers_;
};

}  // namespace hmpm
