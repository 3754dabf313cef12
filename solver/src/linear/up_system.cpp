// linear/up_system.cpp — the direct and iterative solvers of UpSystem.
#include "linear/up_system.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/UmfPackSupport>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#ifdef HMPM_HAVE_MUMPS
#include <dmumps_c.h>
#include <metis.h>
#endif

namespace hmpm {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
}  // namespace

#ifdef HMPM_HAVE_MUMPS
namespace {
// MUMPS (sequential, Debian libmumps-seq-dev): multifrontal LDL^T of a
// general symmetric matrix (threshold pivoting, 1x1 and 2x2 pivots) on the
// lower triangle, in a METIS nested-dissection order computed here (Debian's
// sequential MUMPS has no METIS of its own). Measured against CHOLMOD's
// simplicial LDL^T in docs/performance.md: 3x faster at 77k unknowns, 6x at
// 307k, with an optimised BLAS.
class Mumps {
 public:
  Mumps() {
    std::memset(&id_, 0, sizeof id_);
    id_.comm_fortran = -987654;  // USE_COMM_WORLD: the sequential library's stub
    id_.par = 1;
    id_.sym = 2;
    id_.job = -1;
    dmumps_c(&id_);
    quiet();
  }
  ~Mumps() {
    id_.job = -2;
    dmumps_c(&id_);
  }
  Mumps(const Mumps&) = delete;
  Mumps& operator=(const Mumps&) = delete;

  /// Symbolic analysis of the lower triangle of the CSC pattern.
  bool analyse(int n, const int* outer, const int* inner) {
    irn_.clear();
    jcn_.clear();
    pos_.clear();
    for (int c = 0; c < n; ++c)
      for (int k = outer[c]; k < outer[c + 1]; ++k)
        if (inner[k] >= c) {
          irn_.push_back(inner[k] + 1);
          jcn_.push_back(c + 1);
          pos_.push_back(k);
        }
    a_.assign(pos_.size(), 0.0);
    id_.n = n;
    id_.nnz = static_cast<std::int64_t>(pos_.size());
    id_.irn = irn_.data();
    id_.jcn = jcn_.data();
    id_.a = a_.data();
    id_.icntl[6] = 0;  // AMD on small systems
    if (n >= 1000) {
      // METIS_NodeND on the graph of the pattern (no diagonal).
      std::vector<idx_t> xadj(static_cast<std::size_t>(n) + 1, 0), adj;
      adj.reserve(static_cast<std::size_t>(outer[n]));
      for (int c = 0; c < n; ++c) {
        for (int k = outer[c]; k < outer[c + 1]; ++k)
          if (inner[k] != c) adj.push_back(inner[k]);
        xadj[static_cast<std::size_t>(c) + 1] = static_cast<idx_t>(adj.size());
      }
      idx_t nn = n;
      std::vector<idx_t> perm(static_cast<std::size_t>(n)), iperm(static_cast<std::size_t>(n));
      idx_t options[METIS_NOPTIONS];
      METIS_SetDefaultOptions(options);
      if (METIS_NodeND(&nn, xadj.data(), adj.data(), nullptr, options, perm.data(), iperm.data()) ==
          METIS_OK) {
        order_.resize(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) order_[static_cast<std::size_t>(perm[i])] = i + 1;
        id_.perm_in = order_.data();
        id_.icntl[6] = 1;  // the order given
      }
    }
    id_.job = 1;
    dmumps_c(&id_);
    return id_.infog[0] >= 0;
  }

  /// Numeric factorisation of the values (laid out as the analysed pattern).
  bool factorise(const double* values) {
    for (std::size_t k = 0; k < pos_.size(); ++k) a_[k] = values[pos_[k]];
    for (int attempt = 0; attempt < 3; ++attempt) {
      id_.job = 2;
      dmumps_c(&id_);
      // -8, -9: the estimated workspace was too small (pivoting): more.
      if (id_.infog[0] == -8 || id_.infog[0] == -9) {
        id_.icntl[13] = 2 * std::max(id_.icntl[13], 20);
        continue;
      }
      break;
    }
    return id_.infog[0] >= 0;
  }

