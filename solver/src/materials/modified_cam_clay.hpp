// materials/modified_cam_clay.hpp — the Modified Cam-Clay soil model
// (internal): its constants, derived once per material, and its stress
// update with state (void ratio e, preconsolidation pressure p'c).
//
// Conventions inside the model: p = -tr(sigma)/3 (compression positive),
// q = sqrt(3/2 s:s), eps_v = -tr(eps) (compaction positive); the stress in
// and out is elastic.hpp's (Voigt, compression negative, tensor shear
// strains). With v = 1 + e_n fixed over the step:
//   yield       f = q^2/M^2 + p (p - p'c)
//   elasticity  p = p_n exp(v deps_v^e / kappa)   (exact on the e - ln p
//               unloading-reloading line), s = s_n + 2G dev(deps^e) with
//               G = 3 (1 - 2 nu) / (2 (1 + nu)) K_n, K_n = v p_n / kappa
//   flow        deps^p = dphi df/dsigma (associated)
//   hardening   p'c = p'c_n exp(v deps_v^p / (lambda - kappa))
//   void ratio  e = e_n - v deps_v
// so that e + lambda ln p is kept exactly along the NCL (p = p'c on the
// isotropic axis) and e + kappa ln p along an unloading-reloading line, for
// any step size. The return is implicit (backward Euler at p, q, p'c of
// the step's end): a scalar equation in dphi (safeguarded Newton inside a
// bracket) whose every evaluation solves the volumetric equation
// x = dphi (2p - p'c), x = deps_v^p, for x (monotone: safeguarded Newton).
//
// The elastic trial is the model's own (pressure-dependent bulk modulus):
// the update takes sigma_n and the strain increment, not the constant-
// elasticity trial the other models start from (material.hpp's dispatch).
//
// Zero and tensile mean stress: p_n below p_min = mean_stress_floor (100 Pa)
// is taken as p_min at the start of a step (the exponential law keeps p > 0
// afterwards), and p'c as at least p_min, so a body starting unstressed
// (sigma = 0) gets a tiny stiffness instead of none and nothing divides by
// zero. The void ratio is kept at least void_ratio_floor.
//
// State slots (InternalState, material.hpp): 0 the void ratio, 1 p'c (Pa).
// A slot at 0 is "not initialised": the update then starts from e0 and
// from p'c = OCR p_n (or the material's constant p'c); set-up initialises
// every particle of the material (initialise_cam_clay_state) so outputs
// have the values from the start.
#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "elastic.hpp"
#include "hmpm/problem.hpp"

namespace hmpm::constitutive {

/// Modified Cam-Clay constants, computed once per material.
struct ModifiedCamClayConstants {
  double lambda = 0.1;
  double kappa = 0.03;
  double m2 = 1.44;                      ///< M^2
  double shear_factor = 0.6;             ///< G / K = 3 (1 - 2 nu) / (2 (1 + nu))
  double initial_void_ratio = 1.0;       ///< e0
  double overconsolidation_ratio = 1.0;  ///< used when p'c is not given
  /// The material's p'c when given as one number, Pa; 0 when it is a field
  /// of position (set-up writes each particle's) or from the OCR.
  double preconsolidation_pressure = 0.0;
  bool from_ocr = true;  ///< p'c = OCR times the initial mean effective stress
};

/// Mean effective stresses below this (Pa, compression positive) are taken
/// as this at the start of a step (zero and tensile mean stress).
inline constexpr double mean_stress_floor = 100.0;
/// The smallest void ratio the update keeps.
inline constexpr double void_ratio_floor = 1e-3;

ModifiedCamClayConstants make_modified_cam_clay(const hmpm::ModifiedCamClay& m, double poisson);

/// The particle's state at the start of a step: e and p'c from the slots,
/// or their initial values when a slot is not initialised (0), from the
/// mean effective stress p (compression positive) of its stress.
void cam_clay_start_state(const ModifiedCamClayConstants& c, double p, double& e, double& pc);

/// The shear modulus a step from `stress` (sigma_n) with void ratio e (0:
/// not initialised, e0) uses: G = shear_factor (1 + e) max(p'_n, floor) /
/// kappa, fixed over the step. The deviatoric trial is s_n + 2G de, so the
/// sensitivity of the updated stress to a deviatoric change ds of sigma_n
/// is d_alg ds / (2G) (the quasi-static scheme's spin term).
inline double cam_clay_step_shear_modulus(const ModifiedCamClayConstants& c, const Voigt& stress,
                                          double e) {
  const double p_n = std::max(-(stress(0) + stress(1) + stress(2)) / 3.0, mean_stress_floor);
  const double v = 1.0 + (e > 0.0 ? e : c.initial_void_ratio);
  return c.shear_factor * v * p_n / c.kappa;
}

/// One stress update. `stress` holds sigma_n (Voigt, Pa, compression
/// negative; already rotated) on entry and sigma_{n+1} on exit; `de` is the
/// strain increment (tensor components); `e` and `pc` hold the state at n
/// on entry (0: not initialised, see above) and at n+1 on exit. With
/// `d_alg`, also d sigma_{n+1} / d eps_{n+1} (elastic.hpp's convention; the
/// pressure-dependent elastic tangent on elastic steps). Returns
/// ||d eps_p|| (Frobenius), 0 when the step was elastic. No allocation.
double update_modified_cam_clay(Voigt& stress, const Voigt& de, const ModifiedCamClayConstants& c,
                                double& e, double& pc, Tangent* d_alg);

/// The model as the stress update sees it (see MohrCoulombModel).
struct ModifiedCamClayModel {
  using Constants = ModifiedCamClayConstants;
  static constexpr int state_variables = 2;
  static constexpr int void_ratio_slot = 0;
  static constexpr int preconsolidation_slot = 1;
};

}  // namespace hmpm::constitutive
