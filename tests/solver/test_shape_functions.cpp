// Shape functions (solver/src/shape.hpp) against their closed forms.
//
// GIMP is evaluated branch-free and four lanes at a time (issue 21): the
// convolution of the hat with the particle's box as a difference of the
// hat's antiderivative. The reference here is the piecewise form of
// Bardenhagen & Kober (2004), written out case by case:
//   |d| < lp:               S = 1 - (d^2 + lp^2) / (2 lp),   S' = -d / lp
//   lp <= |d| < 1 - lp:     S = 1 - |d|,                     S' = -sign(d)
//   1 - lp <= |d| < 1 + lp: S = (1 + lp - |d|)^2 / (4 lp),   S' = -sign(d) (1 + lp - |d|) / (2 lp)
//   otherwise 0
// (d in cell units). Both forms are exact; they differ by round-off only:
// each lane is a few additions and products of numbers of order 1, and the
// antiderivative form then multiplies by 1/(2 lp), so its error is a few
// eps / lp: 1e-12 covers lp down to 0.01 with a margin of 100.
//
// The quadratic B-spline (clamped: the ghost node's weight folded into the
// boundary node) is checked against N(d) = 3/4 - d^2 (|d| < 1/2),
// (3/2 - |d|)^2 / 2 (1/2 <= |d| < 3/2), and for the partition of unity
// everywhere, the boundary cells included. Stencils in 2D and 3D are the
// tensor products of the 1D weights, with the nodes numbered axis 0 first.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "../../solver/src/shape.hpp"

