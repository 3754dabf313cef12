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
#include <cstdint>
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
/// Defined in drucker_prager.cpp with the region test and the tangent.
double return_drucker_prager(Voigt& stress, const Elastic& el, const DruckerPragerConstants& dp);

/// Where a Drucker-Prager return lands (the tests of return_drucker_prager).
enum class DruckerPragerRegion : std::uint8_t { elastic, cone, cut_off, corner, apex };

/// The region return_drucker_prager takes for the trial stress `stress`:
/// the same tests in the same arithmetic, so the two always agree.
DruckerPragerRegion drucker_prager_region(const Voigt& stress, const Elastic& el,
                                          const DruckerPragerConstants& dp);

/// Drucker-Prager return with its algorithmic tangent. `stress` is the
/// trial stress on entry and the returned stress on exit, bit for bit what
/// return_drucker_prager gives (it does the return); `d_alg` receives
/// d sigma_{n+1} / d eps_{n+1} (elastic.hpp's convention) of the map
/// eps_{n+1} -> return(sigma_n + D_e (eps_{n+1} - eps_n)). Closed form, with
/// p, q = sqrt(J2), s the trial deviator, 1 = (1,1,1,0,0,0), P the deviatoric
/// projector (diag 1 on the shears) and m = (s_xx, s_yy, s_zz, 2 s_xy, 2 s_yz,
/// 2 s_zx)/q, so that dq = G m . d eps and dp = K 1 . d eps:
///  * elastic: D_e;
///  * cone: sigma = p' 1 + (q'/q) s with dl = f/h, h = G + K alpha alpha_psi,
///    p' = p - K alpha_psi dl, q' = q - G dl; differentiating,
///      D = 1 (x) dp' + (q'/q) 2G P + s (x) (dq' - (q'/q) G m)/q,
///      df = G m + alpha K 1, dp' = K 1 - K alpha_psi df/h, dq' = G m - G df/h
///    (symmetric for associated flow, alpha_psi = alpha);
///  * cut-off (p' = p_t, deviator kept): D = 2G P, no volumetric stiffness;
///  * corner (p' = p_t, q' = k - alpha p_t fixed): D = (q'/q) 2G (P - s (x) m/(2q)),
///    the derivative of a radial return to a fixed radius: stiffness only
///    tangential to the deviatoric circle;
///  * apex (the stress is the fixed point p_t 1): D = 0, no stiffness at all.
/// Returns ||d eps_p|| as return_drucker_prager does.
double return_drucker_prager_with_tangent(Voigt& stress, const Elastic& el,
                                          const DruckerPragerConstants& dp, Tangent& d_alg);

/// The model as the stress update sees it (see MohrCoulombModel).
struct DruckerPragerModel {
  using Constants = DruckerPragerConstants;
  static constexpr int state_variables = 0;
  static inline void return_stress(Voigt& sig, const Elastic& el, const Constants& c) {
    return_drucker_prager(sig, el, c);
  }
};

}  // namespace hmpm::constitutive
