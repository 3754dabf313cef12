// shape.hpp — shape functions on the structured grid (internal).
//
// Each shape function is a small struct with a compile-time stencil width K
// (nodes per axis), a `locate` that, for a particle coordinate expressed in
// cell units along one axis, returns the cell its stencil is anchored to,
// and an `eval` (K = 2; given the coordinate and that cell) or `eval_lanes`
// (K = 3, the K weights in one four-lane vector; given the particle's offset
// from the cell) that returns the first node of the stencil and the K
// weights and derivatives (per cell unit). The tensor product over axes is
// formed by `Stencil`; for the 3-node shape functions in 2D and 3D the
// phases do not form it: they sum row by row from the per-axis factors
// (`Stencil::Axes`, `factorised`), and GIMP evaluates the factors of all
// the axes at once (`Gimp::eval_axes`). Locating (a truncation, a clamp, an
// integer conversion per axis) is about a third of a stencil's cost; the
// time step locates once per step and reuses the cells while particles do
// not move.
// Everything is inline, branch-light and allocation-free: it runs several
// times per particle per step. The vector lanes they compute in, and
// `fused`, are in shape/lanes.hpp.
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
#include <cstring>
#include <type_traits>

#include "shape/lanes.hpp"

namespace hmpm::shape {

/// A GIMP particle's box in cell units: its half-length and the reciprocal
/// of its length (kept per particle: the stencil multiplies by it). Zero
/// for the other shape functions.
struct Box {
  double half_length = 0.0;
  double inverse = 0.0;  ///< 1 / (2 half_length)
};

/// Particle p's box, from a ParticleState (state/particles.hpp).
template <class Particles>
inline Box box_of(const Particles& particles, std::size_t p) {
  if (particles.half_length.empty()) return {};
  return {particles.half_length[p], particles.box_inverse[p]};
}

/// Linear hat functions: 2 nodes per axis.
struct Linear {
  static constexpr int K = 2;
  static inline int locate(double xi, int cells) {
    // Particles are inside the grid (xi >= 0), so truncation is floor.
    return std::clamp(static_cast<int>(xi), 0, cells - 1);
  }
  static inline void eval(double xi, int b, int /*cells*/, Box /*box*/, int& base, double* w,
                          double* dw) {
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
///
/// With s the particle's offset from the middle node (cell units; in
/// [-1/2, 1/2) away from the grid's edges), while the box reaches neither
/// outer node (|s| <= 1 - lp: always there when lp <= 1/2, the sub-cell box
/// of one or more particles per cell) the three weights are one quadratic
/// form in s and one function g of |s|:
///   g = |s| + m^2 / (2 lp),  m = max(lp - |s|, 0),
///   w = (g/2 - s/2, 1 - g, g/2 + s/2),  dw = (g'/2 - 1/2, -g', g'/2 + 1/2),
///   g' = sign(s) (1 - m / lp).
/// (While the box covers the middle node, |s| < lp, g = (s^2 + lp^2) / (2 lp)
/// and w is the piecewise form's quadratic case; beside it, g = |s| and w is
/// the hat's. g is continuous with its slope, so are w and dw.) This costs a
/// few scalar operations, shared by the axes in 2D and 3D (`eval_axes`), and
/// per axis two vector multiply-adds; the older difference of two clamped
/// antiderivatives cost about 16 vector operations per axis and pass.
/// Otherwise (the first node clamped at the grid's edges, or a box wider than
/// a cell) `general`: the convolution as the difference of the hat's
/// antiderivative H at the box's two ends divided by the box's length, with
/// H on the clamped argument c in [-1, 1] one polynomial,
/// H(c) = 1/2 + c - c|c|/2, and the derivative the difference of the hat's
/// values, 1 - |c|. Each node's weight is exact in both; a box reaching past
/// the grid's edge loses the part on the missing node.
struct Gimp {
  static constexpr int K = 3;
  /// Smallest half-length used (cell units): a points body's particle may
  /// be tiny, and 1/half_length multiplies a difference of O(1) values.
  static constexpr double min_half_length = 1e-4;
  static inline int locate(double xi, int cells) {
    // xi >= 0 inside the grid, so truncating xi + 0.5 rounds (no lround call in the hot loop).
    // NOLINTNEXTLINE(bugprone-incorrect-roundings)
    return std::clamp(static_cast<int>(xi + 0.5) - 1, 0, cells - 2);
  }
  /// locate, lane by lane (the same truncation, rounding and clamp).
  template <class V, class I>
  static inline I locate_lanes(V xi, I last) {
#ifdef __AVX__
    __m128i c, top = _mm_setzero_si128();
    if constexpr (sizeof(V) == 16)
      c = _mm_cvttpd_epi32(xi + 0.5);
    else
      c = _mm256_cvttpd_epi32(xi + 0.5);
    std::memcpy(&top, &last, sizeof last);  // an Ints2 fills the lower half only
    c = _mm_max_epi32(_mm_min_epi32(_mm_sub_epi32(c, _mm_set1_epi32(1)), top), _mm_setzero_si128());
    I out;
    std::memcpy(&out, &c, sizeof out);
    return out;
#else
    I out;
    for (int a = 0; a < static_cast<int>(sizeof(I) / sizeof(std::int32_t)); ++a)
      out[a] = locate(xi[a], last[a] + 2);
    return out;
#endif
  }
  /// Weights (lanes 0..2) and derivatives per cell unit of nodes b, b+1, b+2;
  /// f: the particle's offset from node b (cell units). The box's
  /// half-length is at least min_half_length (setup.hpp).
  static inline void eval_lanes(double f, int b, int /*cells*/, Box box, int& base, Lanes& w,
                                Lanes& dw) {
    base = b;
    const double lp = box.half_length, inv = box.inverse;
    const double s = f - 1.0;
    const double as = std::fabs(s);
    if (as > 1.0 - lp) [[unlikely]] {
      general(s, lp, inv, w, dw);
      return;
    }
    const Regular<double> r = regular(s, as, lp, inv);
    w = weights(r.g, s);
    dw = derivatives(r.slope);
  }

  /// The weights and derivatives (Grad) of every axis of a 2D or 3D stencil,
  /// those of eval_lanes: the scalar part of the formula runs once for all
  /// the axes, in the lanes of one vector (two in 2D, four in 3D). x, origin,
  /// inv_h, cells: per axis, as in Stencil::axes; `cell` holds each axis's
  /// cell (its first node) with Located, and receives it without. Returns
  /// the cells.
  template <int Dim, bool Grad, bool Located, class Vec>
  __attribute__((always_inline)) static inline auto eval_axes(const Vec& x, const double* origin,
                                                              const double* inv_h, const int* cells,
                                                              std::int32_t* cell, Box box, Lanes* w,
                                                              Lanes* dw) {
    static_assert(Dim == 2 || Dim == 3);
    using V = std::conditional_t<Dim == 2, Lanes2, Lanes>;
    using I = std::conditional_t<Dim == 2, Ints2, Ints4>;
    // The Dim values at v in one vector (the coordinates, or the cells);
    // lane by lane in 3D: a copy of three values into a vector goes through
    // memory, and the vector's load then waits for the stores to retire.
    auto lanes_of = [](const auto* v) {
      using T = std::remove_cv_t<std::remove_pointer_t<decltype(v)>>;
      using Out = std::conditional_t<std::is_same_v<T, double>, V, I>;
      if constexpr (Dim == 2) {
        Out out;
        std::memcpy(&out, v, sizeof out);
        return out;
      } else {
        return Out{v[0], v[1], v[2], T{}};
      }
    };
    const V xv = lanes_of(x.data()), ov = lanes_of(origin), hv = lanes_of(inv_h);
    I bv{};
    if constexpr (Located) {
      bv = lanes_of(cell);
    } else {  // locate, lane by lane (in registers: the cells stored are not read back)
      bv = locate_lanes((xv - ov) * hv, lanes_of(cells) - 2);
      std::memcpy(cell, &bv, Dim * sizeof(std::int32_t));
    }
    const V f = fused(xv - ov, hv, -to_doubles(bv));  // offset from the cell, one rounding
    const V s = f - 1.0;
    const V as = lanes_abs(s);
    const double lp = box.half_length, inv = box.inverse;
    if (any_lane<Dim>(as > 1.0 - lp)) [[unlikely]] {
      irregular_axes<Dim, Grad>(f, bv, lp, inv, w, dw);
      return bv;
    }
    const Regular<V> r = regular(s, as, lp, inv);
    for (int a = 0; a < Dim; ++a) w[a] = weights(r.g[a], s[a]);
    if constexpr (Grad)
      for (int a = 0; a < Dim; ++a) dw[a] = derivatives(r.slope[a]);
    return bv;
  }

 private:
  static constexpr Lanes half = {0.5, -1.0, 0.5, 0.0}, odd = {-0.5, 0.0, 0.5, 0.0};
  static constexpr Lanes middle = {0.0, 1.0, 0.0, 0.0};

  /// g and g' of the regular form, lane by lane (V: one axis's double, or
  /// the axes' vector), from s, |s| and the box.
  template <class V>
  struct Regular {
    V g, slope;
  };
  template <class V>
  static inline Regular<V> regular(V s, V as, double lp, double inv) {
    const V zero{};
    const V m = lanes_max(lp - as, zero), mi = m * inv;
    return {fused(m, mi, as), lanes_copysign(fused(zero - 2.0, mi, zero + 1.0), s)};
  }
  /// One axis's weights and derivatives from g, s and g'.
  static inline Lanes weights(double g, double s) {
    return fused(splat(g), half, fused(splat(s), odd, middle));
  }
  static inline Lanes derivatives(double slope) {
    return fused(splat(slope), half, odd);
  }

  /// eval_axes's axes one by one (eval_lanes), when one of them is not regular.
  template <int Dim, bool Grad, class V, class I>
  __attribute__((noinline)) static void irregular_axes(V f, I b, double lp, double inv, Lanes* w,
                                                       Lanes* dw) {
    for (int a = 0; a < Dim; ++a) {
      int base;
      Lanes unused;
      eval_lanes(f[a], b[a], 0, {lp, inv}, base, w[a], Grad ? dw[a] : unused);
    }
  }

  /// Any offset and box: node by node, the difference of the antiderivative.
  __attribute__((noinline)) static void general(double s, double lp, double inv, Lanes& w,
                                                Lanes& dw) {
    const Lanes node = {-1.0, 0.0, 1.0, 2.0};
    const Lanes d = s - node;  // particle minus node, cell units
    const Lanes one = {1.0, 1.0, 1.0, 1.0};
    const Lanes hi = lanes_min(lanes_max(d + lp, -one), one);
    const Lanes lo = lanes_min(lanes_max(d - lp, -one), one);
    const Lanes ahi = lanes_abs(hi), alo = lanes_abs(lo);
    w = ((hi - lo) - 0.5 * (hi * ahi - lo * alo)) * inv;
    dw = (alo - ahi) * inv;
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
  /// Weights (lanes 0..2) and derivatives per cell unit of nodes base..base+2.
  /// With f = xi - b in [0.5, 1.5) and t = (1.5 - f, f - 1, f - 0.5) (each
  /// lane one exact sign flip and one subtraction):
  /// w = (0.5 t0^2, 0.75 - t1^2, 0.5 t2^2), dw = (-t0, -2 t1, t2).
  static inline void eval_lanes(double f, int b, int cells, Box /*box*/, int& base, Lanes& w,
                                Lanes& dw) {
    const Lanes sign = {-1.0, 1.0, 1.0, 0.0}, shift = {1.5, -1.0, -0.5, 0.0};
    const Lanes square = {0.5, -1.0, 0.5, 0.0}, constant = {0.0, 0.75, 0.0, 0.0};
    const Lanes slope = {-1.0, -2.0, 1.0, 0.0};
    const Lanes t = fused(sign, splat(f), shift);
    w = fused(square * t, t, constant);
    dw = slope * t;
    if (b < 0) [[unlikely]] {  // ghost node -1 folded into node 0
      base = 0;
      w = Lanes{w[0] + w[1], w[2], 0.0, 0.0};
      dw = Lanes{dw[0] + dw[1], dw[2], 0.0, 0.0};
    } else if (b + 2 > cells) [[unlikely]] {  // ghost node cells+1 folded into node cells
      base = cells - 2;
      w = Lanes{0.0, w[0], w[1] + w[2], 0.0};
      dw = Lanes{0.0, dw[0], dw[1] + dw[2], 0.0};
    } else {
      base = b;
    }
  }
};

/// Tensor-product stencil of one particle: node indices, weights N_i and
/// gradients dN_i/dx (per metre) for the K^Dim nodes around it.
template <int Dim, class Shape>
struct Stencil {
  static constexpr int K = Shape::K;
  static constexpr int N = Dim == 1 ? K : (Dim == 2 ? K * K : K * K * K);
  /// Elements per array: room for the last row's four-lane store (3-node shape functions).
  static constexpr int room = K == 3 ? N + 1 : N;
  std::array<std::int64_t, N> node{};
  std::array<double, room> w{};
  /// dN/dx_a of the N nodes, one array per axis (structure of arrays, so the
  /// products below vectorise across nodes). Zeroed once per phase (not per
  /// particle): weights-only passes leave them untouched.
  std::array<std::array<double, room>, Dim> dw{};

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
                      const std::int64_t* stride, Box box) {
    std::int32_t cell[Dim];
    compute<Grad, false>(x, origin, inv_h, cells, stride, box, cell);
  }

  /// As compute; Located = false also stores each axis's cell (Shape::locate)
  /// in `cell`, Located = true takes them from there (the same x, so the
  /// same cells: a particle located earlier in the step).
  template <bool Grad, bool Located, class Vec>
  __attribute__((always_inline)) inline void compute(const Vec& x, const double* origin,
                                                     const double* inv_h, const int* cells,
                                                     const std::int64_t* stride, Box box,
                                                     std::int32_t* cell) {
    if constexpr (K == 3)
      compute_lanes<Grad, Located>(x, origin, inv_h, cells, stride, box, cell);
    else
      compute_scalar<Grad, Located>(x, origin, inv_h, cells, stride, box, cell);
  }

  /// A particle's offset from its cell's first node b in cell units, from
  /// its offset d from the grid's origin in metres: d inv_h - b in one
  /// rounding (3-node shape functions).
  static inline double offset(double d, double inv_h, int b) {
    return fused(d, inv_h, -static_cast<double>(b));
  }

  /// Whether the phases sum this stencil row by row from its factors
  /// (Axes) instead of node by node: the 3-node shape functions in 2D and 3D.
  static constexpr bool factorised = K == 3 && Dim >= 2;

  /// The stencil's factors without their tensor product (3-node shape
  /// functions): the first node, and per axis the three weights and
  /// derivatives per metre (lanes 0..2). A row is the three nodes along
  /// axis 0 at one (j, k); node (i, j, k) has weight w[0][i] * wr and
  /// gradient (dw[0][i] * wr, w[0][i] * dr[1], w[0][i] * dr[2]), with the
  /// row's factors wr = w[1][j] w[2][k], dr[1] = dw[1][j] w[2][k],
  /// dr[2] = w[1][j] dw[2][k] (for_rows). A pass sums a row along axis 0 with
  /// the axis-0 factors and scales the sum by the row's: per node one
  /// multiply-add per value, and no per-node weights to form or broadcast.
  struct Axes {
    std::int64_t node0;
    Lanes w[Dim];
    Lanes dw[Dim];

    /// body(first node of the row, wr, dr) for the K^(Dim-1) rows; dr[0] is unused.
    template <class Body>
    __attribute__((always_inline)) inline void for_rows(const std::int64_t* stride,
                                                        Body&& body) const {
      std::array<double, Dim> dr{};
      if constexpr (Dim == 2) {
        for (int j = 0; j < K; ++j) {
          dr[1] = dw[1][j];
          body(node0 + j * stride[1], w[1][j], dr);
        }
      } else {
        for (int k = 0; k < K; ++k)
          for (int j = 0; j < K; ++j) {
            dr[1] = dw[1][j] * w[2][k];
            dr[2] = w[1][j] * dw[2][k];
            body(node0 + j * stride[1] + k * stride[2], w[1][j] * w[2][k], dr);
          }
      }
    }
    /// sum_i c[i] v[i] over a row's three nodes (c: lanes 0..2 of an axis's
    /// factors), component by component (plain arithmetic: no expression
    /// template left out of line when a unit's inlining budget is spent).
    template <class V>
    __attribute__((always_inline)) static inline V row_sum(const Lanes& c, const V* v) {
      if constexpr (std::is_same_v<V, double>) {
        return c[0] * v[0] + c[1] * v[1] + c[2] * v[2];
      } else if constexpr (V::SizeAtCompileTime == 2) {  // one SSE register per value
        const Pair r = c[0] * pair(v[0]) + c[1] * pair(v[1]) + c[2] * pair(v[2]);
        V out;
        std::memcpy(out.data(), &r, sizeof r);
        return out;
      } else {
        V r;
        for (int a = 0; a < V::SizeAtCompileTime; ++a)
          r[a] = c[0] * v[0][a] + c[1] * v[1][a] + c[2] * v[2][a];
        return r;
      }
    }
    /// to += s x, component by component.
    template <class V>
    __attribute__((always_inline)) static inline void add_scaled(V& to, double s, const V& x) {
      if constexpr (V::SizeAtCompileTime == 2) {
        const Pair r = pair(to) + s * pair(x);
        std::memcpy(to.data(), &r, sizeof r);
      } else {
        for (int a = 0; a < V::SizeAtCompileTime; ++a) to[a] += s * x[a];
      }
    }

   private:
    using Pair = double __attribute__((vector_size(16)));
    template <class V>
    __attribute__((always_inline)) static inline Pair pair(const V& v) {
      Pair p;
      std::memcpy(&p, v.data(), sizeof p);
      return p;
    }

   public:
    /// The first and last node of the stencil.
    std::int64_t first() const { return node0; }
    std::int64_t last(const std::int64_t* stride) const {
      std::int64_t n = node0 + K - 1;
      for (int a = 1; a < Dim; ++a) n += (K - 1) * stride[a];
      return n;
    }
  };

  /// The factors of x's stencil; Located as in compute. With Grad = false
  /// the derivatives are left unset (passes that need weights only).
  template <bool Located, bool Grad = true, class Vec>
  __attribute__((always_inline)) static inline void axes(const Vec& x, const double* origin,
                                                         const double* inv_h, const int* cells,
                                                         const std::int64_t* stride, Box box,
                                                         std::int32_t* cell, Axes& f) {
    static_assert(K == 3);
    int base[Dim];
    if constexpr (std::is_same_v<Shape, Gimp>) {  // all the axes at once
      const auto b = Shape::template eval_axes<Dim, Grad, Located>(x, origin, inv_h, cells, cell,
                                                                   box, f.w, f.dw);
      for (int a = 0; a < Dim; ++a) base[a] = b[a];
      if constexpr (Grad)
        for (int a = 0; a < Dim; ++a) f.dw[a] *= inv_h[a];
    } else {
      for (int a = 0; a < Dim; ++a) {
        const double d = x[a] - origin[a];
        if constexpr (!Located) cell[a] = Shape::locate(d * inv_h[a], cells[a]);
        Lanes unused;
        Shape::eval_lanes(offset(d, inv_h[a], cell[a]), cell[a], cells[a], box, base[a], f.w[a],
                          Grad ? f.dw[a] : unused);
        if constexpr (Grad) f.dw[a] *= inv_h[a];
      }
    }
    f.node0 = base[0];
    for (int a = 1; a < Dim; ++a) f.node0 += base[a] * stride[a];
  }

 private:
  /// 2-node (linear) stencils, one node at a time.
  template <bool Grad, bool Located, class Vec>
  __attribute__((always_inline)) inline void compute_scalar(const Vec& x, const double* origin,
                                                            const double* inv_h, const int* cells,
                                                            const std::int64_t* stride, Box box,
                                                            std::int32_t* cell) {
    int base[Dim];
    double wa[Dim][K], da[Dim][K];
    for (int a = 0; a < Dim; ++a) {
      const double xi = (x[a] - origin[a]) * inv_h[a];
      if constexpr (!Located) cell[a] = Shape::locate(xi, cells[a]);
      Shape::eval(xi, cell[a], cells[a], box, base[a], wa[a], da[a]);
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

  /// 3-node (GIMP, B-spline) stencils: each axis's three weights in one
  /// vector, and each row of the tensor product (three nodes along axis 0)
  /// one vector product and one four-lane store (the next row's store
  /// overwrites the padding lane; the last one lands in the spare element).
  /// The products are those of compute_scalar, in the same order.
  template <bool Grad, bool Located, class Vec>
  __attribute__((always_inline)) inline void compute_lanes(const Vec& x, const double* origin,
                                                           const double* inv_h, const int* cells,
                                                           const std::int64_t* stride, Box box,
                                                           std::int32_t* cell) {
    int base[Dim];
    Lanes wa[Dim], da[Dim];
    for (int a = 0; a < Dim; ++a) {
      const double d = x[a] - origin[a];
      if constexpr (!Located) cell[a] = Shape::locate(d * inv_h[a], cells[a]);
      Shape::eval_lanes(offset(d, inv_h[a], cell[a]), cell[a], cells[a], box, base[a], wa[a],
                        da[a]);
      if constexpr (Grad) da[a] *= inv_h[a];
    }
    if constexpr (Dim == 1) {
      for (int i = 0; i < K; ++i) node[i] = base[0] + i;
      store_lanes(w.data(), wa[0]);
      if constexpr (Grad) store_lanes(dw[0].data(), da[0]);
    } else if constexpr (Dim == 2) {
      const std::int64_t node0 = base[0] + base[1] * stride[1];
      for (int j = 0; j < K; ++j) {
        const std::int64_t row = node0 + j * stride[1];
        for (int i = 0; i < K; ++i) node[K * j + i] = row + i;
        store_lanes(w.data() + K * j, wa[0] * wa[1][j]);
        if constexpr (Grad) {
          store_lanes(dw[0].data() + K * j, da[0] * wa[1][j]);
          store_lanes(dw[1].data() + K * j, wa[0] * da[1][j]);
        }
      }
    } else {
      const std::int64_t node0 = base[0] + base[1] * stride[1] + base[2] * stride[2];
      for (int k = 0; k < K; ++k)
        for (int j = 0; j < K; ++j) {
          const int n = K * (j + K * k);
          const std::int64_t row = node0 + j * stride[1] + k * stride[2];
          for (int i = 0; i < K; ++i) node[n + i] = row + i;
          const double wjk = wa[1][j] * wa[2][k];
          store_lanes(w.data() + n, wa[0] * wjk);
          if constexpr (Grad) {
            const double djk = da[1][j] * wa[2][k];
            const double wdk = wa[1][j] * da[2][k];
            store_lanes(dw[0].data() + n, da[0] * wjk);
            store_lanes(dw[1].data() + n, wa[0] * djk);
            store_lanes(dw[2].data() + n, wa[0] * wdk);
          }
        }
    }
  }
};

}  // namespace hmpm::shape
