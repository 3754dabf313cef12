// materials/mohr_coulomb.hpp — the Mohr-Coulomb soil model (internal): its
// constants, derived once per material, and its return mapping.
//
// Perfectly plastic, linear yield planes in principal stress space, so the
// return is closed form: no iteration, no allocation, no virtual call and no
// exception, which is what a per-particle, per-step routine must be.
// Closed-form 3x3 spectral decomposition; non-associated flow with
// dilatancy psi, a tension cut-off on the major principal stress, and
// returns to the main plane, to the triaxial compression and extension edges
// and to the apex, chosen by the closed-form region tests of the multi-plane
// algorithm (Clausen, Damkilde & Andersen 2006/2007; derived here, not
// copied). Dilatancy angles are clamped into [0, phi]: psi > phi is
// unphysical and psi < 0 (contractive flow) is not supported by the region
// tests. Conventions: see elastic.hpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "elastic.hpp"
#include "hmpm/problem.hpp"

namespace hmpm::constitutive {

/// A linear yield plane in ordered principal stress space:
/// f = normal . s - offset, plastic flow along `flow` (dg/ds).
struct PrincipalPlane {
  Eigen::Vector3d normal;
  Eigen::Vector3d flow;
  double offset;
};

/// Mohr-Coulomb constants, computed once per material by make_mohr_coulomb.
/// In ordered principal stresses (s1 >= s2 >= s3, compression negative):
///   f  = (1 + sin phi) s1 - (1 - sin phi) s3 - 2 c cos phi
///   g  = (1 + sin psi) s1 - (1 - sin psi) s3
///   ft = s1 - tension_cutoff
struct MohrCoulombConstants {
  double sin_phi = 0.0;
  double cos_phi = 1.0;
  double sin_psi = 0.0;                                   ///< of the clamped dilatancy angle
  double cohesion = 0.0;                                  ///< c, Pa
  double apex = std::numeric_limits<double>::infinity();  ///< c cot phi, Pa; +inf when phi = 0
  double tension_cutoff = 0.0;  ///< sigma_t = min(max(tensile_strength, 0), c cot phi), Pa
  /// The planes a return can activate, in this order: the main plane F1
  /// (s1, s3); F2 (s2, s3), which meets F1 on the triaxial compression edge
  /// s1 = s2; F3 (s1, s2), which meets F1 on the triaxial extension edge
  /// s2 = s3; then the cut-off planes s1, s2, s3 <= sigma_t (associated).
  std::array<PrincipalPlane, 6> planes;

