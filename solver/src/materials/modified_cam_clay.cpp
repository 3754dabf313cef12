// materials/modified_cam_clay.cpp — the Modified Cam-Clay stress update and
// its algorithmic tangent (contracts and equations in modified_cam_clay.hpp).
#include "modified_cam_clay.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace hmpm::constitutive {

ModifiedCamClayConstants make_modified_cam_clay(const hmpm::ModifiedCamClay& m, double poisson) {
  ModifiedCamClayConstants c;
  c.lambda = m.lambda;
  c.kappa = m.kappa;
  c.m2 = m.critical_state_ratio * m.critical_state_ratio;
  const double nu = std::clamp(poisson, -0.99, 0.4999);
  c.shear_factor = 3.0 * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu));
  c.initial_void_ratio = m.initial_void_ratio;
  c.overconsolidation_ratio = m.overconsolidation_ratio;
  c.from_ocr = !m.preconsolidation_pressure;
  c.preconsolidation_pressure = 0.0;
  return c;
}

void cam_clay_start_state(const ModifiedCamClayConstants& c, double p, double& e, double& pc) {
  if (!(e > 0.0)) e = c.initial_void_ratio;
  if (!(pc > 0.0))
    pc = c.from_ocr ? c.overconsolidation_ratio * std::max(p, mean_stress_floor)
                    : c.preconsolidation_pressure;
  pc = std::max(pc, mean_stress_floor);
}

namespace {

/// The step's fixed quantities: the start state and the trial.
struct Step {
  double kb, tb;      ///< kappa / v, (lambda - kappa) / v
  double g;           ///< shear modulus of the step
  double a;           ///< 6 G / M^2
  double m2;          ///< M^2
  double p_tr, q_tr;  ///< trial p, q
  double pc_n;        ///< p'c at n
};

/// Solves x = dphi (2 p(x) - pc(x)) for x = deps_v^p with p(x) = p_tr
/// exp(-x/kb), pc(x) = pc_n exp(x/tb): g(x) increasing, the root bracketed
/// by [-dphi pc_n, 0] or [0, 2 dphi p_tr]; Newton kept in the bracket.
double volumetric_root(const Step& s, double dphi, double x0) {
  const double g0 = -dphi * (2.0 * s.p_tr - s.pc_n);
  double lo = g0 > 0.0 ? -dphi * s.pc_n : 0.0;
  double hi = g0 > 0.0 ? 0.0 : 2.0 * dphi * s.p_tr;
  if (g0 == 0.0) return 0.0;
  double x = std::clamp(x0, lo, hi);
  for (int it = 0; it < 100; ++it) {
    const double p = s.p_tr * std::exp(-x / s.kb), pc = s.pc_n * std::exp(x / s.tb);
    const double g = x - dphi * (2.0 * p - pc);
    if (g == 0.0) break;
    if (g > 0.0)
      hi = x;
    else
      lo = x;
    const double dg = 1.0 + dphi * (2.0 * p / s.kb + pc / s.tb);
    double next = x - g / dg;
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - x);
    x = next;
    // A step of a few ulps: converged (a 1e-16 bound would wait for
    // the bracket to close at round-off, up to the loop's 100 turns).
    if (step <= 1e-15 * std::abs(x) || hi - lo <= 1e-15 * std::abs(x)) break;
  }
  return x;
}

/// The end-of-step state for dphi: x, p, q, pc and the yield function.
struct EndState {
  double x, p, q_ratio, pc, f;
};

EndState end_state(const Step& s, double dphi, double x0) {
  EndState r;
  r.x = volumetric_root(s, dphi, x0);
  r.p = s.p_tr * std::exp(-r.x / s.kb);
  r.pc = s.pc_n * std::exp(r.x / s.tb);
  r.q_ratio = 1.0 / (1.0 + s.a * dphi);
  const double q = r.q_ratio * s.q_tr;
  r.f = q * q / s.m2 + r.p * (r.p - r.pc);
  return r;
}

/// d f / d dphi at an end state (x following dphi).
double yield_slope(const Step& s, double dphi, const EndState& r) {
  const double q = r.q_ratio * s.q_tr;
  const double dg = 1.0 + dphi * (2.0 * r.p / s.kb + r.pc / s.tb);
  const double dx = (2.0 * r.p - r.pc) / dg;
  const double dp = -r.p / s.kb * dx, dpc = r.pc / s.tb * dx;
  const double dq = -q * s.a * r.q_ratio;
  return 2.0 * q / s.m2 * dq + (2.0 * r.p - r.pc) * dp - r.p * dpc;
}

/// The deviatoric projector P and 1 in elastic.hpp's convention.
Tangent deviatoric_projector() {
  Tangent proj = Tangent::Identity();
  proj.topLeftCorner<3, 3>().array() -= 1.0 / 3.0;
  return proj;
}

}  // namespace

