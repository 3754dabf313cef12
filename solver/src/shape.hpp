// shape.hpp — shape functions on the structured grid (internal).
//
// Each shape function is a small struct with a compile-time stencil width K
// (nodes per axis), a `locate` that, for a particle coordinate expressed in
// cell units along one axis, returns the cell its stencil is anchored to,
// and an `eval` that, given that cell, returns the first node of the stencil
// and the K weights and derivatives (per cell unit). The tensor product over
// axes is formed by `Stencil`. Locating (a truncation, a clamp, an integer
// conversion per axis) is about a third of a stencil's cost; the time step
// locates once per step and reuses the cells while particles do not move.
// Everything is inline, branch-light and allocation-free: it runs several
// times per particle per step.
//
// Stencils never leave the grid: at the grid boundary the first node is
// clamped, and for the quadratic B-spline the weight of the missing ghost node
// is folded into the boundary node (a "clamped" B-spline), which keeps the
// partition of unity and a zero sum of gradients.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace hmpm::shape {

/// Linear hat functions: 2 nodes per axis.
struct Linear {
  static constexpr int K = 2;
  static inline int locate(double xi, int cells) {
    // Particles are inside the grid (xi >= 0), so truncation is floor.
    return std::clamp(static_cast<int>(xi), 0, cells - 1);
  }
  static inline void eval(double xi, int b, int /*cells*/, double /*half_length*/, int& base,
                          double* w, double* dw) {
    const double f = xi - b;
    base = b;
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = -1.0;
    dw[1] = 1.0;
  }
};

/// Uniform GIMP (Bardenhagen & Kober 2004): the particle is a box of
/// half-length `half_length` (cell units) convolved with the hat function.
/// 3 nodes per axis.
struct Gimp {
  static constexpr int K = 3;
  static inline void weight(double d, double lp, double& s, double& ds) {
    const double a = std::abs(d);
    const double sg = d < 0 ? -1.0 : 1.0;
    if (a < lp) {
      s = 1.0 - (d * d + lp * lp) / (2.0 * lp);
      ds = -d / lp;
    } else if (a < 1.0 - lp) {
      s = 1.0 - a;
      ds = -sg;
    } else if (a < 1.0 + lp) {
      const double r = 1.0 + lp - a;
      s = r * r / (4.0 * lp);
      ds = -sg * r / (2.0 * lp);
    } else {
      s = 0.0;
      ds = 0.0;
    }
  }
  static inline int locate(double xi, int cells) {
    // xi >= 0 inside the grid, so truncating xi + 0.5 rounds (no lround call in the hot loop).
    // NOLINTNEXTLINE(bugprone-incorrect-roundings)
    return std::clamp(static_cast<int>(xi + 0.5) - 1, 0, cells - 2);
  }
  static inline void eval(double xi, int b, int /*cells*/, double half_length, int& base, double* w,
                          double* dw) {
    base = b;
    for (int k = 0; k < 3; ++k) weight(xi - (b + k), half_length, w[k], dw[k]);
  }
};

/// Quadratic B-spline, 3 nodes per axis, clamped at the grid boundary.
struct BSpline {
  static constexpr int K = 3;
  /// The cell of the middle node's left neighbour; -1 or cells - 1 next to
  /// the boundary, where eval folds the ghost node in.
  static inline int locate(double xi, int /*cells*/) {
    return static_cast<int>(std::floor(xi - 0.5));
  }
  static inline void eval(double xi, int b, int cells, double /*half_length*/, int& base, double* w,
                          double* dw) {
    const double f = xi - b;  // in [0.5, 1.5)
    double w0 = 0.5 * (1.5 - f) * (1.5 - f), w1 = 0.75 - (f - 1.0) * (f - 1.0),
           w2 = 0.5 * (f - 0.5) * (f - 0.5);
    double d0 = -(1.5 - f), d1 = -2.0 * (f - 1.0), d2 = f - 0.5;
    if (b < 0) {  // ghost node -1 folded into node 0
      base = 0;
      w[0] = w0 + w1;
      w[1] = w2;
      w[2] = 0.0;
      dw[0] = d0 + d1;
      dw[1] = d2;
      dw[2] = 0.0;
    } else if (b + 2 > cells) {  // ghost node cells+1 folded into node cells
      base = cells - 2;
      w[0] = 0.0;
      w[1] = w0;
      w[2] = w1 + w2;
      dw[0] = 0.0;
      dw[1] = d0;
      dw[2] = d1 + d2;
    } else {
      base = b;
      w[0] = w0;
      w[1] = w1;
      w[2] = w2;
      dw[0] = d0;
      dw[1] = d1;
      dw[2] = d2;
    }
  }
};