namespace {

using hmpm::shape::Box;
using hmpm::shape::BSpline;
using hmpm::shape::Gimp;
using hmpm::shape::Linear;
using hmpm::shape::Stencil;

constexpr double round_off = 1e-12;

struct Ref {
  double w, dw;
};

Ref gimp_reference(double d, double lp) {
  const double a = std::abs(d), sg = d < 0 ? -1.0 : 1.0;
  if (a < lp) return {1.0 - (d * d + lp * lp) / (2.0 * lp), -d / lp};
  if (a < 1.0 - lp) return {1.0 - a, -sg};
  if (a < 1.0 + lp) {
    const double r = 1.0 + lp - a;
    return {r * r / (4.0 * lp), -sg * r / (2.0 * lp)};
  }
  return {0.0, 0.0};
}

Ref bspline_reference(double d) {
  const double a = std::abs(d), sg = d < 0 ? -1.0 : 1.0;
  if (a < 0.5) return {0.75 - d * d, -2.0 * d};
  if (a < 1.5) return {0.5 * (1.5 - a) * (1.5 - a), -sg * (1.5 - a)};
  return {0.0, 0.0};
}

Box box(double lp) {
  return {lp, 0.5 / lp};
}

/// A 1D stencil of a particle at xi (cell units) in a grid of `cells` cells
/// of unit size.
template <class Shape>
Stencil<1, Shape> stencil_1d(double xi, int cells, Box b) {
  Stencil<1, Shape> s;
  const double origin = 0.0, inv_h = 1.0;
  const std::int64_t stride[3] = {1, 1, 1};
  Eigen::Matrix<double, 1, 1> x;
  x[0] = xi;
  s.template compute<true>(x, &origin, &inv_h, &cells, stride, b);
  return s;
}

/// Particle positions across interior cells: a fine sweep plus the
/// breakpoints of the piecewise forms (node +- lp, node +- 1 -+ lp) and
/// their neighbours, where a case analysis goes wrong first.
std::vector<double> positions(double lp, int cells) {
  std::vector<double> xs;
  for (int i = 0; i <= 4000; ++i) xs.push_back(2.0 + 4.0 * i / 4000.0);
  for (int node = 2; node <= 6; ++node)
    for (double offset : {lp, -lp, 1.0 - lp, -(1.0 - lp), 1.0 + lp, -(1.0 + lp), 0.5, -0.5})
      for (double nudge : {-1e-9, 0.0, 1e-9}) {
        const double x = node + offset + nudge;
        if (x >= 1.5 && x <= cells - 1.5) xs.push_back(x);
      }
  return xs;
}

TEST(ShapeFunctions, GimpEqualsThePiecewiseConvolutionForEveryParticleSize) {
  const int cells = 10;
  for (double lp : {0.5, 0.25, 1.0 / 6.0, 0.125, 0.1, 0.01}) {
    double worst_w = 0.0, worst_dw = 0.0, worst_sum = 0.0, worst_grad_sum = 0.0;
    for (double xi : positions(lp, cells)) {
      const auto s = stencil_1d<Gimp>(xi, cells, box(lp));
      double sum = 0.0, grad_sum = 0.0;
      // The stencil's nodes hold the whole support of the particle (|d| <
      // 1 + lp <= 1.5 from nodes base..base+2); every other node's weight is 0.
      for (int k = 0; k < 3; ++k) {
        const Ref r = gimp_reference(xi - static_cast<double>(s.node[k]), lp);
        worst_w = std::max(worst_w, std::abs(s.w[k] - r.w));
        worst_dw = std::max(worst_dw, std::abs(s.dw[0][k] - r.dw));
        sum += s.w[k];
        grad_sum += s.dw[0][k];
      }
      const double left = gimp_reference(xi - static_cast<double>(s.node[0] - 1), lp).w;
      const double right = gimp_reference(xi - static_cast<double>(s.node[2] + 1), lp).w;
      ASSERT_EQ(left, 0.0) << "lp " << lp << " xi " << xi;
      ASSERT_EQ(right, 0.0) << "lp " << lp << " xi " << xi;
      worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
      worst_grad_sum = std::max(worst_grad_sum, std::abs(grad_sum));
    }
    EXPECT_LT(worst_w, round_off) << "lp " << lp;
    EXPECT_LT(worst_dw, round_off) << "lp " << lp;
    EXPECT_LT(worst_sum, round_off) << "lp " << lp;
    EXPECT_LT(worst_grad_sum, round_off) << "lp " << lp;
  }
}

TEST(ShapeFunctions, GimpDerivativeIsTheSlopeOfItsWeight) {
  // Central differences of the weights themselves (no reference formula):
  // the weights are piecewise quadratic, so away from the breakpoints the
  // difference quotient is exact up to round-off, eps / e = 2e-16 / 1e-5.
  const int cells = 10;
  const double lp = 0.25, e = 1e-5;
  for (int i = 0; i < 200; ++i) {
    const double xi = 3.0 + (i + 0.37) / 200.0;
    const auto s = stencil_1d<Gimp>(xi, cells, box(lp));
    const auto sp = stencil_1d<Gimp>(xi + e, cells, box(lp));
    const auto sm = stencil_1d<Gimp>(xi - e, cells, box(lp));
    if (sp.node[0] != s.node[0] || sm.node[0] != s.node[0]) continue;
    for (int k = 0; k < 3; ++k) {
      const double d = xi - static_cast<double>(s.node[k]);
      bool near_break = false;
      for (double b : {lp, 1.0 - lp, 1.0 + lp}) near_break |= std::abs(std::abs(d) - b) < 2 * e;
      if (near_break) continue;
      EXPECT_NEAR(s.dw[0][k], (sp.w[k] - sm.w[k]) / (2 * e), 1e-9) << "xi " << xi << " node " << k;
    }
  }
}

TEST(ShapeFunctions, GimpNextToTheGridEdgeAndWiderThanACellWeighsEachNodeExactly) {
  // The first node is clamped at the edges (offset from the middle node
  // beyond 1/2), and a box wider than a cell (a points body's large
  // particle) reaches past the outer nodes: both take the general form.
  // Each of the stencil's nodes keeps its exact weight; the part of the
  // box on a node outside the grid or outside the stencil is not mapped.
  // The reference is the convolution itself, integrated exactly: the hat
  // is linear between its kinks at -1, 0 and 1, so the trapezoidal rule on
  // the box split at the kinks is exact (the piecewise form above holds
  // for lp <= 1/2 only).
  auto convolution = [](double d, double lp) {
    auto hat = [](double y) { return std::max(0.0, 1.0 - std::abs(y)); };
    std::vector<double> cuts = {d - lp};
    for (double kink : {-1.0, 0.0, 1.0})
      if (kink > d - lp && kink < d + lp) cuts.push_back(kink);
    cuts.push_back(d + lp);
    double integral = 0.0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
      integral += 0.5 * (hat(cuts[i]) + hat(cuts[i + 1])) * (cuts[i + 1] - cuts[i]);
    return Ref{integral / (2.0 * lp), (hat(d + lp) - hat(d - lp)) / (2.0 * lp)};
  };
  const int cells = 8;
  for (double lp : {0.5, 0.25, 0.1, 0.7, 1.0}) {
    double worst_w = 0.0, worst_dw = 0.0;
    for (int i = 0; i <= 8000; ++i) {
      const double xi = cells * i / 8000.0;
      if (lp <= 0.5 && xi > 1.5 && xi < cells - 1.5) continue;  // the test above
      const auto s = stencil_1d<Gimp>(xi, cells, box(lp));
      for (int k = 0; k < 3; ++k) {
        const Ref r = convolution(xi - static_cast<double>(s.node[k]), lp);
        worst_w = std::max(worst_w, std::abs(s.w[k] - r.w));
        worst_dw = std::max(worst_dw, std::abs(s.dw[0][k] - r.dw));
      }
    }
    EXPECT_LT(worst_w, round_off) << "lp " << lp;
    EXPECT_LT(worst_dw, round_off) << "lp " << lp;
  }
}

TEST(ShapeFunctions, BSplineEqualsItsClosedFormAndStaysWholeAtTheGridEdge) {
  const int cells = 8;
  double worst_w = 0.0, worst_dw = 0.0, worst_sum = 0.0, worst_grad_sum = 0.0;
  for (int i = 0; i <= 8000; ++i) {
    const double xi = cells * i / 8000.0;
    const auto s = stencil_1d<BSpline>(xi, cells, Box{});
    double sum = 0.0, grad_sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      sum += s.w[k];
      grad_sum += s.dw[0][k];
    }
    worst_sum = std::max(worst_sum, std::abs(sum - 1.0));
    worst_grad_sum = std::max(worst_grad_sum, std::abs(grad_sum));
    if (xi < 1.5 || xi > cells - 1.5) continue;  // clamped: checked by the sums
    for (int k = 0; k < 3; ++k) {
      const Ref r = bspline_reference(xi - static_cast<double>(s.node[k]));
      worst_w = std::max(worst_w, std::abs(s.w[k] - r.w));
      worst_dw = std::max(worst_dw, std::abs(s.dw[0][k] - r.dw));
    }
  }
  EXPECT_LT(worst_w, round_off);
  EXPECT_LT(worst_dw, round_off);
  EXPECT_LT(worst_sum, round_off);
  EXPECT_LT(worst_grad_sum, round_off);
}