double update_modified_cam_clay(Voigt& stress, const Voigt& de, const ModifiedCamClayConstants& c,
                                double& e, double& pc, Tangent* d_alg) {
  const double p_raw = -(stress(0) + stress(1) + stress(2)) / 3.0;
  const double p_n = std::max(p_raw, mean_stress_floor);
  cam_clay_start_state(c, p_n, e, pc);
  const double v = 1.0 + e;
  Step s{};
  s.kb = c.kappa / v;
  s.tb = (c.lambda - c.kappa) / v;
  s.g = cam_clay_step_shear_modulus(c, stress, e);
  s.m2 = c.m2;
  s.a = 6.0 * s.g / c.m2;
  s.pc_n = pc;
  const double dev = -(de(0) + de(1) + de(2));
  s.p_tr = p_n * std::exp(dev / s.kb);
  // Trial deviator s_n + 2G dev(de), tensor components.
  Voigt sd = stress;
  const double mean = (stress(0) + stress(1) + stress(2)) / 3.0, de_mean = -dev / 3.0;
  for (int i = 0; i < 3; ++i) sd(i) = stress(i) - mean + 2.0 * s.g * (de(i) - de_mean);
  for (int i = 3; i < 6; ++i) sd(i) = stress(i) + 2.0 * s.g * de(i);
  const double ss = sd.head<3>().squaredNorm() + 2.0 * sd.tail<3>().squaredNorm();
  s.q_tr = std::sqrt(1.5 * ss);
  const double f_tr = s.q_tr * s.q_tr / c.m2 + s.p_tr * (s.p_tr - pc);
  e = std::max(e - v * dev, void_ratio_floor);
  if (f_tr <= 1e-14 * pc * pc) {
    stress = sd;
    stress.head<3>().array() -= s.p_tr;
    if (d_alg) {
      *d_alg = 2.0 * s.g * deviatoric_projector();
      d_alg->topLeftCorner<3, 3>().array() += s.p_tr / s.kb;
    }
    return 0.0;
  }
  // Bracket dphi: f(0) = f_tr > 0; f(dphi) < 0 for dphi large enough.
  double lo = 0.0, hi = 1.0 / (s.a + pc / s.kb);
  EndState r = end_state(s, hi, 0.0);
  for (int it = 0; it < 200 && r.f > 0.0; ++it) {
    lo = hi;
    hi *= 4.0;
    r = end_state(s, hi, r.x);
  }
  // Safeguarded Newton from dphi = 0.
  double dphi = 0.0;
  r = end_state(s, dphi, 0.0);
  r.f = f_tr;
  const double f_tol = 1e-15 * pc * pc;
  for (int it = 0; it < 200; ++it) {
    const double slope = yield_slope(s, dphi, r);
    double next = slope < 0.0 ? dphi - r.f / slope : 0.5 * (lo + hi);
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);
    const double step = std::abs(next - dphi);
    dphi = next;
    r = end_state(s, dphi, r.x);
    if (r.f == 0.0) break;
    if (r.f > 0.0)
      lo = dphi;
    else
      hi = dphi;
    if (std::abs(r.f) <= f_tol || step <= 1e-16 * dphi || hi - lo <= 1e-16 * dphi) break;
  }
  const double p = r.p, ratio = r.q_ratio, q = ratio * s.q_tr;
  stress = ratio * sd;
  stress.head<3>().array() -= p;
  pc = r.pc;
  if (d_alg) {
    // Implicit differentiation of R1 = x - dphi (2p - pc), R2 = f in
    // (x, dphi), with d p_tr / d eps = -(p_tr/kb) 1 and
    // d q_tr / d eps = (3G/q_tr) s~ (s~: the trial deviator, shears doubled).
    const double j11 = 1.0 + dphi * (2.0 * p / s.kb + pc / s.tb), j12 = -(2.0 * p - pc);
    const double j21 = -(2.0 * p - pc) * p / s.kb - p * pc / s.tb;
    const double j22 = -2.0 * q * q * s.a * ratio / c.m2;
    const double det = j11 * j22 - j12 * j21;
    Voigt one = Voigt::Zero(), st = sd;
    one.head<3>().setOnes();
    st.tail<3>() *= 2.0;
    // dR/deps = [b1; b2] (-(p_tr/kb) 1^T) + [0; 6G ratio^2 / M^2] s~^T.
    const double b1 = -dphi * 2.0 * p / s.kb, b2 = (2.0 * p - pc) * p / s.kb;  // times -1^T
    const double c2 = 6.0 * s.g * ratio * ratio / c.m2;
    // [dx; ddphi] = -J^-1 dR/deps; dR/deps = -[b1; b2] 1^T + [0; c2] s~^T.
    const Voigt r1 = -b1 * one, r2 = -b2 * one + c2 * st;
    const Voigt dx = -(j22 * r1 - j12 * r2) / det;
    const Voigt ddphi = -(-j21 * r1 + j11 * r2) / det;
    const Voigt dp = -(p / s.kb) * (one + dx);
    *d_alg = (2.0 * s.g * ratio) * deviatoric_projector() - one * dp.transpose() -
             (s.a * ratio * ratio) * sd * ddphi.transpose();
  }
  const double dev_p = 3.0 * 0.816496580927726 * dphi * q / c.m2;  // ||dev deps_p||
  const double plastic = std::sqrt(r.x * r.x / 3.0 + dev_p * dev_p);
  return plastic > 0.0 ? plastic : 1e-300;
}

}  // namespace hmpm::constitutive
