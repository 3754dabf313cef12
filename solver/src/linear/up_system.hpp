// linear/up_system.hpp — the sparse linear system of the quasi-static u-p
// Newton iterations (internal).
//
// One system per time step: the sparsity pattern (which degrees of freedom
// share a particle stencil) is set once per step, when the particles have
// moved and the grid has been reset; the values are refilled in that pattern
// at every Newton iteration (no allocation). The matrix is the saddle-point
// Jacobian of schemes/quasi_static_scheme.hpp, scaled so that both blocks
// have the same size (see there): symmetric quasi-definite for elastic and
// associated plastic soil, unsymmetric for non-associated plasticity.
//
// Direct solves (docs/schemes.md, measurements in docs/performance.md):
// - symmetric values (checked at every solve, entry against its mirror,
//   to 1e-10 of the largest entry): an LDL^T factorisation without pivoting
//   (SuiteSparse's CHOLMOD, simplicial, AMD or METIS ordering), which a
//   quasi-definite matrix admits in any order; its solution is checked
//   (residual) and, should the factorisation have failed or be inaccurate
//   (an indefinite stiffness block, e.g. softening), the LU below is used;
// - otherwise UMFPACK's LU (SuiteSparse; COLAMD/AMD ordering, partial
//   pivoting).
// The symbolic analysis (ordering, elimination tree) is kept while the
// pattern does not change, across Newton iterations and time steps; the
// numeric factorisation is kept while the values do not change either (an
// elastic step's Jacobian is the same at every Newton iteration: its second
// and later iterations cost a solve, not a factorisation).
// Iterative solves: BiCGSTAB with an incomplete LU (ILUT) preconditioner.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "hmpm/problem.hpp"

namespace hmpm {

class UpSystem {
 public:
  /// Unknowns above which LinearSolver::automatic takes the iterative solver,
  /// per grid dimension (docs/schemes.md gives the measurements behind it):
  /// a 2D factor fills in like n log n, a 3D one like n^(4/3) and costs
  /// n^2 operations.
  static constexpr std::int64_t automatic_iterative_above_2d = 2000000;
  static constexpr std::int64_t automatic_iterative_above_3d = 200000;

  /// Starts a new pattern of n unknowns (the triplet list keeps its capacity).
  void begin_pattern(std::int64_t n);
  /// Marks entry (r, c) as possibly non-zero.
  void add_pattern(std::int64_t r, std::int64_t c) {
    pattern_.emplace_back(static_cast<int>(r), static_cast<int>(c), 0.0);
  }
  /// Compresses the pattern; the solver chosen for `which` (automatic: by
  /// size and the grid's dimension `dim`) analyses it on the first solve,
  /// unless it analysed the same pattern before.
  void finish_pattern(LinearSolver which, double linear_tolerance, int dim = 2);

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

  /// Which factorisation the last direct solve used.
  enum class Method { none, ldlt, lu, iterative };
  Method method() const { return method_; }

  /// Systems of large_system unknowns or more (set_large_above: tests) take
  /// the faster factorisation for large systems, MUMPS's LDL^T, when the
  /// build has it (HMPM_HAVE_MUMPS; it pivots, so symmetric indefinite
  /// values take it too), and reuse a factor for changed values (Newton
  /// iterations after the first, later steps in the same pattern): GMRES
  /// preconditioned by it, to reuse_tolerance of |b| within
  /// reuse_iterations, else a new factor. Below, neither pays (measured,
  /// docs/performance.md): MUMPS's analysis and a GMRES iteration cost
  /// more there than CHOLMOD's factor.
  static constexpr std::int64_t large_system = 20000;
  static constexpr int reuse_iterations = 10;
  static constexpr double reuse_tolerance = 1e-11;
  void set_large_above(std::int64_t n) {
    large_above_ = n;
    factored_ = Method::none;
    ldlt_analysed_ = false;
  }
  /// True when the symmetric factorisation of this size is MUMPS's.
  bool mumps() const;

  std::int64_t linear_iterations = 0;  ///< iterative solves: summed iterations
  std::int64_t solves = 0;
  // Cumulated, for benchmarks (not saved in checkpoints).
  std::int64_t analyses = 0, factorisations = 0;        ///< symbolic / numeric
  std::int64_t reuses = 0, reuse_gmres_iterations = 0;  ///< solves by an older factor
  double factor_seconds = 0.0, solve_seconds = 0.0;

 private:
  struct Solvers;
  Solvers* solvers();

  /// True when the values are symmetric (to 1e-10 of the largest).
  bool symmetric_values() const;
  bool solve_ldlt(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  bool solve_lu(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  bool solve_iterative(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  bool solve_reusing(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  void apply_factor(const Eigen::VectorXd& r, Eigen::VectorXd& z);

  std::int64_t n_ = 0;
  bool iterative_ = false;
  // Whether each solver's symbolic analysis / numeric factorisation belongs
  // to the current pattern / values.
  bool ldlt_analysed_ = false, lu_analysed_ = false;
  Method factored_ = Method::none;  ///< the factor that holds factored_values_
  Method method_ = Method::none;
  std::int64_t large_above_ = large_system;
  bool reuse_failed_ = false;
  std::vector<double> factored_values_;
  // The pattern the factorisations analysed, and each entry's mirror (the
  // position of (c, r) for entry (r, c); -1: none, the pattern unsymmetric).
  std::vector<int> analysed_outer_, analysed_inner_;
  std::vector<std::int64_t> mirror_;
  bool structurally_symmetric_ = false;
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