/// The grid of the 2D and 3D stencil checks: unequal cells and spacings
/// per axis, nodes numbered axis 0 first.
struct TestGrid {
  int cells[3] = {7, 9, 6};
  double origin[3] = {-1.0, 0.5, 2.0};
  double h[3] = {0.5, 0.25, 2.0};
  double inv_h[3] = {1.0 / h[0], 1.0 / h[1], 1.0 / h[2]};
  std::int64_t stride[3] = {1, cells[0] + 1, std::int64_t{cells[0] + 1} * (cells[1] + 1)};
  /// The point at xi cell units from the origin.
  template <int Dim>
  Eigen::Matrix<double, Dim, 1> point(const double* xi) const {
    Eigen::Matrix<double, Dim, 1> x;
    for (int a = 0; a < Dim; ++a) x[a] = origin[a] + xi[a] * h[a];
    return x;
  }
};

/// In 2D and 3D every node's weight and gradient are products of the 1D
/// ones (computed here by the 1D stencil), the nodes numbered axis 0 first.
template <int Dim, class Shape>
void expect_tensor_product(Box b) {
  using StencilT = Stencil<Dim, Shape>;
  const TestGrid g;
  const int* const cells = g.cells;
  const double* const inv_h = g.inv_h;
  const std::int64_t* const stride = g.stride;
  const double where[4][3] = {
      {0.3, 0.6, 0.1}, {2.77, 4.1, 3.3}, {6.9, 8.95, 5.999}, {3.5, 4.5, 2.5}};
  for (const auto& xi : where) {
    const Eigen::Matrix<double, Dim, 1> x = g.point<Dim>(xi);
    StencilT s;
    s.template compute<true>(x, g.origin, inv_h, cells, stride, b);
    std::array<Stencil<1, Shape>, Dim> axis;
    for (int a = 0; a < Dim; ++a) axis[a] = stencil_1d<Shape>(xi[a], cells[a], b);
    int n = 0;
    const int kz = Dim == 3 ? Shape::K : 1, ky = Dim >= 2 ? Shape::K : 1;
    for (int k = 0; k < kz; ++k)
      for (int j = 0; j < ky; ++j)
        for (int i = 0; i < Shape::K; ++i, ++n) {
          const int idx[3] = {i, j, k};
          std::int64_t node = 0;
          double w = 1.0;
          for (int a = 0; a < Dim; ++a) {
            node += axis[a].node[idx[a]] * stride[a];
            w *= axis[a].w[idx[a]];
          }
          EXPECT_EQ(s.node[n], node);
          EXPECT_NEAR(s.w[n], w, round_off);
          for (int g = 0; g < Dim; ++g) {
            double dw = inv_h[g];
            for (int a = 0; a < Dim; ++a) dw *= a == g ? axis[a].dw[0][idx[a]] : axis[a].w[idx[a]];
            EXPECT_NEAR(s.dw[g][n], dw, round_off * inv_h[g]);
          }
        }
  }
}

