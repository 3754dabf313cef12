// materials/mohr_coulomb.cpp — the Mohr-Coulomb return mapping and its
// algorithmic tangent (materials/mohr_coulomb.hpp has the model, its
// constants and the contracts). Out of line so that the Eigen solvers it
// uses are compiled once, not in every unit of the solver.
#include "mohr_coulomb.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>
#include <type_traits>

namespace hmpm::constitutive {

namespace detail {
namespace {

/// Solves the closed-form return onto the intersection of the M planes in
/// `active`: s = trial - sum_j dl_j D b_j with f_i(s) = 0 for every active i.
/// Returns false when the planes are (numerically) dependent. dl receives the
/// multipliers.
template <int M>
bool solve_active(const std::array<int, M>& active, const Eigen::Vector3d& trial, const Elastic& el,
                  const std::array<PrincipalPlane, 6>& planes, Eigen::Vector3d& out,
                  Eigen::Matrix<double, M, 1>& dl) {
  Eigen::Matrix<double, M, M> a;
  Eigen::Matrix<double, M, 1> rhs;
  Eigen::Matrix<double, 3, M> corrector;
  for (int j = 0; j < M; ++j) corrector.col(j) = stiffness_times(el, planes[active[j]].flow);
  for (int i = 0; i < M; ++i) {
    const PrincipalPlane& pl = planes[active[i]];
    rhs(i) = pl.normal.dot(trial) - pl.offset;
    for (int j = 0; j < M; ++j) a(i, j) = pl.normal.dot(corrector.col(j));
  }
  const double scale = a.cwiseAbs().maxCoeff();
  const double det = a.determinant();
  if (!(std::abs(det) > 1e-12 * std::pow(scale, M))) return false;
  dl = a.inverse() * rhs;
  out = trial - corrector * dl;
  return true;
}

/// Energy distance (trial - s) : C^-1 : (trial - s) in principal space.
inline double energy_distance(const Elastic& el, const Eigen::Vector3d& trial,
                              const Eigen::Vector3d& s) {
  const Eigen::Vector3d d = trial - s;
  return d.dot(compliance_times(el, d));
}

}  // namespace

Eigen::Vector3d mohr_coulomb_principal(const Eigen::Vector3d& trial, const Elastic& el,
                                       const MohrCoulombConstants& mc, double tol,
                                       ActiveSet* active) {
  const auto record = [active](const auto& set, bool fixed) {
    if (active == nullptr) return;
    active->count = static_cast<int>(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) active->planes[i] = set[i];
    active->fixed = fixed;
  };
  const auto& pl = mc.planes;
  const auto f_main = [&](const Eigen::Vector3d& s) { return pl[0].normal.dot(s) - pl[0].offset; };
  const auto ordered = [&](const Eigen::Vector3d& s) {
    return s(0) >= s(1) - tol && s(1) >= s(2) - tol;
  };
  const double dl_tol = -tol / (2.0 * el.shear);  // multipliers are strains: f / stiffness

  // Stage 1: Mohr-Coulomb alone (main plane, edges, apex).
  Eigen::Vector3d mc_stress = trial;
  bool found = f_main(trial) <= tol;  // only the cut-off is violated
  record(std::array<int, 0>{}, false);
  if (!found) {
    Eigen::Vector3d plane;
    Eigen::Matrix<double, 1, 1> dl1;
    solve_active<1>({0}, trial, el, pl, plane, dl1);  // always solvable: a.Db > 0
    if (ordered(plane)) {
      mc_stress = plane;
      found = true;
      record(std::array{0}, false);
    }
    Eigen::Matrix<double, 2, 1> dl2;
    Eigen::Vector3d edge;
    // Plane return overshooting s1 >= s2: triaxial compression edge s1 = s2.
    if (!found && plane(0) < plane(1) && solve_active<2>({0, 1}, trial, el, pl, edge, dl2) &&
        dl2.minCoeff() >= dl_tol && edge(1) >= edge(2) - tol) {
      mc_stress = edge;
      found = true;
      record(std::array{0, 1}, false);
    }
    // Plane return overshooting s2 >= s3: triaxial extension edge s2 = s3.
    if (!found && plane(1) < plane(2) && solve_active<2>({0, 2}, trial, el, pl, edge, dl2) &&
        dl2.minCoeff() >= dl_tol && edge(0) >= edge(1) - tol) {
      mc_stress = edge;
      found = true;
      record(std::array{0, 2}, false);
    }
    if (!found) {
      if (std::isfinite(mc.apex)) {
        // Beyond both edges' apex planes: the apex. No multiplier test here:
        // with psi < phi the flow cone of the sextant's three planes does not
        // contain the hydrostatic axis, yet the apex is the return there.
        mc_stress = Eigen::Vector3d::Constant(mc.apex);
        record(std::array<int, 0>{}, true);
      } else {
        // Tresca (no apex): only rounding can get here; take whichever edge
        // return is admissible and nearer in the energy norm.
        double best = std::numeric_limits<double>::infinity();
        for (int partner = 1; partner <= 2; ++partner) {
          if (!solve_active<2>({0, partner}, trial, el, pl, edge, dl2) || !ordered(edge)) continue;
          const double d = energy_distance(el, trial, edge);
          if (d < best) best = d, mc_stress = edge, record(std::array{0, partner}, false);
        }
        if (!std::isfinite(best)) mc_stress = plane, record(std::array{0}, false);
      }
    }
  }
  if (mc_stress(0) <= mc.tension_cutoff + tol) return mc_stress;

  // Stage 2: the cut-off is active (only when sigma_t < c cot phi). Try the
  // active sets that contain s1 <= sigma_t, from planes to corners; accept
  // the first with non-negative multipliers whose stress is admissible. If
  // non-associated flow leaves a gap, take the nearest admissible candidate
  // in the energy norm (the cut-off apex (sigma_t, sigma_t, sigma_t) always is).
  const auto admissible = [&](const Eigen::Vector3d& s) {
    return ordered(s) && f_main(s) <= tol && s(0) <= mc.tension_cutoff + tol;
  };
  Eigen::Vector3d best_stress = Eigen::Vector3d::Constant(mc.tension_cutoff);
  double best = energy_distance(el, trial, best_stress);
  ActiveSet best_set;
  best_set.fixed = true;
  Eigen::Vector3d s;
  const auto attempt = [&](const auto& set) {
    constexpr int m = static_cast<int>(std::tuple_size_v<std::decay_t<decltype(set)>>);
    Eigen::Matrix<double, m, 1> dl;
    if (!solve_active<m>(set, trial, el, pl, s, dl) || !admissible(s)) return false;
    if (dl.minCoeff() >= dl_tol) {
      record(set, m == 3);
      return true;
    }
    const double d = energy_distance(el, trial, s);
    if (d < best) {
      best = d, best_stress = s;
      if (active != nullptr) {
        best_set.count = m;
        for (int i = 0; i < m; ++i) best_set.planes[i] = set[i];
        best_set.fixed = m == 3;
      }
    }
    return false;
  };
  if (attempt(std::array{3}) || attempt(std::array{0, 3}) || attempt(std::array{3, 4})) return s;
  // Corner on the extension edge: s1 = sigma_t, s2 = s3 on F1.
  if (attempt(std::array{0, 2, 3})) return s;
  // Corner on the compression edge: s1 = s2 = sigma_t, s3 on F1. Four planes
  // meet there; its flow cone is the union of the cones of any three.
  if (attempt(std::array{0, 3, 4}) || attempt(std::array{1, 3, 4}) ||
      attempt(std::array{0, 1, 3}) || attempt(std::array{0, 1, 4})) {
    return s;
  }
  if (attempt(std::array{3, 4, 5})) return Eigen::Vector3d::Constant(mc.tension_cutoff);  // exact
  if (active != nullptr) *active = best_set;
  return best_stress;
}

namespace {

/// d r / d t of the principal return onto the planes of `active` (ordered
/// principal stresses, descending): with N and B the active planes' normals
/// and flows and D the principal stiffness, r = t - D B A^-1 (N^T t - c),
/// A = N^T D B, so dr/dt = I - D B A^-1 N^T; I when nothing was active, 0
/// when the result is a fixed point (or three independent planes meet).
Eigen::Matrix3d principal_return_jacobian(const ActiveSet& active, const Elastic& el,
                                          const MohrCoulombConstants& mc) {
  if (active.fixed || active.count >= 3) return Eigen::Matrix3d::Zero();
  if (active.count == 0) return Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 2> n = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> db = Eigen::Matrix<double, 3, 2>::Zero();
  for (int j = 0; j < active.count; ++j) {
    const PrincipalPlane& pl = mc.planes[active.planes[j]];
    n.col(j) = pl.normal;
    db.col(j) = stiffness_times(el, pl.flow);
  }
  if (active.count == 1)
    return Eigen::Matrix3d::Identity() - db.col(0) * n.col(0).transpose() / n.col(0).dot(db.col(0));
  const Eigen::Matrix2d a = n.transpose() * db;
  return Eigen::Matrix3d::Identity() - db * a.inverse() * n.transpose();
}

}  // namespace

}  // namespace detail

namespace detail {

bool surely_elastic(const Voigt& stress, const MohrCoulombConstants& mc) {
  // With s the deviator, s1 - s3 <= 2 sqrt(J2), s1 + s3 = 2p - s2 <=
  // 2p + sqrt(J2/3) and s1 <= p + 2 sqrt(J2/3).
  const double p = (stress(0) + stress(1) + stress(2)) / 3.0;
  const double dx = stress(0) - p, dy = stress(1) - p, dz = stress(2) - p;
  const double j2 = 0.5 * (dx * dx + dy * dy + dz * dz) + stress(3) * stress(3) +
                    stress(4) * stress(4) + stress(5) * stress(5);
  const double q = std::sqrt(j2), q3 = std::sqrt(j2 / 3.0);
  const double two_c_cos = 2.0 * mc.cohesion * mc.cos_phi;
  return 2.0 * q + mc.sin_phi * (2.0 * p + q3) - two_c_cos <= 0.0 &&
         p + 2.0 * q3 <= mc.tension_cutoff;
}

void rotate_back(const Eigen::Vector3d& r, const Eigen::Matrix3d& v, Voigt& stress) {
  if (r(0) == r(1) && r(1) == r(2)) {
    stress << r(0), r(0), r(0), 0.0, 0.0, 0.0;
    return;
  }
  const Eigen::Matrix3d m = v * Eigen::Vector3d(r(2), r(1), r(0)).asDiagonal() * v.transpose();
  stress << m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(0, 1) + m(1, 0)), 0.5 * (m(1, 2) + m(2, 1)),
      0.5 * (m(0, 2) + m(2, 0));
}

}  // namespace detail

