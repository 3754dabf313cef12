// column_waves.hpp — waves in a saturated column (verification §5,
// Verruijt): the exact solution of the 1D u-p equations (Laplace transform,
// four exponentials, de Hoog's inversion: exact()) and a converged
// finite-difference solution of the same equations (reference()) that
// checks it. Test helpers, not solver code.
//
// x up, base x = 0 fixed and impermeable, top x = H drained (p = 0) and
// loaded by the compressive traction q(t); no gravity; tension positive:
//   rho a = d(sigma' - p)/dx,              sigma' = E_oed du/dx
//   w = -kappa (dp/dx + rho_f a),          kappa = k / gamma_w
//   Q dp/dt = -dv/dx - dw/dx
// Velocities, accelerations and Darcy fluxes live on the N + 1 nodes,
// sigma' and p at the N cell centres. Leapfrog in time: a^n from the
// stresses at n, v^{n+1/2} = v^{n-1/2} + dt a^n, w^n from p^n and a^n,
// then sigma' and p to n + 1 from v^{n+1/2} and w^n. Second order in space
// (checked by the test that uses it: the differences between N, 2N and 4N
// cells fall by about 4).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <vector>

namespace column_waves {

struct Column {
  double H = 0.5, porosity = 0.1, rho_s = 2222.0, rho_f = 1000.0;
  double e_oed = 200e3;          ///< constrained modulus, Pa
  double storage = 0.1 / 20e3;   ///< Q = n / Kf, 1/Pa
  double kappa = 1e-4 / 9810.0;  ///< k / gamma_w
  double rho() const { return (1 - porosity) * rho_s + porosity * rho_f; }
  double fast_speed() const { return std::sqrt((e_oed + 1 / storage) / rho()); }
};

/// sigma' and p at `depths` (from the top) at each of `times`, rows in time
/// order: out[t][2 d] = sigma', out[t][2 d + 1] = p. The column starts at
/// rest with sigma' = 0 and p = initial_pressure (Terzaghi's start: p = q
/// with the load q carried by the water, the top drained from t = 0).
inline std::vector<std::vector<double>> reference(const Column& c,
                                                  const std::function<double(double)>& load,
                                                  int cells, const std::vector<double>& times,
                                                  const std::vector<double>& depths,
                                                  double initial_pressure = 0.0) {
  const int n = cells;
  const double h = c.H / n, rho = c.rho();
  const double dt = 0.25 * std::min(h / c.fast_speed(), c.storage * h * h / (2 * c.kappa));
  std::vector<double> v(n + 1, 0.0), a(n + 1, 0.0), w(n + 1, 0.0), s(n, 0.0),
      p(n, initial_pressure);
  std::vector<std::vector<double>> out;
  // Linear interpolation of a cell-centred field at depth z (p = 0 at the
  // top face, where the last cell's value is extrapolated for sigma').
  auto at = [&](const std::vector<double>& f, double z, bool drained) {
    const double x = c.H - z;
    const double cx = x / h - 0.5;
    if (cx >= n - 1) {
      const double top = drained ? 0.0 : f[n - 1];
      const double r = (cx - (n - 1)) / 0.5;
      return f[n - 1] + r * (top - f[n - 1]);
    }
    const int j = std::clamp(static_cast<int>(std::floor(cx)), 0, n - 2);
    const double r = std::clamp(cx - j, 0.0, 1.0);
    return f[j] + r * (f[j + 1] - f[j]);
  };
  double t = 0.0;
  std::size_t next = 0;
  auto sample = [&]() {
    std::vector<double> row;
    for (double z : depths) {
      row.push_back(at(s, z, false));
      row.push_back(at(p, z, true));
    }
    out.push_back(std::move(row));
  };
  while (next < times.size()) {
    if (t >= times[next] - 1e-12) {
      sample();
      ++next;
      continue;
    }
    const double step = std::min(dt, times[next] - t);
    // Accelerations from the stresses at t (node 0 fixed).
    for (int i = 1; i < n; ++i) a[i] = ((s[i] - p[i]) - (s[i - 1] - p[i - 1])) / (rho * h);
    a[n] = (-load(t) - (s[n - 1] - p[n - 1])) / (rho * h / 2);
    for (int i = 1; i <= n; ++i) v[i] += step * a[i];
    for (int i = 1; i < n; ++i) w[i] = -c.kappa * ((p[i] - p[i - 1]) / h + c.rho_f * a[i]);
    w[n] = -c.kappa * ((0.0 - p[n - 1]) / (h / 2) + c.rho_f * a[n]);
    for (int j = 0; j < n; ++j) {
      const double dv = (v[j + 1] - v[j]) / h, dw = (w[j + 1] - w[j]) / h;
      s[j] += step * c.e_oed * dv;
      p[j] += step * (-dv - dw) / c.storage;
    }
    t += step;
  }
  return out;
}

using Complex = std::complex<double>;

/// The inverse Laplace transform of fhat at t > 0 by de Hoog, Knight and
/// Stokes (1982): the Fourier series of e^{-gamma t} f(t) on [0, 2T],
/// summed as a continued fraction (quotient-difference algorithm) with
/// their remainder estimate. 2M + 1 terms.
template <class F>
double de_hoog(const F& fhat, double t, double T, int M, double negligible, double tol = 1e-12) {
  const double pi = 3.14159265358979323846;
  const double gamma = -std::log(tol) / (2 * T);
  const int n = 2 * M;
  std::vector<Complex> a(n + 1);
  for (int k = 0; k <= n; ++k) a[k] = fhat(Complex(gamma, k * pi / T));
  a[0] *= 0.5;
  // Terms that underflow to zero (a wave that has not arrived: the
  // transform is exp(-s z / c) small) would divide zero by zero below; the
  // series then bounds f by (2M + 1) max|a_k| e^{gamma t} / T.
  if (std::find(a.begin(), a.end(), Complex(0.0)) != a.end()) {
    double bound = 0.0;
    for (const Complex& v : a) bound = std::max(bound, std::abs(v));
    bound *= (n + 1) * std::exp(gamma * t) / T;
    return bound < negligible ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  }
  // Quotient-difference table, one row r at a time (updated in place in
  // increasing i, each entry reading only entries not yet overwritten):
  // e_r[i] = q_r[i+1] - q_r[i] + e_{r-1}[i+1], q_{r+1}[i] = q_r[i+1] e_r[i+1] / e_r[i];
  // the continued fraction's coefficients are d_{2r-1} = -q_r[0], d_{2r} = -e_r[0].
  std::vector<Complex> e(n + 1), q(n + 1), d(n + 1);
  for (int i = 0; i < n; ++i) q[i] = a[i + 1] / a[i];
  d[0] = a[0];
  for (int r = 1; r <= M; ++r) {
    for (int i = 0; i <= n - 2 * r; ++i) e[i] = q[i + 1] - q[i] + e[i + 1];
    const int j = 2 * r;
    d[j - 1] = -q[0];
    d[j] = -e[0];
    if (r < M)
      for (int i = 0; i <= n - 2 * r - 1; ++i) q[i] = q[i + 1] * e[i + 1] / e[i];
  }
  const Complex z = std::exp(Complex(0, pi * t / T));
  Complex A_prev = 0.0, A = d[0], B_prev = 1.0, B = 1.0;  // A_{-1}, A_0, B_{-1}, B_0
  for (int k = 1; k < n; ++k) {
    const Complex An = A + d[k] * z * A_prev, Bn = B + d[k] * z * B_prev;
    A_prev = A;
    A = An;
    B_prev = B;
    B = Bn;
  }
  // Last term with the remainder estimate.
  const Complex h = 0.5 * (1.0 + (d[n - 1] - d[n]) * z);
  const Complex R = -h * (1.0 - std::sqrt(1.0 + d[n] * z / (h * h)));
  const Complex An = A + R * A_prev, Bn = B + R * B_prev;
  return std::exp(gamma * t) / T * (An / Bn).real();
}

/// The Laplace transforms of sigma' and p at height x of the column under
/// the load transform qhat (Laplace variable s): the u-p equations of
/// reference() with zero initial state give, for U, P ~ exp(lambda x),
///   (E mu - rho s^2)(kappa mu - Q s) = s mu (1 - kappa rho_f s),  mu = lambda^2,
/// two roots mu, four exponentials; amplitudes from u = 0 and dp/dx = 0 at
/// the base (w = -kappa (p' + rho_f s^2 U) = 0 with U = 0), p = 0 and
/// sigma' - p = -q at the top. Written with exp(r (x - H)) and exp(-r x)
/// (Re r >= 0), so nothing overflows.
inline std::array<Complex, 2> transformed(const Column& c, Complex s, Complex qhat, double x) {
  const double E = c.e_oed, rho = c.rho(), Q = c.storage, kap = c.kappa, H = c.H;
  const Complex a2 = E * kap;
  const Complex a1 = -(E * Q * s + s + kap * s * s * (rho - c.rho_f));
  const Complex a0 = rho * Q * s * s * s;
  const Complex disc = std::sqrt(a1 * a1 - 4.0 * a2 * a0);
  const Complex qq = -0.5 * (a1 + (std::real(std::conj(a1) * disc) >= 0 ? disc : -disc));
  const Complex mu[2] = {qq / a2, a0 / qq};
  Complex lam[4], beta[4];
  bool plus[4];
  for (int i = 0; i < 2; ++i) {
    Complex r = std::sqrt(mu[i]);
    if (r.real() < 0) r = -r;
    const int j = 2 * i;
    lam[j] = r;
    lam[j + 1] = -r;
    plus[j] = true;
    plus[j + 1] = false;
  }
  for (int k = 0; k < 4; ++k) beta[k] = (E * lam[k] * lam[k] - rho * s * s) / lam[k];
  auto phi = [&](int k, double xx) {
    return plus[k] ? std::exp(lam[k] * (xx - H)) : std::exp(lam[k] * xx);
  };
  Complex m[4][5];
  for (int k = 0; k < 4; ++k) {
    const Complex at_base = phi(k, 0.0), at_top = phi(k, H);
    m[0][k] = at_base;
    m[1][k] = beta[k] * lam[k] * at_base;
    m[2][k] = beta[k] * at_top;
    m[3][k] = E * lam[k] * at_top;
  }
  m[0][4] = 0.0;
  m[1][4] = 0.0;
  m[2][4] = 0.0;
  m[3][4] = -qhat;
  for (int col = 0; col < 4; ++col) {  // Gaussian elimination, partial pivoting
    int piv = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::abs(m[r][col]) > std::abs(m[piv][col])) piv = r;
    for (int k = 0; k < 5; ++k) std::swap(m[col][k], m[piv][k]);
    for (int r = 0; r < 4; ++r) {
      if (r == col) continue;
      const Complex f = m[r][col] / m[col][col];
      for (int k = col; k < 5; ++k) m[r][k] -= f * m[col][k];
    }
  }
  Complex sig = 0.0, p = 0.0;
  for (int k = 0; k < 4; ++k) {
    const Complex coef = m[k][4] / m[k][k];
    const Complex ph = phi(k, x);
    sig += coef * E * lam[k] * ph;
    p += coef * beta[k] * ph;
  }
  return {sig, p};
}

/// The exact sigma' and p at `depths` (from the top) at each of `times`
/// for the load q0 ramped over `ramp` seconds, rows as reference().
inline std::vector<std::vector<double>> exact(const Column& c, double q0, double ramp,
                                              const std::vector<double>& times,
                                              const std::vector<double>& depths, int M = 120) {
  std::vector<std::vector<double>> out;
  for (double t : times) {
    std::vector<double> row;
    for (double z : depths)
      for (int f = 0; f < 2; ++f) {
        if (t <= 0.0) {
          row.push_back(0.0);
          continue;
        }
        const auto fhat = [&](Complex s) {
          const Complex qhat = q0 * (1.0 - std::exp(-s * ramp)) / (ramp * s * s);
          return transformed(c, s, qhat, c.H - z)[f];
        };
        row.push_back(de_hoog(fhat, t, 2.0 * t, M, 1e-9 * q0));
      }
    out.push_back(std::move(row));
  }
  return out;
}

}  // namespace column_waves