/// Tensor-product stencil of one particle: node indices, weights N_i and
/// gradients dN_i/dx (per metre) for the K^Dim nodes around it.
template <int Dim, class Shape>
struct Stencil {
  static constexpr int K = Shape::K;
  static constexpr int N = Dim == 1 ? K : (Dim == 2 ? K * K : K * K * K);
  std::array<std::int64_t, N> node{};
  std::array<double, N> w{};
  /// dN/dx_a of the N nodes, one array per axis (structure of arrays, so the
  /// products below vectorise across nodes). Zeroed once per phase (not per
  /// particle): weights-only passes leave them untouched.
  std::array<std::array<double, N>, Dim> dw{};

  /// Gradient of node k's shape function.
  Eigen::Matrix<double, Dim, 1> grad(int k) const {
    Eigen::Matrix<double, Dim, 1> g;
    for (int a = 0; a < Dim; ++a) g[a] = dw[a][k];
    return g;
  }

  /// x: particle position; origin, inv_h: grid; cells, stride: per axis.
  /// With Grad = false only node indices and weights are filled (passes that
  /// interpolate values but not gradients).
  template <bool Grad = true, class Vec>
  inline void compute(const Vec& x, const double* origin, const double* inv_h, const int* cells,
                      const std::int64_t* stride, double half_length) {
    std::int32_t cell[Dim];
    compute<Grad, false>(x, origin, inv_h, cells, stride, half_length, cell);
  }

  /// As compute; Located = false also stores each axis's cell (Shape::locate)
  /// in `cell`, Located = true takes them from there (the same x, so the
  /// same cells: a particle located earlier in the step).
  template <bool Grad, bool Located, class Vec>
  inline void compute(const Vec& x, const double* origin, const double* inv_h, const int* cells,
                      const std::int64_t* stride, double half_length, std::int32_t* cell) {
    int base[Dim];
    double wa[Dim][K], da[Dim][K];
    for (int a = 0; a < Dim; ++a) {
      const double xi = (x[a] - origin[a]) * inv_h[a];
      if constexpr (!Located) cell[a] = Shape::locate(xi, cells[a]);
      Shape::eval(xi, cell[a], cells[a], half_length, base[a], wa[a], da[a]);
      if constexpr (Grad)
        for (int k = 0; k < K; ++k) da[a][k] *= inv_h[a];
    }
    if constexpr (Dim == 1) {
      for (int i = 0; i < K; ++i) {
        node[i] = base[0] + i;
        w[i] = wa[0][i];
        if constexpr (Grad) dw[0][i] = da[0][i];
      }
    } else if constexpr (Dim == 2) {
      const std::int64_t node0 = base[0] + base[1] * stride[1];
      int n = 0;
      for (int j = 0; j < K; ++j) {
        const std::int64_t row = node0 + j * stride[1];
        for (int i = 0; i < K; ++i, ++n) {
          node[n] = row + i;
          w[n] = wa[0][i] * wa[1][j];
          if constexpr (Grad) {
            dw[0][n] = da[0][i] * wa[1][j];
            dw[1][n] = wa[0][i] * da[1][j];
          }
        }
      }
    } else {
      const std::int64_t node0 = base[0] + base[1] * stride[1] + base[2] * stride[2];
      int n = 0;
      for (int k = 0; k < K; ++k)
        for (int j = 0; j < K; ++j) {
          const std::int64_t row = node0 + j * stride[1] + k * stride[2];
          const double wjk = wa[1][j] * wa[2][k];
          const double djk = da[1][j] * wa[2][k];
          const double wdk = wa[1][j] * da[2][k];
          for (int i = 0; i < K; ++i, ++n) {
            node[n] = row + i;
            w[n] = wa[0][i] * wjk;
            if constexpr (Grad) {
              dw[0][n] = da[0][i] * wjk;
              dw[1][n] = wa[0][i] * djk;
              dw[2][n] = wa[0][i] * wdk;
            }
          }
        }
    }
  }
};

}  // namespace hmpm::shape