  /// x = A^-1 b with the factor in hand.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    x = b;
    id_.rhs = x.data();
    id_.nrhs = 1;
    id_.lrhs = id_.n;
    id_.job = 3;
    dmumps_c(&id_);
  }

 private:
  void quiet() {
    id_.icntl[0] = -1;  // no error, diagnostic or global output
    id_.icntl[1] = -1;
    id_.icntl[2] = -1;
    id_.icntl[3] = 0;
  }
  DMUMPS_STRUC_C id_;
  std::vector<int> irn_, jcn_, order_;
  std::vector<int> pos_;  ///< each lower-triangle entry's position in the CSC values
  std::vector<double> a_;
};
}  // namespace
#endif

struct UpSystem::Solvers {
  // Simplicial LDL^T (supernodal CHOLMOD is LL^T only, for positive
  // definite matrices); CHOLMOD picks AMD or METIS by the fill they give.
  Eigen::CholmodSimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
  Eigen::BiCGSTAB<Eigen::SparseMatrix<double>, Eigen::IncompleteLUT<double>> bicgstab;
#ifdef HMPM_HAVE_MUMPS
  Mumps mumps;
#endif
  Eigen::VectorXd residual;  ///< check of the LDL^T solution
  // Preconditioned GMRES with the factor in hand (UpSystem::solve_reusing).
  std::vector<Eigen::VectorXd> v, z;
  Eigen::VectorXd w;
  // CHOLMOD prints a failed LDL^T (which the LU then solves) on stderr:
  // the outcome is reported by the return values instead.
  Solvers() {
    ldlt.cholmod().print = 0;
  }
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
  // The analyses hold while the pattern is the one they analysed; so does
  // the factor in hand (exact while the values are those it factorised, a
  // preconditioner otherwise: solve()).
  const int* outer = matrix_.outerIndexPtr();
  const int* inner = matrix_.innerIndexPtr();
  const auto n = static_cast<std::size_t>(n_);
  const auto nnz = static_cast<std::size_t>(matrix_.nonZeros());
  const bool same = analysed_outer_.size() == n + 1 && analysed_inner_.size() == nnz &&
                    std::equal(outer, outer + n + 1, analysed_outer_.begin()) &&
                    std::equal(inner, inner + nnz, analysed_inner_.begin());
  if (same) return;
  factored_ = Method::none;
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
  // The factor in hand serves while the values are those it factorised;
  // when they have changed (the next Newton iteration, the next step in
  // the same pattern), it preconditions GMRES on the new values, unless
  // that failed last time: then, as when GMRES fails now, a new factor.
  const double* v = matrix_.valuePtr();
  const auto nnz = static_cast<std::size_t>(matrix_.nonZeros());
  const bool unchanged = factored_ != Method::none && factored_values_.size() == nnz &&
                         std::equal(v, v + nnz, factored_values_.begin());
  if (!unchanged && factored_ != Method::none) {
    if (n_ >= large_above_ && !reuse_failed_ && solve_reusing(b, x)) return true;
    reuse_failed_ = true;
    factored_ = Method::none;
  }
  if (factored_ == Method::ldlt || (factored_ == Method::none && symmetric_values()))
    if (solve_ldlt(b, x)) return true;
  return solve_lu(b, x);
}

bool UpSystem::mumps() const {
#ifdef HMPM_HAVE_MUMPS
  return n_ >= large_above_;
#else
  return false;
#endif
}

void UpSystem::apply_factor(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  Solvers& s = *solvers();
  if (factored_ == Method::lu) {
    z = s.lu.solve(r);
    return;
  }
#ifdef HMPM_HAVE_MUMPS
  if (mumps()) {
    s.mumps.solve(r, z);
    return;
  }
#endif
  z = s.ldlt.solve(r);
}