TEST(ShapeFunctions, StencilsAreTensorProductsOfTheAxes) {
  expect_tensor_product<2, Linear>(Box{});
  expect_tensor_product<3, Linear>(Box{});
  expect_tensor_product<2, Gimp>(box(0.25));
  expect_tensor_product<3, Gimp>(box(1.0 / 6.0));
  expect_tensor_product<2, BSpline>(Box{});
  expect_tensor_product<3, BSpline>(Box{});
}

/// The factorised form the phases sum row by row (Stencil::Axes, for_rows)
/// gives every node the index, weight and gradient of the tensor-product
/// stencil: node (i, row) has weight w0_i wr and gradient (dw0_i wr,
/// w0_i dr_1, w0_i dr_2). The products are grouped differently (w0_i (wy wz)
/// against (w0_i wy) wz), so they agree to round-off, not bit for bit.
/// Positions next to both grid edges are included (the B-spline's folded
/// ghost nodes).
template <int Dim, class Shape>
void expect_rows_match_stencil(Box b) {
  using StencilT = Stencil<Dim, Shape>;
  static_assert(StencilT::factorised);
  const TestGrid g;
  const int* const cells = g.cells;
  const double* const inv_h = g.inv_h;
  const std::int64_t* const stride = g.stride;
  const double where[5][3] = {
      {0.3, 0.6, 0.1}, {2.77, 4.1, 3.3}, {6.9, 8.95, 5.999}, {3.5, 4.5, 2.5}, {0.01, 8.6, 5.4}};
  for (const auto& xi : where) {
    const Eigen::Matrix<double, Dim, 1> x = g.point<Dim>(xi);
    StencilT s;
    std::int32_t cell[Dim];
    s.template compute<true, false>(x, g.origin, inv_h, cells, stride, b, cell);
    typename StencilT::Axes f, located_here;
    StencilT::template axes<true>(x, g.origin, inv_h, cells, stride, b, cell, f);
    // Locating in the same call (the first pass of a step) finds the same
    // cells and factors.
    std::int32_t cell_here[Dim];
    StencilT::template axes<false>(x, g.origin, inv_h, cells, stride, b, cell_here, located_here);
    // Each axis's factors are those of the one-axis evaluation, bit for bit
    // (GIMP evaluates all the axes at once in 2D and 3D).
    for (int a = 0; a < Dim; ++a) {
      EXPECT_EQ(cell_here[a], cell[a]);
      int base = 0;
      hmpm::shape::Lanes w1, dw1;
      Shape::eval_lanes(StencilT::offset(x[a] - g.origin[a], inv_h[a], cell[a]), cell[a], cells[a],
                        b, base, w1, dw1);
      for (int i = 0; i < Shape::K; ++i) {
        EXPECT_EQ(located_here.w[a][i], f.w[a][i]);
        EXPECT_EQ(located_here.dw[a][i], f.dw[a][i]);
        EXPECT_EQ(f.w[a][i], w1[i]);
        EXPECT_EQ(f.dw[a][i], dw1[i] * inv_h[a]);
      }
    }
    EXPECT_EQ(f.first(), s.node[0]);
    EXPECT_EQ(f.last(stride), s.node[StencilT::N - 1]);
    int n = 0;
    f.for_rows(stride, [&](std::int64_t row, double wr, const auto& dr) {
      for (int i = 0; i < Shape::K; ++i, ++n) {
        EXPECT_EQ(row + i, s.node[n]);
        EXPECT_NEAR(f.w[0][i] * wr, s.w[n], round_off);
        EXPECT_NEAR(f.dw[0][i] * wr, s.dw[0][n], round_off * inv_h[0]);
        for (int a = 1; a < Dim; ++a)
          EXPECT_NEAR(f.w[0][i] * dr[a], s.dw[a][n], round_off * inv_h[a]);
      }
    });
    EXPECT_EQ(n, StencilT::N);
    // The row sums the phases use: sum_i c_i v_i over a row's nodes.
    const double v[3] = {1.5, -2.0, 0.25};
    EXPECT_DOUBLE_EQ(StencilT::Axes::row_sum(f.w[0], v),
                     f.w[0][0] * 1.5 - f.w[0][1] * 2.0 + f.w[0][2] * 0.25);
  }
}

TEST(ShapeFunctions, RowFactorsReproduceTheTensorProductStencil) {
  expect_rows_match_stencil<2, Gimp>(box(0.25));
  expect_rows_match_stencil<3, Gimp>(box(1.0 / 6.0));
  expect_rows_match_stencil<2, BSpline>(Box{});
  expect_rows_match_stencil<3, BSpline>(Box{});
}

}  // namespace
