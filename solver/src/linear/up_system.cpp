// linear/up_system.cpp — the direct and iterative solvers of UpSystem.
#include "linear/up_system.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>
#include <chrono>
#include <cmath>
#include <memory>

namespace hmpm {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

struct UpSystem::Solvers {
  // Simplicial LDL^T (supernodal CHOLMOD is LL^T only, for positive
  // definite matrices); CHOLMOD picks AMD or METIS by the fill they give.
  Eigen::CholmodSimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
  Eigen::BiCGSTAB<Eigen::SparseMatrix<double>, Eigen::IncompleteLUT<double>> bicgstab;
  Eigen::VectorXd residual;  ///< check of the LDL^T solution
  // CHOLMOD prints a failed LDL^T (which the LU then solves) on stderr:
  // the outcome is reported by the return values instead.
  Solvers() { ldlt.cholmod().print = 0; }
};

void UpSystem::SolversDeleter::operator()(Solvers* s) const {
  delete s;
}

UpSystem::Solvers* UpSystem::solvers() {
  if (!solvers_) solvers_.reset(new Solvers());
  return solvers_.get();
}

void UpSystem::begin_pattern(std::int64_t n) {
  n_ = n;
  pattern_.clear();
}

void UpSystem::finish_pattern(LinearSolver which, double linear_tolerance, int dim) {
  matrix_.resize(static_cast<int>(n_), static_cast<int>(n_));
  matrix_.setFromTriplets(pattern_.begin(), pattern_.end());
  matrix_.makeCompressed();
  const std::int64_t above = dim >= 3 ? automatic_iterative_above_3d : automatic_iterative_above_2d;
  iterative_ = which == LinearSolver::iterative || (which == LinearSolver::automatic && n_ > above);
  tolerance_ = linear_tolerance;
  factored_ = Method::none;
  // The analyses hold while the pattern is the one they analysed.
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  const auto n = static_cast<std::size_t>(n_);
  const auto nnz = static_cast<std::size_t>(matrix_.nonZeros());
  const bool same = analysed_outer_.size() == n + 1 && analysed_inner_.size() == nnz &&
                    std::equal(outer, outer + n + 1, analysed_outer_.begin()) &&
                    std::equal(inner, inner + nnz, analysed_inner_.begin());
  if (same) return;
  ldlt_analysed_ = lu_analysed_ = false;
  analysed_outer_.assign(outer, outer + n + 1);
  analysed_inner_.assign(inner, inner + nnz);
  // Mirrors: walking the columns c in order, the entries (c, r) of column
  // r come in ascending c, so one cursor per column finds them all.
  mirror_.assign(nnz, -1);
  std::vector<std::int64_t> cursor(outer, outer + n);
  structurally_symmetric_ = true;
  for (std::size_t c = 0; c < n; ++c)
    for (int k = outer[c]; k < outer[c + 1]; ++k) {
      const auto r = static_cast<std::size_t>(inner[k]);
      std::int64_t& m = cursor[r];
      if (m < outer[r + 1] && static_cast<std::size_t>(inner[m]) == c)
        mirror_[static_cast<std::size_t>(k)] = m++;
      else
        structurally_symmetric_ = false;
    }
}

void UpSystem::zero_values() {
  double* v = matrix_.valuePtr();
  for (Eigen::Index k = 0; k < matrix_.nonZeros(); ++k) v[k] = 0.0;
}

bool UpSystem::symmetric_values() const {
  if (!structurally_symmetric_) return false;
  const double* v = matrix_.valuePtr();
  const auto nnz = static_cast<std::size_t>(matrix_.nonZeros());
  double largest = 0.0;
  for (std::size_t k = 0; k < nnz; ++k) largest = std::max(largest, std::abs(v[k]));
  const double tol = 1e-10 * largest;
  for (std::size_t k = 0; k < nnz; ++k)
    if (std::abs(v[k] - v[mirror_[k]]) > tol) return false;
  return true;
}

bool UpSystem::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  ++solves;
  if (iterative_) return solve_iterative(b, x);
  // The factor in hand serves while the values are those it factorised.
  const double* v = matrix_.valuePtr();
  const auto nnz = static_cast<std::size_t>(matrix_.nonZeros());
  const bool unchanged = factored_ != Method::none && factored_values_.size() == nnz &&
                         std::equal(v, v + nnz, factored_values_.begin());
  if (!unchanged) factored_ = Method::none;
  if (factored_ == Method::ldlt || (factored_ == Method::none && symmetric_values()))
    if (solve_ldlt(b, x)) return true;
  return solve_lu(b, x);
}

bool UpSystem::solve_ldlt(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Solvers& s = *solvers();
  const auto t0 = Clock::now();
  if (factored_ != Method::ldlt) {
    if (!ldlt_analysed_) {
      s.ldlt.analyzePattern(matrix_);
      ldlt_analysed_ = true;
      ++analyses;
    }
    s.ldlt.factorize(matrix_);
    ++factorisations;
    factor_seconds += since(t0);
    if (s.ldlt.info() != Eigen::Success) return false;
    factored_ = Method::ldlt;
    factored_values_.assign(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros());
  }
  const auto t1 = Clock::now();
  x = s.ldlt.solve(b);
  // Without pivoting, an indefinite stiffness block can spoil the factor:
  // the residual says so (then the LU takes over).
  s.residual = b;
  s.residual.noalias() -= matrix_ * x;
  solve_seconds += since(t1);
  method_ = Method::ldlt;
  if (x.allFinite() && s.residual.norm() <= 1e-8 * b.norm()) return true;
  factored_ = Method::none;
  return false;
}

bool UpSystem::solve_lu(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Solvers& s = *solvers();
  const auto t0 = Clock::now();
  if (factored_ != Method::lu) {
    if (!lu_analysed_) {
      s.lu.analyzePattern(matrix_);
      lu_analysed_ = true;
      ++analyses;
    }
    s.lu.factorize(matrix_);
    ++factorisations;
    factor_seconds += since(t0);
    if (s.lu.info() != Eigen::Success) {
      error_ = "the sparse LU factorisation failed (singular Jacobian)";
      factored_ = Method::none;
      return false;
    }
    factored_ = Method::lu;
    factored_values_.assign(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros());
  }
  const auto t1 = Clock::now();
  x = s.lu.solve(b);
  solve_seconds += since(t1);
  method_ = Method::lu;
  if (x.allFinite()) return true;
  error_ = "the sparse LU solve gave a non-finite solution (singular Jacobian)";
  return false;
}

bool UpSystem::solve_iterative(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Solvers& s = *solvers();
  method_ = Method::iterative;
  const auto t0 = Clock::now();
  s.bicgstab.setTolerance(tolerance_);
  s.bicgstab.setMaxIterations(2000);  // measured: 3 to 35 iterations (2D, 2k to 190k unknowns)
  s.bicgstab.preconditioner().setDroptol(1e-4);
  s.bicgstab.preconditioner().setFillfactor(20);
  s.bicgstab.compute(matrix_);
  factor_seconds += since(t0);
  if (s.bicgstab.info() != Eigen::Success) {
    error_ = "the incomplete LU preconditioner failed";
    return false;
  }
  const auto t1 = Clock::now();
  x = s.bicgstab.solve(b);
  solve_seconds += since(t1);
  linear_iterations += s.bicgstab.iterations();
  if (s.bicgstab.info() != Eigen::Success || !x.allFinite()) {
    error_ = "BiCGSTAB did not reach linear_tolerance";
    return false;
  }
  return true;
}

}  // namespace hmpm
