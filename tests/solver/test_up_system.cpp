// tests/solver/test_up_system.cpp — UpSystem's choice of factorisation
// (linear/up_system.hpp): symmetric quasi-definite values -> LDL^T,
// unsymmetric values -> LU, a symmetric matrix without an LDL^T in the
// given order -> the LU takes over; factors reused while the values hold.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "../../solver/src/linear/up_system.hpp"

namespace hmpm {
namespace {

// Fills a dense n x n matrix into the system (every entry in the pattern).
void fill(UpSystem& sys, const Eigen::MatrixXd& a, bool large = false) {
  const auto n = a.rows();
  if (large) sys.set_large_above(0);  // MUMPS and the reuse of factors
  sys.begin_pattern(n);
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c) sys.add_pattern(r, c);
  sys.finish_pattern(LinearSolver::direct, 1e-12);
  sys.zero_values();
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c)
      if (a(r, c) != 0.0) sys.add(r, c, a(r, c));
}

// Solves and checks x against the dense LU's solution.
void expect_solves(UpSystem& sys, const Eigen::MatrixXd& a, UpSystem::Method method) {
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(a.rows(), 1.0, 2.0);
  Eigen::VectorXd x(a.rows());
  ASSERT_TRUE(sys.solve(b, x)) << sys.error();
  EXPECT_EQ(sys.method(), method);
  const Eigen::VectorXd expected = a.fullPivLu().solve(b);
  EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm());
}

// [K -C; -C^T -S], K and S positive definite: symmetric quasi-definite.
Eigen::MatrixXd quasi_definite() {
  Eigen::MatrixXd a(4, 4);
  a << 4, 1, -1, -0.5,    //
      1, 3, -0.2, -1,     //
      -1, -0.2, -2, 0.3,  //
      -0.5, -1, 0.3, -1;
  return a;
}

TEST(UpSystem, SymmetricQuasiDefiniteValuesTakeLdltAndKeepTheFactor) {
  UpSystem sys;
  const Eigen::MatrixXd a = quasi_definite();
  fill(sys, a, /*large=*/true);
  expect_solves(sys, a, UpSystem::Method::ldlt);
  expect_solves(sys, a, UpSystem::Method::ldlt);  // same values: no new factor
  EXPECT_EQ(sys.factorisations, 1);
  Eigen::MatrixXd a2 = a;
  a2(0, 0) = 5.0;
  sys.zero_values();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) sys.add(r, c, a2(r, c));
  // New values in the same pattern: the factor in hand preconditions
  // GMRES (a reuse, no new factor); without reuse, a new factor.
  expect_solves(sys, a2, UpSystem::Method::ldlt);
  EXPECT_EQ(sys.factorisations, 1);
  EXPECT_EQ(sys.reuses, 1);
  a2(1, 1) = 3.5;
  sys.zero_values();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) sys.add(r, c, a2(r, c));
  sys.set_large_above(1000);  // no reuse below: a new factor
  expect_solves(sys, a2, UpSystem::Method::ldlt);
  EXPECT_EQ(sys.factorisations, 2);
  EXPECT_EQ(sys.reuses, 1);
  EXPECT_EQ(sys.analyses, 2);  // CHOLMOD's, after MUMPS's
  // The same pattern again in a new step: the analysis is kept.
  fill(sys, a);
  expect_solves(sys, a, UpSystem::Method::ldlt);
  EXPECT_EQ(sys.analyses, 2);
}

TEST(UpSystem, UnsymmetricValuesTakeLu) {
  UpSystem sys;
  Eigen::MatrixXd a = quasi_definite();
  a(0, 1) = 1.5;  // a non-associated tangent's asymmetry
  fill(sys, a);
  expect_solves(sys, a, UpSystem::Method::lu);
}

TEST(UpSystem, SymmetricWithoutLdltInItsOrderFallsBackToLu) {
  // Symmetric indefinite with zero diagonal: no LDL^T without pivoting.
  UpSystem sys;
  Eigen::MatrixXd a(2, 2);
  a << 0, 1, 1, 0;
  fill(sys, a);
  expect_solves(sys, a, UpSystem::Method::lu);
  // MUMPS's LDL^T (large systems) pivots, 2x2 pivots here: no LU needed.
  UpSystem large;
  fill(large, a, /*large=*/true);
  expect_solves(large, a, large.mumps() ? UpSystem::Method::ldlt : UpSystem::Method::lu);
}

TEST(UpSystem, AFactorThatNoLongerPreconditionsWellIsReplaced) {
  // A_new = A D, D diagonal from 1 to 1e4: A_new A^-1 has 40 distinct
  // eigenvalues over four decades, more than GMRES resolves in
  // reuse_iterations: a new factor (LU: A D is unsymmetric).
  const int n = 40;
  Eigen::MatrixXd a = Eigen::MatrixXd::Constant(n, n, 0.1);
  for (int i = 0; i < n; ++i) a(i, i) = 10.0 + i;
  UpSystem sys;
  fill(sys, a, /*large=*/true);
  expect_solves(sys, a, UpSystem::Method::ldlt);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = std::pow(1e4, double(i) / (n - 1));
  const Eigen::MatrixXd a2 = a * d.asDiagonal();
  sys.zero_values();
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) sys.add(r, c, a2(r, c));
  expect_solves(sys, a2, UpSystem::Method::lu);
  EXPECT_EQ(sys.reuses, 0);
  EXPECT_EQ(sys.factorisations, 2);
  // A small change to those values: the LU factor serves.
  Eigen::MatrixXd a3 = a2;
  a3(3, 3) *= 1.01;
  sys.zero_values();
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) sys.add(r, c, a3(r, c));
  expect_solves(sys, a3, UpSystem::Method::lu);
  EXPECT_EQ(sys.reuses, 1);
  EXPECT_EQ(sys.factorisations, 2);
}

}  // namespace
}  // namespace hmpm
