// objective_rate.hpp — the Jaumann (co-rotational) stress rate (internal).
//
// sigma += dt (W sigma - sigma W), with the spin W = (L - L^T)/2 of the
// velocity gradient L, so that a rigid rotation rotates the stress instead
// of straining it. Written out per Voigt component: W is antisymmetric and
// sigma symmetric, so W sigma - sigma W = M + M^T with M = W sigma; only the
// three spin components a = W_xy, b = W_yz, c = W_zx enter.
// tests/solver/test_objective_rate.cpp checks it against the matrix form and
// against the exact rotation R sigma R^T.
#pragma once

#include <Eigen/Core>

namespace hmpm {

/// Adds the Jaumann rotation over one step to the Voigt stress s
/// (xx, yy, zz, xy, yz, zx). 1D has no spin: nothing to do. Always inlined:
/// GCC 12 kept the 3D version out of line, which sends the stress through
/// memory at every particle (callgrind, 3D dry: 1328 -> 1294 instructions per
/// particle-step).
template <int Dim>
__attribute__((always_inline)) inline void rotate_jaumann(
    Eigen::Matrix<double, 6, 1>& s, const Eigen::Matrix<double, Dim, Dim>& grad_v, double dt) {
  if constexpr (Dim == 2) {
    const double a = 0.5 * (grad_v(0, 1) - grad_v(1, 0)) * dt;  // W_xy dt
    const double dxx = 2.0 * a * s[3], dxy = a * (s[1] - s[0]);
    s[0] += dxx;
    s[1] -= dxx;
    s[3] += dxy;
  } else if constexpr (Dim == 3) {
    const double a = 0.5 * (grad_v(0, 1) - grad_v(1, 0)) * dt;  // W_xy dt
    const double b = 0.5 * (grad_v(1, 2) - grad_v(2, 1)) * dt;  // W_yz dt
    const double c = 0.5 * (grad_v(2, 0) - grad_v(0, 2)) * dt;  // W_zx dt
    const double xx = s[0], yy = s[1], zz = s[2], xy = s[3], yz = s[4], zx = s[5];
    s[0] += 2.0 * (a * xy - c * zx);
    s[1] += 2.0 * (b * yz - a * xy);
    s[2] += 2.0 * (c * zx - b * yz);
    s[3] += a * (yy - xx) + b * zx - c * yz;
    s[4] += b * (zz - yy) + c * xy - a * zx;
    s[5] += c * (xx - zz) + a * yz - b * xy;
  }
}

/// The spins of a Dim-dimensional gradient: 1 in 2D (W_xy), 3 in 3D
/// (W_xy, W_yz, W_zx), 0 in 1D.
template <int Dim>
inline constexpr int spin_count = Dim == 2 ? 1 : (Dim == 3 ? 3 : 0);

/// The derivative of rotate_jaumann(s, grad, 1) with respect to the
/// gradient, for the Newton tangent of a scheme that rotates the stress by
/// its increment's spin: the rotated stress is linear in the spins, so
/// d s / d w (Voigt, from the stress s before the rotation) and
/// d w / d grad(i, j) are exact. dsdw[w] is the Voigt derivative by spin w;
/// the spin w of a gradient g is sum over (i, j) of coeff(w, i, j) g(i, j)
/// (spin_gradient below).
template <int Dim>
inline void jaumann_derivatives(
    const Eigen::Matrix<double, 6, 1>& s,
    Eigen::Matrix<double, 6, 1> (&dsdw)[spin_count<Dim> > 0 ? spin_count<Dim> : 1]) {
  const double xx = s[0], yy = s[1], zz = s[2], xy = s[3], yz = s[4], zx = s[5];
  if constexpr (Dim == 2) {
    dsdw[0] << 2.0 * xy, -2.0 * xy, 0.0, yy - xx, 0.0, 0.0;
  } else if constexpr (Dim == 3) {
    dsdw[0] << 2.0 * xy, -2.0 * xy, 0.0, yy - xx, -zx, yz;  // by a = W_xy
    dsdw[1] << 0.0, 2.0 * yz, -2.0 * yz, zx, zz - yy, -xy;  // by b = W_yz
    dsdw[2] << -2.0 * zx, 0.0, 2.0 * zx, -yz, xy, xx - zz;  // by c = W_zx
  } else {
    dsdw[0].setZero();
  }
}

/// The spin w of a displacement gradient g = sum_l u_l grad_l^T by the
/// displacement component b of a node with shape gradient gl:
/// d w / d u_{l,b} (a = 0.5 (g01 - g10), b = 0.5 (g12 - g21), c = 0.5 (g20 - g02)).
template <int Dim>
inline double spin_gradient(int w, int b, const Eigen::Matrix<double, Dim, 1>& gl) {
  if constexpr (Dim < 2) {
    return 0.0;
  } else {
    const int i = w == 0 ? 0 : (w == 1 ? 1 : 2), j = w == 0 ? 1 : (w == 1 ? 2 : 0);
    if (b == i) return 0.5 * gl[j];  // g(i, j) = u_i gl_j
    if (b == j) return -0.5 * gl[i];
    return 0.0;
  }
}

}  // namespace hmpm
