// materials/drucker_prager.hpp — the Drucker-Prager soil model (internal):
// its constants, derived once per material, and its return mapping.
//
// Perfectly plastic, works with (p, sqrt(J2)): return to the cone, to the
// tension cut-off on the mean stress, or to the corner/apex where the two
// meet. Closed form, no spectral decomposition, no iteration, no
// allocation. Dilatancy clamped into [0, phi]. Conventions: see elastic.hpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "elastic.hpp"
#include "hmpm/problem.hpp"

namespace hmpm::constitutive {

/// Drucker-Prager constants, computed once per material by make_drucker_prager.
/// With p = tr(sigma)/3 (negative in compression) and J2 = s:s/2:
///   f  = sqrt(J2) + alpha p - k          (alpha >= 0: compression strengthens)
///   g  = sqrt(J2) + alpha_psi p
///   ft = p - mean_tension_cutoff
struct DruckerPragerConstants {
  double alpha = 0.0;
  double k = 0.0;  ///< Pa
  double alpha_psi = 0.0;
  double mean_tension_cutoff = 0.0;  ///< p_t = min(max(tensile_strength, 0), k/alpha), Pa
};

/// Precomputes the Drucker-Prager constants of `m` (angles in degrees, Pa).
/// Plane-strain match to Mohr-Coulomb (the classical fit, exact for
/// associated flow in plane strain at the limit state, d eps_zz^p = 0):
///   alpha = 3 tan phi / sqrt(9 + 12 tan^2 phi),  k = 3 c / sqrt(9 + 12 tan^2 phi),
///   alpha_psi = the same expression in psi (clamped into [0, phi]).
/// The mean-stress cut-off is p_t = min(max(tensile_strength, 0), k/alpha).
inline DruckerPragerConstants make_drucker_prager(const hmpm::DruckerPrager& m) {
  DruckerPragerConstants c;
  // The angle as given, in [0, 90] (the job spec refuses 90 and above; 89
  // was the clamp once): alpha and k stay well-conditioned up to 90.
  const double phi = std::clamp(m.friction_angle_deg, 0.0, 90.0) * detail::deg_to_rad;
  const double psi =
      std::clamp(m.dilatancy_angle_deg, 0.0, phi / detail::deg_to_rad) * detail::deg_to_rad;
  const double tp = std::tan(phi), ts = std::tan(psi);
  const double root = std::sqrt(9.0 + 12.0 * tp * tp);
  c.alpha = 3.0 * tp / root;
  c.k = 3.0 * std::max(m.cohesion, 0.0) / root;
  c.alpha_psi = 3.0 * ts / std::sqrt(9.0 + 12.0 * ts * ts);
  const double apex = c.alpha > 0.0 ? c.k / c.alpha : std::numeric_limits<double>::infinity();
  c.mean_tension_cutoff = std::min(std::max(m.tensile_strength, 0.0), apex);
  return c;
}

/// Drucker-Prager return mapping. `stress` holds the elastic trial stress
/// (Voigt, Pa, compression negative) on entry and the returned stress on
/// exit. In (p, sqrt(J2)) the return is: to the cone along
/// (K alpha_psi, G) when that lands at p <= p_t with sqrt(J2) >= 0; else to
/// the cut-off p = p_t with the deviator kept, if that is inside the cone;
/// else to the corner p = p_t, sqrt(J2) = k - alpha p_t (the apex when
/// p_t = k/alpha). The deviator keeps its direction throughout. Elastic
/// trials are left bitwise untouched. Returns ||d eps_p|| >= 0 (0 if elastic).
/// Kept out of line (noinline): inlined into the stress phase, its cheap
/// elastic test would be fused with the phase's arithmetic (FMA
/// contraction), which changes the rounding of every plastic run and buys
/// nothing measurable.
[[gnu::noinline]] inline double return_drucker_prager(Voigt& stress, const Elastic& el,
                                                      const DruckerPragerConstants& dp) {
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

/// The model as the stress update sees it (see MohrCoulombModel).
struct DruckerPragerModel {
  using Constants = DruckerPragerConstants;
  static constexpr int state_variables = 0;
  static inline void return_stress(Voigt& sig, const Elastic& el, const Constants& c) {
    return_drucker_prager(sig, el, c);
  }
};

}  // namespace hmpm::constitutive
