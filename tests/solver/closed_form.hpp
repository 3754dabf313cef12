// closed_form.hpp — analytical solutions of the reference problems
// (../shared/verification/README.md), used as the yardstick of the tests.
#pragma once

#include <cmath>

namespace closed_form {

constexpr double pi = 3.14159265358979323846;

/// Vibrating bar fixed at x = 0, free at x = L, first mode (§1).
struct Bar {
  double E, rho, L, v0;
  double beta() const { return pi / (2 * L); }
  double omega() const { return beta() * std::sqrt(E / rho); }
  double displacement(double x, double t) const { return v0 / omega() * std::sin(omega() * t) * std::sin(beta() * x); }
  double velocity(double x, double t) const { return v0 * std::cos(omega() * t) * std::sin(beta() * x); }
};

/// Transient pressure in a column with p = dp at x = 0 and 0 at x = L (§2).
inline double darcy_pressure(double x, double t, double L, double dp, double c, int terms = 400) {
  double p = dp * (1 - x / L);
  for (int m = 1; m <= terms; ++m) {
    const double e = std::exp(-std::pow(m * pi / L, 2) * c * t);
    if (e < 1e-300) break;
    p -= 2 * dp / (m * pi) * std::sin(m * pi * x / L) * e;
  }
  return p;
}

/// Terzaghi excess pore pressure, z from the drained face (§3).
inline double terzaghi_pressure(double z, double tv, double H, double q, int terms = 400) {
  double p = 0;
  for (int m = 0; m < terms; ++m) {
    const double M = pi * (2 * m + 1) / 2;
    const double e = std::exp(-M * M * tv);
    if (e < 1e-300) break;
    p += q * 2 / M * std::sin(M * z / H) * e;
  }
  return p;
}

inline double terzaghi_degree(double tv, int terms = 400) {
  double s = 0;
  for (int m = 0; m < terms; ++m) {
    const double M = pi * (2 * m + 1) / 2;
    s += 2 / (M * M) * std::exp(-M * M * tv);
  }
  return 1 - s;
}

}  // namespace closed_form