double return_mohr_coulomb(Voigt& stress, const Elastic& el, const MohrCoulombConstants& mc) {
  if (detail::surely_elastic(stress, mc)) return 0.0;  // cheap test first

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(detail::to_tensor(stress));
  const Eigen::Vector3d& ev = eig.eigenvalues();     // ascending
  const Eigen::Vector3d trial(ev(2), ev(1), ev(0));  // s1 >= s2 >= s3
  const double f = mc.planes[0].normal.dot(trial) - mc.planes[0].offset;
  if (f <= 0.0 && trial(0) <= mc.tension_cutoff) return 0.0;

  const double scale = trial.cwiseAbs().maxCoeff() + mc.cohesion;
  const Eigen::Vector3d r = detail::mohr_coulomb_principal(trial, el, mc, 1e-13 * scale);

  detail::rotate_back(r, eig.eigenvectors(), stress);
  return detail::compliance_times(el, trial - r).norm();
}

double return_mohr_coulomb_with_tangent(Voigt& stress, const Elastic& el,
                                        const MohrCoulombConstants& mc, Tangent& d_alg) {
  const Voigt trial_stress = stress;
  const double plastic = return_mohr_coulomb(stress, el, mc);
  d_alg = elastic_tangent(el);
  if (plastic == 0.0) return 0.0;

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(detail::to_tensor(trial_stress));
  const Eigen::Vector3d& ev = eig.eigenvalues();     // ascending
  const Eigen::Vector3d trial(ev(2), ev(1), ev(0));  // s1 >= s2 >= s3
  const double scale = trial.cwiseAbs().maxCoeff() + mc.cohesion;
  detail::ActiveSet active;
  const Eigen::Vector3d r = detail::mohr_coulomb_principal(trial, el, mc, 1e-13 * scale, &active);
  const Eigen::Matrix3d jac_desc = detail::principal_return_jacobian(active, el, mc);

  // Ascending order (the eigen solver's): index a here is 2 - a above.
  Eigen::Matrix3d jac, theta = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y;
  for (int a = 0; a < 3; ++a) {
    y(a) = r(2 - a);
    for (int b = 0; b < 3; ++b) jac(a, b) = jac_desc(2 - a, 2 - b);
  }
  // Trial values closer than this are tied: the quotient's rounding (a few
  // ulp of the scale in y(a) - y(b) where the return ties them, on an edge)
  // would dominate it, so the limit is used instead (exact for this
  // piecewise affine return; 0 on an edge, 1 between the two free values of
  // a cut-off plane).
  const double tie = 1e-10 * scale;
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      if (a == b) continue;
      const double dx = ev(a) - ev(b);
      theta(a, b) = std::abs(dx) > tie ? (y(a) - y(b)) / dx : jac(a, a) - jac(a, b);
    }
  }
  // d sigma / d sigma_tr, column by column: a unit change of the trial's
  // Voigt component j (shears change both off-diagonal entries).
  const Eigen::Matrix3d& v = eig.eigenvectors();
  static constexpr int row[6] = {0, 1, 2, 0, 1, 0}, col[6] = {0, 1, 2, 1, 2, 2};
  Tangent dsig = Tangent::Zero();
  for (int j = 0; j < 6; ++j) {
    Eigen::Matrix3d dx = Eigen::Matrix3d::Zero();
    dx(row[j], col[j]) = 1.0;
    dx(col[j], row[j]) = 1.0;
    const Eigen::Matrix3d dxp = v.transpose() * dx * v;
    Eigen::Matrix3d dyp = theta.cwiseProduct(dxp);
    dyp.diagonal() = jac * dxp.diagonal();
    const Eigen::Matrix3d dy = v * dyp * v.transpose();
    for (int i = 0; i < 6; ++i) dsig(i, j) = dy(row[i], col[i]);
  }
  d_alg = dsig * d_alg;
  return plastic;
}

}  // namespace hmpm::constitutive

