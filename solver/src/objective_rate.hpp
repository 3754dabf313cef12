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

}  // namespace hmpm
