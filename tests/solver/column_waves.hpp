// column_waves.hpp — a converged reference for waves in a saturated column
// (verification §5, Verruijt): the 1D u-p equations solved by a staggered
// finite-difference scheme on a fine grid (a test helper, not solver code).
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
#include <cmath>
#include <functional>
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
/// order: out[t][2 d] = sigma', out[t][2 d + 1] = p.
inline std::vector<std::vector<double>> reference(const Column& c,
                                                  const std::function<double(double)>& load,
                                                  int cells, const std::vector<double>& times,
                                                  const std::vector<double>& depths) {
  const int n = cells;
  const double h = c.H / n, rho = c.rho();
  const double dt = 0.25 * std::min(h / c.fast_speed(), c.storage * h * h / (2 * c.kappa));
  std::vector<double> v(n + 1, 0.0), a(n + 1, 0.0), w(n + 1, 0.0), s(n, 0.0), p(n, 0.0);
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

}  // namespace column_waves