namespace hmpm::constitutive {

double return_mohr_coulomb_softening(Voigt& stress, const Elastic& el,
                                     const MohrCoulombConstants& peak, double& kappa,
                                     Tangent* d_alg) {
  const double kappa_n = std::max(kappa, 0.0);
  const MohrCoulombConstants start = softened(peak, kappa_n);
  const Voigt trial_stress = stress;
  const auto elastic = [&]() {
    if (d_alg != nullptr) *d_alg = elastic_tangent(el);
    return 0.0;
  };
  if (detail::surely_elastic(stress, start)) return elastic();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(detail::to_tensor(trial_stress));
  const Eigen::Vector3d& ev = eig.eigenvalues();     // ascending
  const Eigen::Vector3d trial(ev(2), ev(1), ev(0));  // s1 >= s2 >= s3
  const auto inside = [&](const MohrCoulombConstants& c) {
    return c.planes[0].normal.dot(trial) - c.planes[0].offset <= 0.0 &&
           trial(0) <= c.tension_cutoff;
  };
  if (inside(start)) return elastic();  // elastic at the step's start strength
  const double tol = 1e-13 * (trial.cwiseAbs().maxCoeff() + peak.cohesion);
  constexpr double root_two_thirds = 0.816496580927726;
  // The principal return with constants c, and its softening strain.
  const auto principal_with = [&](const MohrCoulombConstants& c, Eigen::Vector3d& r) {
    if (inside(c)) {
      r = trial;
      return 0.0;
    }
    r = detail::mohr_coulomb_principal(trial, el, c, tol);
    return root_two_thirds * detail::compliance_times(el, trial - r).norm();
  };
  const auto principal = [&](double k, Eigen::Vector3d& r) {
    return principal_with(softened(peak, k), r);
  };
  // F(k) = k - kappa_n - g(k), g growing with k (the soil softens), so
  // F(kappa_n) = -g_start < 0 and, the step's start strength giving the
  // least g, F(kappa_n + g_start) <= 0. Secant steps from these two (F is
  // smooth and, without a snap-back at the point, increasing: 2-4 steps
  // reach the tolerance); should one leave the bracket or stall, a
  // bracketed Illinois iteration up to the residual's g (F >= 0 there).
  Eigen::Vector3d r;
  const double g_start = principal_with(start, r);
  // kappa to 1e-12 / eta: the strength then to 1e-12 of its drop.
  const double k_tol =
      std::max(1e-12 / std::max(peak.shape_factor, 1e-300), 1e-15 * (kappa_n + g_start));
  double k_prev = kappa_n, f_prev = -g_start;
  double k = kappa_n + g_start;
  double fk = g_start - principal(k, r);
  double lo = k, f_lo = fk;
  bool converged = !(fk < -k_tol);
  for (int it = 0; it < 8 && !converged; ++it) {
    const double next = k - fk * (k - k_prev) / (fk - f_prev);
    if (!(next > lo) || !std::isfinite(next)) break;
    k_prev = k, f_prev = fk;
    k = next;
    fk = k - kappa_n - principal(k, r);
    if (fk < 0.0 && k > lo) lo = k, f_lo = fk;
    converged = std::abs(fk) <= k_tol;
  }
  if (!converged) {
    double hi = kappa_n + principal(std::numeric_limits<double>::infinity(), r);
    double f_hi = hi - kappa_n - principal(hi, r);
    k = hi;
    // Illinois (regula falsi that halves the stale end's weight).
    int side = 0;
    for (int it = 0; it < 100 && f_hi > 0.0 && hi - lo > k_tol; ++it) {
      k = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
      if (!(k > lo && k < hi)) k = 0.5 * (lo + hi);
      fk = k - kappa_n - principal(k, r);
      if (fk == 0.0) break;
      if (fk < 0.0) {
        lo = k, f_lo = fk;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = k, f_hi = fk;
        if (side == 1) f_lo *= 0.5;
        side = 1;
      }
    }
  }
  kappa = kappa_n + principal(k, r);
  // The stress at kappa_{n+1}'s constants, rotated back with the trial's
  // eigenvectors (the same code in both paths, so they agree bit for bit).
  const MohrCoulombConstants end = softened(peak, kappa);
  const double plastic = principal_with(end, r) / root_two_thirds;
  if (d_alg == nullptr) {
    detail::rotate_back(r, eig.eigenvectors(), stress);
    return plastic;
  }
  // The stress and its tangent at fixed kappa (the same return at `end`).
  Tangent d_kappa;
  stress = trial_stress;
  return_mohr_coulomb_with_tangent(stress, el, end, d_kappa);
  detail::rotate_back(r, eig.eigenvectors(), stress);
  // d sigma / d kappa and d g / d kappa: central differences of the
  // principal return (the trial, hence its eigenvectors, is fixed).
  const double h = 1e-6 * std::max(kappa, 1.0 / std::max(peak.shape_factor, 1e-300));
  Eigen::Vector3d r_plus, r_minus;
  const double g_plus = principal(kappa + h, r_plus);
  const double g_minus = principal(std::max(kappa - h, 0.0), r_minus);
  const double width = kappa + h - std::max(kappa - h, 0.0);
  const double dg_dk = (g_plus - g_minus) / width;
  const Eigen::Vector3d dr_desc = (r_plus - r_minus) / width;
  const Eigen::Matrix3d& v = eig.eigenvectors();
  const Eigen::Matrix3d dm =
      v * Eigen::Vector3d(dr_desc(2), dr_desc(1), dr_desc(0)).asDiagonal() * v.transpose();
  Voigt dsig_dk;
  dsig_dk << dm(0, 0), dm(1, 1), dm(2, 2), dm(0, 1), dm(1, 2), dm(0, 2);
  // d g / d eps: g = sqrt(2/3) |d eps_p|, d eps_p = C (sigma_tr - sigma), so
  // d(d eps_p)/d eps = I - C D_kappa; |.| is the tensor norm (shears twice).
  const Tangent compliance = elastic_tangent(el).inverse();
  const Voigt deps_p = compliance * (trial_stress - stress);
  const double norm =
      std::sqrt(deps_p.head<3>().squaredNorm() + 2.0 * deps_p.tail<3>().squaredNorm());
  Eigen::Matrix<double, 1, 6> dg_de = Eigen::Matrix<double, 1, 6>::Zero();
  if (norm > 0.0) {
    Voigt weighted = deps_p;
    weighted.tail<3>() *= 2.0;
    dg_de = root_two_thirds / norm * weighted.transpose() *
            (Tangent::Identity() - compliance * d_kappa);
  }
  const double denominator = 1.0 - dg_dk;
  *d_alg = d_kappa;
  if (std::abs(denominator) > 1e-12) *d_alg += dsig_dk * (dg_de / denominator);
  return plastic;
}

}  // namespace hmpm::constitutive
