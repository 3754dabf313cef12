// materials/drucker_prager.cpp — the Drucker-Prager return mapping, its
// region test and its algorithmic tangent (contracts in drucker_prager.hpp),
// compiled once rather than in every unit of the solver.
#include "drucker_prager.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace hmpm::constitutive {

double return_drucker_prager(Voigt& stress, const Elastic& el, const DruckerPragerConstants& dp) {
  const double p = (stress(0) + stress(1) + stress(2)) / 3.0;
  const double dx = stress(0) - p, dy = stress(1) - p, dz = stress(2) - p;
  const double q = std::sqrt(0.5 * (dx * dx + dy * dy + dz * dz) + stress(3) * stress(3) +
                             stress(4) * stress(4) + stress(5) * stress(5));
  const double f = q + dp.alpha * p - dp.k;
  const double pt = dp.mean_tension_cutoff;
  if (f <= 0.0 && p <= pt) return 0.0;

  const double g = el.shear, bulk = el.lambda + 2.0 * g / 3.0;
  const double tol = 1e-13 * (std::abs(p) + q + dp.k);
  double p_new = pt, q_new = q;
  bool done = false;
  if (f > 0.0) {  // cone
    const double dl = f / (g + bulk * dp.alpha * dp.alpha_psi);
    const double qc = q - g * dl, pc = p - bulk * dp.alpha_psi * dl;
    if (qc >= 0.0 && pc <= pt + tol) {
      p_new = pc;
      q_new = qc;
      done = true;
    }
  }
  if (!done && !(p > pt && q + dp.alpha * pt - dp.k <= 0.0)) {
    q_new = std::max(dp.k - dp.alpha * pt, 0.0);  // corner / apex
  }
  const double ratio = q > 0.0 ? q_new / q : 0.0;
  if (q_new == 0.0) {
    stress << p_new, p_new, p_new, 0.0, 0.0, 0.0;  // apex: exactly hydrostatic
  } else if (q_new == q) {
    stress.head<3>().array() += p_new - p;  // cut-off: deviator untouched
  } else {
    stress.head<3>() << p_new + ratio * dx, p_new + ratio * dy, p_new + ratio * dz;
    stress.tail<3>() *= ratio;
  }
  const double dq = q - q_new, dpm = p - p_new;
  // ||d eps_p||^2 = ||ds||^2/(4G^2) + 3 (dp/(3K))^2, with ||ds|| = sqrt(2) dq.
  return std::sqrt(dq * dq / (2.0 * g * g) + dpm * dpm / (3.0 * bulk * bulk));
}

DruckerPragerRegion drucker_prager_region(const Voigt& stress, const Elastic& el,
                                          const DruckerPragerConstants& dp) {
  const double p = (stress(0) + stress(1) + stress(2)) / 3.0;
  const double dx = stress(0) - p, dy = stress(1) - p, dz = stress(2) - p;
  const double q = std::sqrt(0.5 * (dx * dx + dy * dy + dz * dz) + stress(3) * stress(3) +
                             stress(4) * stress(4) + stress(5) * stress(5));
  const double f = q + dp.alpha * p - dp.k;
  const double pt = dp.mean_tension_cutoff;
  if (f <= 0.0 && p <= pt) return DruckerPragerRegion::elastic;
  const double g = el.shear, bulk = el.lambda + 2.0 * g / 3.0;
  const double tol = 1e-13 * (std::abs(p) + q + dp.k);
  if (f > 0.0) {
    const double dl = f / (g + bulk * dp.alpha * dp.alpha_psi);
    const double qc = q - g * dl, pc = p - bulk * dp.alpha_psi * dl;
    if (qc >= 0.0 && pc <= pt + tol)
      return qc == 0.0 ? DruckerPragerRegion::apex : DruckerPragerRegion::cone;
  }
  if (p > pt && q + dp.alpha * pt - dp.k <= 0.0)
    return q == 0.0 ? DruckerPragerRegion::apex : DruckerPragerRegion::cut_off;
  return std::max(dp.k - dp.alpha * pt, 0.0) == 0.0 ? DruckerPragerRegion::apex
                                                    : DruckerPragerRegion::corner;
}

double return_drucker_prager_with_tangent(Voigt& stress, const Elastic& el,
                                          const DruckerPragerConstants& dp, Tangent& d_alg) {
  const Voigt trial = stress;
  const DruckerPragerRegion region = drucker_prager_region(trial, el, dp);
  const double plastic = return_drucker_prager(stress, el, dp);
  const double g = el.shear, bulk = el.lambda + 2.0 * g / 3.0;
  const double p = (trial(0) + trial(1) + trial(2)) / 3.0;
  Voigt s = trial, one = Voigt::Zero();
  s.head<3>().array() -= p;
  one.head<3>().setOnes();
  Tangent proj = Tangent::Identity();  // deviatoric projector P
  proj.topLeftCorner<3, 3>().array() -= 1.0 / 3.0;
  const double q = std::sqrt(0.5 * s.head<3>().squaredNorm() + s.tail<3>().squaredNorm());
  Voigt m = s;
  if (q > 0.0) {
    m.tail<3>() *= 2.0;
    m /= q;
  }
  switch (region) {
    case DruckerPragerRegion::elastic:
      d_alg = elastic_tangent(el);
      break;
    case DruckerPragerRegion::cone: {
      const double h = g + bulk * dp.alpha * dp.alpha_psi;
      const double f = q + dp.alpha * p - dp.k;
      const double ratio = (q - g * f / h) / q;
      const Voigt df = g * m + dp.alpha * bulk * one;
      const Voigt dp_new = bulk * one - (bulk * dp.alpha_psi / h) * df;
      const Voigt dq_new = g * m - (g / h) * df;
      d_alg = one * dp_new.transpose() + (ratio * 2.0 * g) * proj +
              s * ((dq_new - ratio * g * m) / q).transpose();
      break;
    }
    case DruckerPragerRegion::cut_off:
      d_alg = 2.0 * g * proj;
      break;
    case DruckerPragerRegion::corner: {
      const double ratio = (dp.k - dp.alpha * dp.mean_tension_cutoff) / q;
      d_alg = (ratio * 2.0 * g) * (proj - s * m.transpose() / (2.0 * q));
      break;
    }
    case DruckerPragerRegion::apex:
      d_alg.setZero();
      break;
  }
  return plastic;
}

}  // namespace hmpm::constitutive