bool UpSystem::solve_reusing(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  // Restarted-free GMRES, preconditioned on the right by the factor in hand
  // (so its residual is the true one), at most reuse_iterations iterations.
  Solvers& s = *solvers();
  const auto t0 = Clock::now();
  const int m = reuse_iterations;
  const double bn = b.norm();
  x.setZero(b.size());
  if (!(bn > 0)) return true;
  s.v.resize(static_cast<std::size_t>(m) + 1);
  s.z.resize(static_cast<std::size_t>(m));
  Eigen::MatrixXd hess = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(m + 1), cs(m), sn(m);
  s.v[0] = b / bn;
  g[0] = bn;
  int k = 0;
  bool reached = false;
  for (int j = 0; j < m; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    apply_factor(s.v[uj], s.z[uj]);
    s.w.noalias() = matrix_ * s.z[uj];
    for (int i = 0; i <= j; ++i) {
      hess(i, j) = s.w.dot(s.v[static_cast<std::size_t>(i)]);
      s.w -= hess(i, j) * s.v[static_cast<std::size_t>(i)];
    }
    hess(j + 1, j) = s.w.norm();
    for (int i = 0; i < j; ++i) {  // the earlier rotations on column j
      const double t = cs[i] * hess(i, j) + sn[i] * hess(i + 1, j);
      hess(i + 1, j) = -sn[i] * hess(i, j) + cs[i] * hess(i + 1, j);
      hess(i, j) = t;
    }
    const double r = std::hypot(hess(j, j), hess(j + 1, j));
    if (!(r > 0)) break;
    cs[j] = hess(j, j) / r;
    sn[j] = hess(j + 1, j) / r;
    const double h1 = hess(j + 1, j);
    hess(j, j) = r;
    hess(j + 1, j) = 0.0;
    g[j + 1] = -sn[j] * g[j];
    g[j] *= cs[j];
    k = j + 1;
    ++reuse_gmres_iterations;
    if (std::abs(g[j + 1]) <= reuse_tolerance * bn) {
      reached = true;
      break;
    }
    if (!(h1 > 0)) break;
    s.v[uj + 1] = s.w / h1;
  }
  if (k > 0) {
    const Eigen::VectorXd y =
        hess.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    for (int i = 0; i < k; ++i) x += y[i] * s.z[static_cast<std::size_t>(i)];
  }
  s.residual = b;
  s.residual.noalias() -= matrix_ * x;
  solve_seconds += since(t0);
  if (!reached || !x.allFinite() || !(s.residual.norm() <= 10 * reuse_tolerance * bn)) return false;
  ++reuses;
  method_ = factored_;
  return true;
}

bool UpSystem::solve_ldlt(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Solvers& s = *solvers();
  const auto t0 = Clock::now();
  if (factored_ != Method::ldlt) {
#ifdef HMPM_HAVE_MUMPS
    if (!mumps()) {
      if (!ldlt_analysed_) {
        s.ldlt.analyzePattern(matrix_);
        ldlt_analysed_ = true;
        ++analyses;
      }
      s.ldlt.factorize(matrix_);
    } else if (!ldlt_analysed_) {
      if (!s.mumps.analyse(static_cast<int>(n_), matrix_.outerIndexPtr(), matrix_.innerIndexPtr()))
        return false;
      ldlt_analysed_ = true;
      ++analyses;
    }
    const bool factorised =
        mumps() ? s.mumps.factorise(matrix_.valuePtr()) : s.ldlt.info() == Eigen::Success;
#else
    if (!ldlt_analysed_) {
      s.ldlt.analyzePattern(matrix_);
      ldlt_analysed_ = true;
      ++analyses;
    }
    s.ldlt.factorize(matrix_);
    const bool factorised = s.ldlt.info() == Eigen::Success;
#endif
    ++factorisations;
    factor_seconds += since(t0);
    if (!factorised) return false;
    factored_ = Method::ldlt;
    reuse_failed_ = false;
    factored_values_.assign(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros());
  }
  const auto t1 = Clock::now();
#ifdef HMPM_HAVE_MUMPS
  if (mumps())
    s.mumps.solve(b, x);
  else
    x = s.ldlt.solve(b);
#else
  x = s.ldlt.solve(b);
#endif
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
    reuse_failed_ = false;
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
