// linear/pressure_system.hpp — the sparse symmetric positive definite system
// of the semi-implicit pressure increment and its solvers (internal).
//
// The scheme (schemes/semi_implicit_scheme.hpp) fills the lower triangle of
// the matrix column by column (compressed sparse columns, rows ascending)
// through begin / add / end_column, then calls solve. Buffers are kept from
// step to step: the matrix arrays grow only when the system does, and the
// direct solver's symbolic analysis (the fill-reducing ordering) is redone
// only when the sparsity pattern changed. The numeric factorisation
// (direct) or the incomplete Cholesky preconditioner (iterative) is
// recomputed every step: the coefficients change with dt and the particles.
#pragma once

#include <Eigen/Core>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cstdint>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

class PressureSystem {
 public:
  /// Unknown counts up to which LinearSolver::automatic factorises (per
  /// dimension of the grid; measured in docs/schemes.md): a sparse Cholesky
  /// of a 1D or 2D grid Laplacian fills in little, a 3D one much more.
  static constexpr std::int64_t direct_limit_2d = 200000, direct_limit_3d = 1000;

  struct Outcome {
    bool ok = true;
    bool direct = true;
    int iterations = 0;   ///< conjugate-gradient iterations (0 for direct)
    double residual = 0;  ///< relative residual of the iterative solve
  };

  /// Starts a system of n unknowns with at most max_entries lower-triangle entries.
  void begin(int n, std::int64_t max_entries);
  /// Appends entry (row, current column); rows ascending within a column,
  /// the diagonal first.
  void add(int row, double value) {
    a_.innerIndexPtr()[entries_] = row;
    a_.valuePtr()[entries_] = value;
    ++entries_;
  }
  /// Closes the current column.
  void end_column() { a_.outerIndexPtr()[++column_] = static_cast<int>(entries_); }

  /// Solves A x = b (x: the initial guess of the iterative solver on entry).
  /// `dim` picks the automatic solver's size limit.
  Outcome solve(const Eigen::Ref<const Eigen::VectorXd>& b, Eigen::Ref<Eigen::VectorXd> x,
                LinearSolver choice, double tolerance, int dim);

  int size() const { return static_cast<int>(a_.rows()); }

 private:
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  Matrix a_;
  std::int64_t entries_ = 0;
  int column_ = 0;
  // The pattern the direct solver analysed last.
  std::vector<int> analysed_outer_, analysed_inner_;
  bool analysed_ = false;
  Eigen::SimplicialLDLT<Matrix, Eigen::Lower, Eigen::AMDOrdering<int>> direct_;
  Eigen::ConjugateGradient<Matrix, Eigen::Lower, Eigen::IncompleteCholesky<double, Eigen::Lower>>
      iterative_;
};

}  // namespace hmpm