  // Strain softening (MohrCoulomb::softening): c, phi and psi go from the
  // peak values above to the residual ones as X = X_r + (X_p - X_r)
  // exp(-shape_factor kappa), kappa the particle's accumulated equivalent
  // plastic strain under this material (its one state variable). softened()
  // makes the constants at a kappa from these.
  bool softens = false;
  double friction = 0.0;          ///< phi, radians (the peak)
  double dilatancy = 0.0;         ///< psi, radians, clamped into [0, phi] (the peak)
  double tensile_strength = 0.0;  ///< as given (>= 0); the cut-off is min(it, apex)
  double residual_cohesion = 0.0;
  double residual_friction = 0.0;   ///< radians
  double residual_dilatancy = 0.0;  ///< radians, clamped into [0, residual phi]
  double shape_factor = 0.0;        ///< eta, regularised for the cell size where asked
};

namespace detail {

/// The planes a principal return ended on (for its tangent): `count` of
/// them, indices into MohrCoulombConstants::planes; count = 0 when the trial
/// was kept, `fixed` when the result is a point that does not move with the
/// trial (the apex, a cut-off corner, the cut-off apex).
struct ActiveSet {
  int count = 0;
  std::array<int, 3> planes{};
  bool fixed = false;
};

/// Closed-form Mohr-Coulomb return in ordered principal stresses (s1 >= s2 >= s3).
/// `trial` must violate f or the cut-off. Returns the principal stresses on
/// or inside the yield surface; `tol` (Pa) absorbs rounding in region tests.
/// `active`, when given, receives the planes the result lies on (the stress
/// itself does not depend on it).
Eigen::Vector3d mohr_coulomb_principal(const Eigen::Vector3d& trial, const Elastic& el,
                                       const MohrCoulombConstants& mc, double tol,
                                       ActiveSet* active = nullptr);

/// A cheap sufficient test that `stress` lies inside the yield surface and
/// the cut-off (from p and J2 alone, no eigen decomposition).
bool surely_elastic(const Voigt& stress, const MohrCoulombConstants& mc);

/// `stress` = the tensor of principal values r (descending) on the trial's
/// eigenvectors v (columns, ascending eigenvalues); a hydrostatic r exactly.
void rotate_back(const Eigen::Vector3d& r, const Eigen::Matrix3d& v, Voigt& stress);

}  // namespace detail

/// Precomputes the Mohr-Coulomb constants of `m` (angles in degrees, c and
/// tensile_strength in Pa). The dilatancy angle is clamped into [0, phi]; the
/// cut-off is sigma_t = min(max(tensile_strength, 0), c cot phi), so the
/// default tensile_strength = 0 means "no tension" (and sigma_t is the apex
/// when c = 0). phi = 0 gives Tresca with no apex.
/// The constants of angles phi, psi (radians; psi already within [0, phi]),
/// cohesion c and tensile strength (>= 0), without softening.
inline MohrCoulombConstants mohr_coulomb_constants(double phi, double psi, double cohesion,
                                                   double tensile_strength) {
  MohrCoulombConstants c;
  c.friction = phi;
  c.dilatancy = psi;
  c.sin_phi = std::sin(phi);
  c.cos_phi = std::cos(phi);
  c.sin_psi = std::sin(psi);
  c.cohesion = std::max(cohesion, 0.0);
  c.tensile_strength = std::max(tensile_strength, 0.0);
  c.apex = c.sin_phi > 0.0 ? c.cohesion * c.cos_phi / c.sin_phi
                           : std::numeric_limits<double>::infinity();
  c.tension_cutoff = std::min(c.tensile_strength, c.apex);
  const double sp = c.sin_phi, ss = c.sin_psi, k = 2.0 * c.cohesion * c.cos_phi;
  c.planes[0] = {{1 + sp, 0, -(1 - sp)}, {1 + ss, 0, -(1 - ss)}, k};
  c.planes[1] = {{0, 1 + sp, -(1 - sp)}, {0, 1 + ss, -(1 - ss)}, k};
  c.planes[2] = {{1 + sp, -(1 - sp), 0}, {1 + ss, -(1 - ss), 0}, k};
  for (int i = 0; i < 3; ++i) {
    c.planes[3 + i].normal = Eigen::Vector3d::Unit(i);
    c.planes[3 + i].flow = Eigen::Vector3d::Unit(i);
    c.planes[3 + i].offset = c.tension_cutoff;
  }
  return c;
}

/// The constants of a softening material at softening strain kappa >= 0
/// (peak.softens; the peak itself at kappa = 0, the residual as kappa grows).
/// The tension cut-off stays the given tensile strength, at most the
/// softened apex c cot phi.
inline MohrCoulombConstants softened(const MohrCoulombConstants& peak, double kappa) {
  if (!(kappa > 0.0)) return peak;
  const double w = std::isinf(kappa) ? 0.0 : std::exp(-peak.shape_factor * kappa);
  const auto mix = [w](double p, double r) { return r + (p - r) * w; };
  MohrCoulombConstants c = mohr_coulomb_constants(
      mix(peak.friction, peak.residual_friction), mix(peak.dilatancy, peak.residual_dilatancy),
      mix(peak.cohesion, peak.residual_cohesion), peak.tensile_strength);
  c.softens = true;
  c.residual_cohesion = peak.residual_cohesion;
  c.residual_friction = peak.residual_friction;
  c.residual_dilatancy = peak.residual_dilatancy;
  c.shape_factor = peak.shape_factor;
  return c;
}

inline MohrCoulombConstants make_mohr_coulomb(const hmpm::MohrCoulomb& m) {
  // The angle as given, in [0, 90] (the job spec refuses 90 and above; 89
  // was the clamp once). Up to 89.999 degrees the return lands on the
  // surface to rounding, except the Mohr-Coulomb corner of the main plane
  // and a cut-off below the apex, nearly parallel there: |f| up to 2e-5 of
  // the trial (tests/solver/test_constitutive.cpp, steep angles).
  const double phi = std::clamp(m.friction_angle_deg, 0.0, 90.0) * detail::deg_to_rad;
  const double psi =
      std::clamp(m.dilatancy_angle_deg, 0.0, phi / detail::deg_to_rad) * detail::deg_to_rad;
  MohrCoulombConstants c = mohr_coulomb_constants(phi, psi, m.cohesion, m.tensile_strength);
  if (m.softening) {
    const hmpm::MohrCoulomb::Softening& s = *m.softening;
    c.softens = true;
    c.residual_cohesion = std::max(s.residual_cohesion, 0.0);
    const double phi_r = std::clamp(s.residual_friction_angle_deg, 0.0, 90.0);
    c.residual_friction = phi_r * detail::deg_to_rad;
    c.residual_dilatancy =
        std::clamp(s.residual_dilatancy_angle_deg, 0.0, phi_r) * detail::deg_to_rad;
    c.shape_factor = std::max(s.shape_factor, 0.0);
  }
  return c;
}

/// Mohr-Coulomb return mapping. `stress` holds the elastic trial stress
/// (Voigt, Pa, compression negative) on entry and the returned stress on
/// exit; `el` is the elasticity that made the trial. Elastic trials are
/// detected from p and J2 alone when possible, then from the principal
/// stresses, and are left bitwise untouched. A plastic trial is decomposed
/// (closed-form 3x3 eigen solver), returned in principal space and rotated
/// back with the same eigenvectors (a hydrostatic result is set exactly).
/// Returns ||d eps_p|| >= 0 (0 if elastic). Never throws, never allocates.
/// Defined in mohr_coulomb.cpp, like the rest of the return (compiled once,
/// not in every unit that includes this header).
double return_mohr_coulomb(Voigt& stress, const Elastic& el, const MohrCoulombConstants& mc);

/// Mohr-Coulomb return with its algorithmic tangent. `stress` is the trial
/// stress on entry and the returned stress on exit, bit for bit what
/// return_mohr_coulomb gives (it does the return); `d_alg` receives
/// d sigma_{n+1} / d eps_{n+1} (elastic.hpp's convention) of the map
/// eps_{n+1} -> return(sigma_n + D_e (eps_{n+1} - eps_n)). Analytical: the
/// returned stress is the isotropic tensor function sigma = sum_a r_a(t) e_a
/// e_a^T of the trial (t its eigenvalues, e_a its eigenvectors), so
/// (de Souza Neto, Peric & Owen, ch. 8 and appendix A) in the trial's
/// eigenbasis d sigma_aa = sum_b (dr_a/dt_b) d sigma_tr,bb and
/// d sigma_ab = theta_ab d sigma_tr,ab for a != b, with
/// theta_ab = (r_a - r_b)/(t_a - t_b) (0 where the return ties r_a = r_b:
/// an edge, the apex), or its limit dr_a/dt_a - dr_a/dt_b when t_a = t_b; then
/// D_alg = (d sigma / d sigma_tr) D_e. dr/dt is the exact derivative of the
/// closed-form return onto the active planes (principal_return_jacobian):
/// the main plane, an edge (two planes), the apex and the cut-off corners
/// (fixed points: dr/dt = 0, only the rotation terms theta remain), the
/// cut-off planes. Returns ||d eps_p|| as return_mohr_coulomb does.
double return_mohr_coulomb_with_tangent(Voigt& stress, const Elastic& el,
                                        const MohrCoulombConstants& mc, Tangent& d_alg);

/// Strain-softening Mohr-Coulomb return: `peak` softens (peak.softens),
/// `kappa` is the particle's softening strain at the step's start on entry
/// and at its end on exit. Implicit in kappa: the returned stress lies on
/// the yield surface of softened(peak, kappa_{n+1}), with
/// kappa_{n+1} = kappa_n + sqrt(2/3) ||d eps_p|| (a scalar equation solved
/// by a bracketed secant iteration around the closed-form return; the
/// trial's eigen decomposition is done once). `d_alg`, when given, receives
/// the algorithmic tangent including kappa's dependence on the strain:
/// D = D_kappa + (d sigma/d kappa) (x) (d kappa/d eps), d kappa/d eps =
/// (d g/d eps) / (1 - d g/d kappa), g the step's softening strain at fixed
/// kappa (d/d kappa by central differences of the principal return, d/d eps
/// from D_kappa, the tangent at fixed kappa). Returns ||d eps_p||.
double return_mohr_coulomb_softening(Voigt& stress, const Elastic& el,
                                     const MohrCoulombConstants& peak, double& kappa,
                                     Tangent* d_alg);

/// The model as the stress update sees it: its constants, its return
/// mapping and the number of per-particle internal state variables it keeps
/// (ParticleState::internal). Perfectly plastic: none; with softening one,
/// the softening strain kappa (slot 0).
struct MohrCoulombModel {
  using Constants = MohrCoulombConstants;
  static constexpr int state_variables = 0;
  static constexpr int softening_state_variables = 1;
  static constexpr int softening_slot = 0;
  static inline void return_stress(Voigt& sig, const Elastic& el, const Constants& c) {
    return_mohr_coulomb(sig, el, c);
  }
};

}  // namespace hmpm::constitutive
