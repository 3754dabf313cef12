// closed_form.hpp — analytical solutions of the reference problems
// (docs/reference-problems.md), used as the yardstick of the tests.
#pragma once

#include <cmath>
#include <vector>

namespace closed_form {

constexpr double pi = 3.14159265358979323846;

/// Vibrating bar fixed at x = 0, free at x = L, first mode (§1).
struct Bar {
  double E, rho, L, v0;
  double beta() const { return pi / (2 * L); }
  double omega() const { return beta() * std::sqrt(E / rho); }
  double displacement(double x, double t) const {
    return v0 / omega() * std::sin(omega() * t) * std::sin(beta() * x);
  }
  double velocity(double x, double t) const {
    return v0 * std::cos(omega() * t) * std::sin(beta() * x);
  }
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

/// Pressure diffusion dp/dt = c p_xx on [0, L] with p(0) = 0, a constant
/// inflow across x = L (p_x(L) = g, g = r gamma_w / k for a rate r into the
/// soil, no gravity) and p = 0 at t = 0: p = g [x - sum_n 8 L (-1)^n /
/// ((2n+1)^2 pi^2) sin(l_n x) exp(-l_n^2 c t)], l_n = (2n+1) pi / (2 L).
inline double flux_column_pressure(double x, double t, double L, double g, double c,
                                   int terms = 400) {
  double p = g * x;
  for (int n = 0; n < terms; ++n) {
    const double l = (2 * n + 1) * pi / (2 * L);
    const double e = std::exp(-l * l * c * t);
    if (e < 1e-300) break;
    p -= g * 8 * L * (n % 2 ? -1.0 : 1.0) / std::pow((2 * n + 1) * pi, 2) * std::sin(l * x) * e;
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

namespace closed_form {

/// Mandel's problem (§4; Mandel 1953, Abousleiman et al. 1996): plane-strain
/// specimen |x| <= a between rigid smooth impermeable plates carrying 2F,
/// lateral faces drained. With the drained and undrained Poisson ratios nu,
/// nu_u, the consolidation coefficient c and the initial (undrained)
/// pressure p0 = F B (1 + nu_u) / (3a):
///   p(x,t) = 2 p0 sum_n sin(a_n) / (a_n - sin(a_n) cos(a_n))
///                      (cos(a_n x/a) - cos(a_n)) exp(-a_n^2 c t / a^2),
/// a_n the positive roots of tan(a) = (1 - nu)/(nu_u - nu) a, one in each
/// ((n-1) pi, (n-1) pi + pi/2).
struct Mandel {
  double nu, nu_u, a, c, p0;
  std::vector<double> roots;

  Mandel(double nu_in, double nu_u_in, double a_in, double c_in, double p0_in, int terms = 400)
      : nu(nu_in), nu_u(nu_u_in), a(a_in), c(c_in), p0(p0_in) {
    const double k = (1 - nu) / (nu_u - nu);
    // f = sin - k a cos changes sign once on each bracket; bisection to round-off.
    auto f = [k](double x) { return std::sin(x) - k * x * std::cos(x); };
    for (int n = 1; n <= terms; ++n) {
      double lo = (n - 1) * pi + 1e-9, hi = (n - 1) * pi + pi / 2 - 1e-12;
      const bool lo_negative = f(lo) < 0;
      for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        if ((f(mid) < 0) == lo_negative)
          lo = mid;
        else
          hi = mid;
      }
      roots.push_back(0.5 * (lo + hi));
    }
  }

  double pressure(double x, double t) const {
    double s = 0;
    for (double r : roots) {
      const double e = std::exp(-r * r * c * t / (a * a));
      if (e < 1e-300) break;
      s += std::sin(r) / (r - std::sin(r) * std::cos(r)) * (std::cos(r * x / a) - std::cos(r)) * e;
    }
    return 2 * p0 * s;
  }
};

}  // namespace closed_form
