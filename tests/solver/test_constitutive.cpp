// Stress-point tests of the Mohr-Coulomb and Drucker-Prager return mappings
// (solver/src/materials/mohr_coulomb.hpp, drucker_prager.hpp): elastic
// states untouched, returned stresses on the yield surface, flow along
// D : dg/dsigma, closest point for associated flow, apex and edges, the
// analytical peak of triaxial and plane-strain
// paths, dilatancy and the Tresca limit. The yield functions used to check
// are written here again from the angles (not from the Constants structs),
// and evaluated with Eigen's iterative eigen solver, not the closed-form one
// the solver uses. Compression negative, Pa, Voigt xx yy zz xy yz zx.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "../../solver/src/materials/drucker_prager.hpp"
#include "../../solver/src/materials/mohr_coulomb.hpp"

namespace {

namespace cm = hmpm::constitutive;
using cm::Voigt;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double pi = 3.14159265358979323846;
double rad(double deg) {
  return deg * pi / 180.0;
}

cm::Elastic elastic(double E, double nu) {
  return {E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))};
}

Voigt to_voigt(const Matrix3d& m) {
  Voigt v;
  v << m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(1, 2), m(0, 2);
  return v;
}

Matrix3d to_matrix(const Voigt& v) {
  Matrix3d m;
  m << v(0), v(3), v(5), v(3), v(1), v(4), v(5), v(4), v(2);
  return m;
}

/// Stress with principal values s (any order) along the columns of q.
Voigt from_principal(const Vector3d& s, const Matrix3d& q) {
  return to_voigt(q * s.asDiagonal() * q.transpose());
}

/// Principal stresses, descending (s1 >= s2 >= s3), and their directions.
struct Principal {
  Vector3d values;
  Matrix3d directions;  // column i belongs to values(i)
};
Principal principal(const Voigt& v) {
  Eigen::SelfAdjointEigenSolver<Matrix3d> es(to_matrix(v));  // iterative QL
  Principal p;
  for (int i = 0; i < 3; ++i) {
    p.values(i) = es.eigenvalues()(2 - i);
    p.directions.col(i) = es.eigenvectors().col(2 - i);
  }
  return p;
}

Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

/// sigma = D : eps (tensor components in Voigt).
Voigt stiffness(const cm::Elastic& el, const Voigt& eps) {
  Voigt s = 2 * el.shear * eps;
  s.head<3>().array() += el.lambda * eps.head<3>().sum();
  return s;
}
Voigt compliance(const cm::Elastic& el, const Voigt& s) {
  const double two_g = 2 * el.shear;
  Voigt e = s / two_g;
  e.head<3>().array() -= el.lambda / (two_g * (3 * el.lambda + two_g)) * s.head<3>().sum();
  return e;
}
double contract(const Voigt& a, const Voigt& b) {
  return a.head<3>().dot(b.head<3>()) + 2 * a.tail<3>().dot(b.tail<3>());
}
double energy(const cm::Elastic& el, const Voigt& a, const Voigt& b) {
  return contract(compliance(el, a), b);
}

// ---- independent yield functions --------------------------------------

struct MohrCase {
  double phi, psi, c, tension;  // degrees, degrees, Pa, Pa
  hmpm::MohrCoulomb material() const { return {phi, psi, c, tension}; }
  double cutoff() const { return phi > 0 ? std::min(tension, c / std::tan(rad(phi))) : tension; }
  /// max(Mohr-Coulomb, cut-off) at principal values s (descending).
  double yield(const Vector3d& s) const {
    const double sp = std::sin(rad(phi));
    const double f = (1 + sp) * s(0) - (1 - sp) * s(2) - 2 * c * std::cos(rad(phi));
    return std::max(f, s(0) - cutoff());
  }
  double yield_of(const Voigt& s) const { return yield(principal(s).values); }
  cm::MohrCoulombConstants constants() const { return cm::make_mohr_coulomb(material()); }
  static double apply(Voigt& s, const cm::Elastic& el, const cm::MohrCoulombConstants& k) {
    return cm::return_mohr_coulomb(s, el, k);
  }
};

struct DruckerCase {
  double phi, psi, c, tension;
  hmpm::DruckerPrager material() const { return {phi, psi, c, tension}; }
  double alpha() const {
    const double t = std::tan(rad(phi));
    return 3 * t / std::sqrt(9 + 12 * t * t);
  }
  double k() const {
    const double t = std::tan(rad(phi));
    return 3 * c / std::sqrt(9 + 12 * t * t);
  }
  double cutoff() const { return alpha() > 0 ? std::min(tension, k() / alpha()) : tension; }
  double yield(const Voigt& s) const {
    const double p = s.head<3>().sum() / 3;
    Voigt d = s;
    d.head<3>().array() -= p;
    const double q = std::sqrt(0.5 * contract(d, d));
    return std::max(q + alpha() * p - k(), p - cutoff());
  }
  double yield_of(const Voigt& s) const { return yield(s); }
  cm::DruckerPragerConstants constants() const { return cm::make_drucker_prager(material()); }
  static double apply(Voigt& s, const cm::Elastic& el, const cm::DruckerPragerConstants& k) {
    return cm::return_drucker_prager(s, el, k);
  }
};

const std::vector<MohrCase> mohr_cases = {
    {30, 0, 0, 0},        // cohesionless sand: apex and cut-off at zero stress
    {30, 10, 10e3, 0},    // cohesive, no tension: the cut-off below the apex
    {35, 35, 20e3, 5e3},  // associated, cut-off at 5 kPa
    {20, 5, 5e3, 1e9},    // tensile strength above c cot phi: cut-off at the apex
    {0, 0, 50e3, 1e9},    // Tresca (no apex), cut-off far away
    {0, 0, 50e3, 0},      // Tresca with no tension
};
const std::vector<DruckerCase> drucker_cases = {
    {30, 0, 0, 0}, {30, 10, 10e3, 0}, {35, 35, 20e3, 5e3}, {20, 5, 5e3, 1e9}, {0, 0, 50e3, 1e9}};

/// A random trial: principal values uniform in [-1, 1] x 10^u (u uniform in
/// [3, 7]) Pa, shifted by a random mean, in random directions.
Voigt random_trial(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1), e(3, 7);
  const double scale = std::pow(10.0, e(rng));
  const Vector3d s =
      scale * Vector3d(u(rng), u(rng), u(rng)) + Vector3d::Constant(scale * 2 * u(rng));
  return from_principal(s, random_rotation(rng));
}

double max_abs_principal(const Voigt& v) {
  return principal(v).values.cwiseAbs().maxCoeff();
}

/// One random trial, its magnitude (largest |principal stress|), and what a
/// return function `apply(Voigt&) -> ||d eps_p||` makes of it.
struct Sample {
  Voigt trial, out;
  double scale, dl;
};
template <class Apply>
Sample sample(std::mt19937_64& rng, Apply apply) {
  Sample s;
  s.trial = random_trial(rng);
  s.scale = max_abs_principal(s.trial);
  s.out = s.trial;
  s.dl = apply(s.out);
  return s;
}

// ---- elastic states -----------------------------------------------------

TEST(MohrCoulomb, ElasticStatesAreUntouched) {
  std::mt19937_64 rng(1);
  const cm::Elastic el = elastic(50e6, 0.3);
  std::uniform_real_distribution<double> u(0, 1);
  int checked = 0;
  for (const MohrCase& mc : mohr_cases) {
    const auto k = cm::make_mohr_coulomb(mc.material());
    for (int i = 0; i < 1000; ++i) {
      const double mean = -1e6 * u(rng);
      const Vector3d s = Vector3d::Constant(mean) + 0.5 * mean * Vector3d(u(rng), u(rng), u(rng));
      // Strictly inside by a margin, so that the decision cannot hinge on rounding.
      std::array<double, 3> sorted = {s(0), s(1), s(2)};
      std::sort(sorted.rbegin(), sorted.rend());
      if (mc.yield(Vector3d(sorted[0], sorted[1], sorted[2])) > -1e-6 * std::abs(mean)) continue;
      const Voigt trial = from_principal(s, random_rotation(rng));
      Voigt out = trial;
      EXPECT_EQ(cm::return_mohr_coulomb(out, el, k), 0.0);
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): untouched means the same bits.
      ASSERT_EQ(std::memcmp(out.data(), trial.data(), sizeof(Voigt)), 0);  // bitwise
      ++checked;
    }
  }
  std::printf("Mohr-Coulomb: %d elastic states untouched\n", checked);
  EXPECT_GT(checked, 2000);
}

TEST(DruckerPrager, ElasticStatesAreUntouched) {
  std::mt19937_64 rng(2);
  const cm::Elastic el = elastic(50e6, 0.3);
  int checked = 0;
  for (const DruckerCase& dc : drucker_cases) {
    const auto k = cm::make_drucker_prager(dc.material());
    for (int i = 0; i < 1000; ++i) {
      const Voigt trial = random_trial(rng);
      const double y = dc.yield(trial);
      if (y > -1e-6 * max_abs_principal(trial)) continue;
      Voigt out = trial;
      EXPECT_EQ(cm::return_drucker_prager(out, el, k), 0.0);
      // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): untouched means the same bits.
      ASSERT_EQ(std::memcmp(out.data(), trial.data(), sizeof(Voigt)), 0);
      ++checked;
    }
  }
  std::printf("Drucker-Prager: %d elastic states untouched\n", checked);
  EXPECT_GT(checked, 500);
}

// ---- on the surface -----------------------------------------------------

// After a plastic return, max(f, cut-off) = 0 at the returned stress. The
// residual is rounding in the spectral decomposition, the closed-form solve
// and the rotation back: a few 1e-16 of the trial's magnitude, amplified by
// at most the ratio of stiffness to strength terms (~10); 1e-10 of the trial
// scale leaves room for that and still catches any wrong formula.
constexpr double surface_tol = 1e-10;

template <class Case>
void check_on_surface(const std::vector<Case>& cases, std::uint64_t seed, const char* name,
                      int min_plastic, double tol = surface_tol) {
  std::mt19937_64 rng(seed);
  for (double nu : {0.2, 0.3, 0.45}) {
    const cm::Elastic el = elastic(50e6, nu);
    for (const Case& mat : cases) {
      const auto k = mat.constants();
      double worst = 0;
      int plastic = 0;
      for (int i = 0; i < 1500; ++i) {
        const auto [trial, out, scale, dl] =
            sample(rng, [&](Voigt& s) { return Case::apply(s, el, k); });
        ASSERT_TRUE(out.allFinite());
        const double y = mat.yield_of(out);
        ASSERT_LE(y, tol * scale) << "outside after return";
        if (mat.yield_of(trial) > 1e-6 * scale) {
          ++plastic;
          EXPECT_GT(dl, 0.0);
          worst = std::max(worst, std::abs(y) / scale);
          ASSERT_LE(std::abs(y), tol * scale) << "phi " << mat.phi << " c " << mat.c;
        }
      }
      std::printf("%s phi=%g psi=%g c=%g t=%g nu=%g: %d plastic, max |f|/scale = %.2e\n", name,
                  mat.phi, mat.psi, mat.c, mat.tension, nu, plastic, worst);
      EXPECT_GT(plastic, min_plastic);
    }
  }
}

TEST(MohrCoulomb, ReturnedStressIsOnTheSurface) {
  check_on_surface(mohr_cases, 3, "MC", 500);
}
TEST(DruckerPrager, ReturnedStressIsOnTheSurface) {
  check_on_surface(drucker_cases, 4, "DP", 300);
}

// Friction angles in [89, 90), which the job spec accepts, are used as given
// (the solver clamped them to 89 degrees, which at 89.5 doubles the cohesive
// strength 2 c cos phi): the constants follow the angle and the return lands
// on the yield surface of that angle, cohesive or not, with and without
// dilatancy and tension cut-off. Near 90 degrees the main plane and the
// tension cut-off become nearly parallel and the Mohr-Coulomb return to
// their corner (cut-off below the apex) loses digits: |f| / scale measured
// 3e-10 at 88, 7e-9 at 89, 4e-7 at 89.5 and up to 2e-5 at 89.999 degrees
// (every other case, and Drucker-Prager, stays at rounding). The returned
// stress is admissible to that tolerance, 1e-4: a few Pa in 1e5.
constexpr double steep_surface_tol = 1e-4;
const std::vector<MohrCase> steep_mohr_cases = {
    {89.5, 0, 10e3, 0}, {89.9, 10, 10e3, 1e9}, {89.99, 89.99, 0, 0}, {89.999, 30, 5e3, 0}};
const std::vector<DruckerCase> steep_drucker_cases = {
    {89.5, 0, 10e3, 0}, {89.9, 10, 10e3, 1e9}, {89.99, 89.99, 0, 0}, {89.999, 30, 5e3, 0}};

TEST(MohrCoulomb, FrictionAnglesAbove89DegreesAreHonoured) {
  for (const MohrCase& mat : steep_mohr_cases)
    EXPECT_DOUBLE_EQ(mat.constants().sin_phi, std::sin(rad(mat.phi))) << mat.phi;
  check_on_surface(steep_mohr_cases, 5, "MC", 100, steep_surface_tol);
}
TEST(DruckerPrager, FrictionAnglesAbove89DegreesAreHonoured) {
  for (const DruckerCase& mat : steep_drucker_cases)
    EXPECT_DOUBLE_EQ(mat.constants().alpha, mat.alpha()) << mat.phi;
  check_on_surface(steep_drucker_cases, 6, "DP", 100, steep_surface_tol);
}

// ---- flow direction, dilatancy, closest point ------------------------------

/// Norm of the part of a orthogonal to b, relative to |a| (Euclidean in
/// tensor components).
double off_parallel(const Voigt& a, const Voigt& b) {
  const double bb = contract(b, b);
  const Voigt r = a - contract(a, b) / bb * b;
  return std::sqrt(contract(r, r) / contract(a, a));
}

// On the main plane, sigma_trial - sigma = dl D : dg/dsigma, and with it the
// plastic strain dl dg/dsigma: trace/(e1 - e3) = sin psi (0 for psi = 0,
// dilative for psi > 0). The directions come from a second, independent eigen
// solve; for eigenvalue gaps above 1e-3 of the scale they agree to ~1e-13,
// so 1e-9 is a safe bound for "parallel" and for the dilatancy ratio.
TEST(MohrCoulomb, FlowIsAlongStiffnessTimesPotentialGradientOnThePlane) {
  std::mt19937_64 rng(5);
  const cm::Elastic el = elastic(50e6, 0.3);
  for (double psi : {0.0, 10.0, 30.0}) {
    const MohrCase mc{30, psi, 10e3, 0};
    const auto k = cm::make_mohr_coulomb(mc.material());
    const double ss = std::sin(rad(psi));
    const Vector3d b(1 + ss, 0, -(1 - ss));
    double worst = 0, worst_dilatancy = 0;
    int on_plane = 0;
    for (int i = 0; i < 5000; ++i) {
      const auto [trial, out, scale, dl] =
          sample(rng, [&](Voigt& s) { return cm::return_mohr_coulomb(s, el, k); });
      const Principal r = principal(out);
      const double gap = 1e-3 * scale;
      if (dl == 0 || r.values(0) - r.values(1) < gap || r.values(1) - r.values(2) < gap ||
          r.values(0) > mc.cutoff() - gap) {
        continue;  // not the main plane
      }
      ++on_plane;
      const Voigt dg = from_principal(b, r.directions);
      const Voigt dsigma = trial - out;
      worst = std::max(worst, off_parallel(dsigma, stiffness(el, dg)));
      const Voigt deps = compliance(el, dsigma);
      EXPECT_NEAR(std::sqrt(contract(deps, deps)), dl, 1e-9 * dl);  // the reported norm
      const Vector3d e = principal(deps).values;
      const double volumetric = deps.head<3>().sum();
      worst_dilatancy = std::max(worst_dilatancy, std::abs(volumetric / (e(0) - e(2)) - ss));
      if (psi > 0) {
        EXPECT_GT(volumetric, 0.0);  // dilative: volume grows
      }
    }
    std::printf("MC plane psi=%g: %d cases, max off-parallel %.2e, |tr/(e1-e3) - sin psi| %.2e\n",
                psi, on_plane, worst, worst_dilatancy);
    EXPECT_GT(on_plane, 200);
    EXPECT_LE(worst, 1e-9);
    EXPECT_LE(worst_dilatancy, 1e-9);
  }
}

// On the cone, d eps_p = dl (s/(2 sqrt J2) + alpha_psi/3 I): stress
// correction parallel to D of that, and tr/|dev| = sqrt(2) alpha_psi.
// Everything here is a few flops from the trial; 1e-10 is ample.
TEST(DruckerPrager, FlowIsAlongStiffnessTimesPotentialGradientOnTheCone) {
  std::mt19937_64 rng(6);
  const cm::Elastic el = elastic(50e6, 0.3);
  for (double psi : {0.0, 10.0, 30.0}) {
    const DruckerCase dc{30, psi, 10e3, 0};
    const auto k = cm::make_drucker_prager(dc.material());
    const double ts = std::tan(rad(psi)), alpha_psi = 3 * ts / std::sqrt(9 + 12 * ts * ts);
    double worst = 0, worst_dilatancy = 0;
    int on_cone = 0;
    for (int i = 0; i < 3000; ++i) {
      const Voigt trial = random_trial(rng);
      Voigt out = trial;
      if (cm::return_drucker_prager(out, el, k) == 0) continue;
      const double p = out.head<3>().sum() / 3;
      Voigt s = out;
      s.head<3>().array() -= p;
      const double q = std::sqrt(0.5 * contract(s, s));
      if (q < 1e-3 * max_abs_principal(trial) || p > dc.cutoff() - 1e-6) continue;  // not the cone
      ++on_cone;
      Voigt dg = s / (2 * q);
      dg.head<3>().array() += alpha_psi / 3;
      worst = std::max(worst, off_parallel(trial - out, stiffness(el, dg)));
      const Voigt deps = compliance(el, trial - out);
      Voigt dev = deps;
      dev.head<3>().array() -= deps.head<3>().sum() / 3;
      worst_dilatancy =
          std::max(worst_dilatancy, std::abs(deps.head<3>().sum() / std::sqrt(contract(dev, dev)) -
                                             std::sqrt(2.0) * alpha_psi));
      if (psi > 0) {
        EXPECT_GT(deps.head<3>().sum(), 0.0);
      }
    }
    std::printf("DP cone psi=%g: %d cases, max off-parallel %.2e, dilatancy error %.2e\n", psi,
                on_cone, worst, worst_dilatancy);
    EXPECT_GT(on_cone, 200);
    EXPECT_LE(worst, 1e-10);
    EXPECT_LE(worst_dilatancy, 1e-10);
  }
}

// For psi = phi the return is the projection onto the (convex) elastic
// domain in the energy norm <a, b> = a : C^-1 : b, characterised by
// <trial - sigma, tau - sigma> <= 0 for every admissible tau. The taus are
// the other returned stresses and interior points. Normalised by the two
// norms the left side is a cosine; 1e-9 covers rounding of O(1e-13).
template <class Return, class Admissible>
void check_closest_point(std::mt19937_64& rng, const cm::Elastic& el, Return ret, Admissible inside,
                         const char* name) {
  std::vector<Voigt> trials, returned, taus;
  for (int i = 0; i < 600; ++i) {
    Voigt t = random_trial(rng);
    t *= 1e5 / max_abs_principal(t);  // one scale, so that the taus interleave
    Voigt r = t;
    if (ret(r) > 0) {
      trials.push_back(t);
      returned.push_back(r);
      taus.push_back(r);
    } else {
      taus.push_back(t);
    }
  }
  double worst = -1;
  for (std::size_t i = 0; i < trials.size(); ++i) {
    const Voigt d = trials[i] - returned[i];
    const double nd = std::sqrt(energy(el, d, d));
    for (const Voigt& tau : taus) {
      if (!inside(tau)) continue;
      const Voigt e = tau - returned[i];
      const double ne = std::sqrt(energy(el, e, e));
      // A tau within 1e-9 of the scale is the returned point itself (two
      // returns to the same corner): the cosine of rounding noise means nothing.
      if ((tau - returned[i]).norm() <= 1e-9 * 1e5) continue;
      worst = std::max(worst, energy(el, d, e) / (nd * ne));
    }
  }
  std::printf("%s closest point: %zu returns, max cos(trial-sigma, tau-sigma)_E = %.2e\n", name,
              trials.size(), worst);
  EXPECT_GT(trials.size(), 200u);
  EXPECT_LE(worst, 1e-9);
}

TEST(MohrCoulomb, AssociatedReturnIsTheClosestPointInTheEnergyNorm) {
  std::mt19937_64 rng(7);
  for (const MohrCase mc :
       {MohrCase{35, 35, 20e3, 5e3}, MohrCase{30, 30, 0, 0}, MohrCase{0, 0, 50e3, 20e3}}) {
    const cm::Elastic el = elastic(50e6, 0.3);
    const auto k = cm::make_mohr_coulomb(mc.material());
    check_closest_point(
        rng, el, [&](Voigt& s) { return cm::return_mohr_coulomb(s, el, k); },
        [&](const Voigt& s) { return mc.yield(principal(s).values) <= 1e-9 * 1e5; }, "MC");
  }
}

TEST(DruckerPrager, AssociatedReturnIsTheClosestPointInTheEnergyNorm) {
  std::mt19937_64 rng(8);
  for (const DruckerCase dc : {DruckerCase{35, 35, 20e3, 5e3}, DruckerCase{30, 30, 0, 0}}) {
    const cm::Elastic el = elastic(50e6, 0.3);
    const auto k = cm::make_drucker_prager(dc.material());
    check_closest_point(
        rng, el, [&](Voigt& s) { return cm::return_drucker_prager(s, el, k); },
        [&](const Voigt& s) { return dc.yield(s) <= 1e-9 * 1e5; }, "DP");
  }
}

// ---- apex and edges -----------------------------------------------------

// With c = 0 and psi = 0 every tensile trial (all principal stresses >= 0)
// goes to the apex, which is exactly zero stress: compared bitwise.
TEST(MohrCoulomb, TensileTrialsOfCohesionlessSoilGoToZeroStress) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (double nu : {0.0, 0.3, 0.49}) {
    const cm::Elastic el = elastic(50e6, nu);
    for (double psi : {0.0, 30.0}) {
      const auto k = cm::make_mohr_coulomb({30, psi, 0, 0});
      // Hydrostatic tension: the apex for any psi.
      Voigt h = Voigt::Zero();
      h.head<3>().setConstant(1e4);
      EXPECT_GT(cm::return_mohr_coulomb(h, el, k), 0.0);
      EXPECT_TRUE((h.array() == 0.0).all()) << h.transpose();
      if (psi > 0) continue;
      for (int i = 0; i < 500; ++i) {
        Vector3d s(u(rng), u(rng), u(rng));
        if (i % 3 == 0) s(i % 2 + 1) = 0;  // uniaxial / biaxial tension
        Voigt t = from_principal(1e5 * s, random_rotation(rng));
        cm::return_mohr_coulomb(t, el, k);
        ASSERT_TRUE((t.array() == 0.0).all()) << t.transpose();
      }
    }
  }
}

TEST(DruckerPrager, TensileTrialsOfCohesionlessSoilGoToZeroStress) {
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> u(0, 1);
  const cm::Elastic el = elastic(50e6, 0.3);
  const auto k = cm::make_drucker_prager({30, 0, 0, 0});
  for (int i = 0; i < 500; ++i) {
    Voigt t = from_principal(1e5 * Vector3d(u(rng), u(rng), u(rng)), random_rotation(rng));
    EXPECT_GT(cm::return_drucker_prager(t, el, k), 0.0);
    ASSERT_TRUE((t.array() == 0.0).all()) << t.transpose();
  }
}

// Trials whose plane return would cross s1 = s2 (or s2 = s3) end on the
// triaxial compression (extension) edge: the two equal to rounding (1e-12 of
// the scale; they come from one 2x2 solve) and f = 0.
TEST(MohrCoulomb, TrialsBeyondTheEdgesReturnToTheEdges) {
  const cm::Elastic el = elastic(50e6, 0.3);
  std::mt19937_64 rng(11);
  const MohrCase mc{30, 0, 10e3, 0};
  const auto k = cm::make_mohr_coulomb(mc.material());
  // Compression: s1, s2 close, s3 far more compressive.
  Voigt t = from_principal(Vector3d(-95e3, -100e3, -600e3), random_rotation(rng));
  cm::return_mohr_coulomb(t, el, k);
  Vector3d r = principal(t).values;
  EXPECT_NEAR(r(0), r(1), 1e-12 * 600e3) << r.transpose();
  EXPECT_GT(r(1) - r(2), 1e3);
  EXPECT_NEAR(mc.yield(r), 0.0, 1e-12 * 600e3);
  // Extension: s2, s3 close, s1 far less compressive.
  t = from_principal(Vector3d(-50e3, -595e3, -600e3), random_rotation(rng));
  cm::return_mohr_coulomb(t, el, k);
  r = principal(t).values;
  EXPECT_NEAR(r(1), r(2), 1e-12 * 600e3) << r.transpose();
  EXPECT_GT(r(0) - r(1), 1e3);
  EXPECT_NEAR(mc.yield(r), 0.0, 1e-12 * 600e3);
}

// Tension cut-off below the apex (c = 20 kPa, sigma_t = 5 kPa). A trial
// with s1 in tension and mild compression lands on s1 = sigma_t with the
// associated cut-off flow D e1: s2 and s3 drop by lambda/(lambda + 2G) of
// the s1 correction. With more compression in s3 it lands on the line where
// the cut-off meets the main plane (s1 = sigma_t, f = 0). Hydrostatic
// tension goes to the cut-off apex (sigma_t, sigma_t, sigma_t) exactly.
// 1e-12 of the scale: a closed-form solve and the rotation back.
TEST(MohrCoulomb, TensionCutOffBelowTheApex) {
  const cm::Elastic el = elastic(50e6, 0.3);
  std::mt19937_64 rng(14);
  const MohrCase mc{30, 0, 20e3, 5e3};
  const auto k = cm::make_mohr_coulomb(mc.material());
  const double tol = 1e-12 * 50e3;
  Vector3d s(50e3, -5e3, -10e3);
  Voigt t = from_principal(s, random_rotation(rng));
  EXPECT_GT(cm::return_mohr_coulomb(t, el, k), 0.0);
  Vector3d r = principal(t).values;
  const double drop = (s(0) - 5e3) * el.lambda / (el.lambda + 2 * el.shear);
  EXPECT_NEAR(r(0), 5e3, tol);
  EXPECT_NEAR(r(1), s(1) - drop, tol);
  EXPECT_NEAR(r(2), s(2) - drop, tol);
  const double sp = std::sin(rad(30)), two_c_cos = 2 * 20e3 * std::cos(rad(30));
  EXPECT_LT((1 + sp) * r(0) - (1 - sp) * r(2) - two_c_cos, -1e3);  // the cut-off alone
  s << 50e3, -20e3, -40e3;
  t = from_principal(s, random_rotation(rng));
  cm::return_mohr_coulomb(t, el, k);
  r = principal(t).values;
  EXPECT_NEAR(r(0), 5e3, tol);
  EXPECT_NEAR(r(2), ((1 + sp) * 5e3 - two_c_cos) / (1 - sp), tol);
  Voigt h = Voigt::Zero();
  h.head<3>().setConstant(1e5);
  cm::return_mohr_coulomb(h, el, k);
  EXPECT_TRUE((h.head<3>().array() == 5e3).all() && (h.tail<3>().array() == 0.0).all())
      << h.transpose();
}

// ---- stress paths -------------------------------------------------------

/// Strain-driven path with stress-controlled sides: each step applies the
/// axial increment d_axial (yy) and finds, by secant iteration, the lateral
/// increments for which the controlled sides (xx, and zz unless plane
/// strain) keep sigma = confining after the return. Returns sigma_yy per step.
template <class Return>
std::vector<Voigt> drive(const cm::Elastic& el, Return ret, double confining, double d_axial,
                         int steps, bool plane_strain) {
  Voigt sigma = Voigt::Zero();
  sigma.head<3>().setConstant(confining);
  std::vector<Voigt> path;
  const auto response = [&](double lateral) {
    Voigt deps = Voigt::Zero();
    deps << lateral, d_axial, plane_strain ? 0.0 : lateral, 0, 0, 0;
    Voigt s = sigma + stiffness(el, deps);
    ret(s);
    return s;
  };
  const double k_lat = plane_strain ? el.lambda + 2 * el.shear : 2 * el.lambda + 2 * el.shear;
  double x0 = -el.lambda * d_axial / k_lat;
  for (int n = 0; n < steps; ++n) {
    Voigt s0 = response(x0);
    double r0 = s0(0) - confining;
    double x1 = x0 - r0 / k_lat;
    for (int it = 0; it < 60 && std::abs(r0) > 1e-10 * std::abs(confining); ++it) {
      const Voigt s1 = response(x1);
      const double r1 = s1(0) - confining;
      const double x2 = r1 == r0 ? x1 : x1 - r1 * (x1 - x0) / (r1 - r0);
      x0 = x1, r0 = r1, s0 = s1, x1 = x2;
    }
    EXPECT_LE(std::abs(r0), 1e-10 * std::abs(confining)) << "step " << n;
    sigma = s0;
    path.push_back(sigma);
  }
  return path;
}

// Triaxial compression, confining -100 kPa, c = 10 kPa, phi = 30: the axial
// stress at failure is sigma_c Kp - 2 c sqrt(Kp), Kp = (1 + sin)/(1 - sin)
// (the textbook sigma1 = sigma3 Kp + 2c sqrt(Kp) with compression negative).
// Perfect plasticity: once reached it stays there while loading continues.
// The return is exact on the edge, so the only error is the secant
// tolerance on the sides (1e-10): 1e-9 relative.
TEST(MohrCoulomb, TriaxialCompressionReachesTheAnalyticalPeakAndStaysThere) {
  const cm::Elastic el = elastic(50e6, 0.3);
  const double sc = -100e3, c = 10e3, sp = std::sin(rad(30));
  const double kp = (1 + sp) / (1 - sp), peak = sc * kp - 2 * c * std::sqrt(kp);
  for (double psi : {0.0, 10.0}) {
    const auto k = cm::make_mohr_coulomb({30, psi, c, 0});
    const auto path = drive(
        el, [&](Voigt& s) { return cm::return_mohr_coulomb(s, el, k); }, sc, -2e-5, 600,
        false);  // 1.2 % axial strain
    int on_peak = 0;
    for (const Voigt& s : path) {
      EXPECT_GE(s(1), peak * (1 + 1e-9));  // never beyond the peak
      if (std::abs(s(1) - peak) <= 1e-9 * std::abs(peak)) {
        ++on_peak;
        EXPECT_NEAR(s(2), s(0), 1e-9 * std::abs(sc));  // on the compression edge
      }
    }
    std::printf("MC triaxial psi=%g: peak %.6f kPa (analytical %.6f), %d of %zu steps on it\n", psi,
                path.back()(1) / 1e3, peak / 1e3, on_peak, path.size());
    EXPECT_NEAR(path.back()(1), peak, 1e-9 * std::abs(peak));
    EXPECT_GT(on_peak, 300);  // it stays on the peak for the second half of the path
  }
}

// Drucker-Prager in triaxial compression reaches its own closed form
// sqrt(J2) + alpha p = k with sqrt(J2) = (s_c - s_a)/sqrt(3), p = (s_a + 2 s_c)/3.
TEST(DruckerPrager, TriaxialCompressionReachesItsClosedForm) {
  const cm::Elastic el = elastic(50e6, 0.3);
  const DruckerCase dc{30, 0, 10e3, 0};
  const auto k = cm::make_drucker_prager(dc.material());
  const double sc = -100e3, a = dc.alpha(), r3 = 1 / std::sqrt(3.0);
  const double peak = (dc.k() - sc * (r3 + 2 * a / 3)) / (a / 3 - r3);
  const auto path = drive(
      el, [&](Voigt& s) { return cm::return_drucker_prager(s, el, k); }, sc, -2e-5, 600, false);
  std::printf("DP triaxial: peak %.6f kPa (closed form %.6f)\n", path.back()(1) / 1e3, peak / 1e3);
  EXPECT_NEAR(path.back()(1), peak, 1e-9 * std::abs(peak));
}

// The cone match: in plane strain with associated flow, the limit state of
// Drucker-Prager has d eps_zz^p = 0, and the plane-strain fit makes its
// in-plane principal stresses satisfy Mohr-Coulomb exactly. sigma_zz
// relaxes toward that state exponentially with plastic strain; after 10 %
// axial strain the limit is reached to 1e-6 relative (measured ~1e-12).
TEST(DruckerPrager, AssociatedPlaneStrainLimitMatchesMohrCoulomb) {
  const cm::Elastic el = elastic(50e6, 0.3);
  const double sc = -100e3, c = 10e3, sp = std::sin(rad(30));
  const double kp = (1 + sp) / (1 - sp), peak = sc * kp - 2 * c * std::sqrt(kp);
  const auto k = cm::make_drucker_prager({30, 30, c, 0});
  const auto path = drive(
      el, [&](Voigt& s) { return cm::return_drucker_prager(s, el, k); }, sc, -1e-4, 1000, true);
  std::printf("DP plane strain (associated): limit %.6f kPa, Mohr-Coulomb %.6f kPa\n",
              path.back()(1) / 1e3, peak / 1e3);
  EXPECT_NEAR(path.back()(1), peak, 1e-6 * std::abs(peak));
}

// ---- Tresca limit -------------------------------------------------------

// phi = 0: Mohr-Coulomb is Tresca, (s1 - s3)/2 = c after any plastic return;
// Drucker-Prager is von Mises with sqrt(J2) = k = c. Same 1e-10 as above.
TEST(MohrCoulomb, ZeroFrictionIsTresca) {
  std::mt19937_64 rng(12);
  const cm::Elastic el = elastic(50e6, 0.3);
  const double c = 50e3;
  const auto k = cm::make_mohr_coulomb({0, 0, c, 1e12});
  const auto kd = cm::make_drucker_prager({0, 0, c, 1e12});
  double worst = 0, worst_dp = 0;
  for (int i = 0; i < 2000; ++i) {
    const Voigt trial = random_trial(rng);
    const double scale = max_abs_principal(trial);
    Voigt t = trial;
    if (cm::return_mohr_coulomb(t, el, k) > 0) {
      const Vector3d r = principal(t).values;
      worst = std::max(worst, std::abs((r(0) - r(2)) / 2 - c) / scale);
    }
    t = trial;
    if (cm::return_drucker_prager(t, el, kd) > 0) {
      t.head<3>().array() -= t.head<3>().sum() / 3;
      worst_dp = std::max(worst_dp, std::abs(std::sqrt(0.5 * contract(t, t)) - c) / scale);
    }
  }
  std::printf("Tresca: max |tau_max - c|/scale = %.2e; von Mises: %.2e\n", worst, worst_dp);
  EXPECT_LE(worst, surface_tol);
  EXPECT_LE(worst_dp, surface_tol);
}

// ---- robustness ---------------------------------------------------------

TEST(Constitutive, DegenerateTrialsGiveFiniteAdmissibleStresses) {
  const cm::Elastic el = elastic(50e6, 0.3);
  std::mt19937_64 rng(13);
  std::vector<Voigt> trials;
  trials.push_back(Voigt::Zero());
  for (double p : {-1e5, 1e5, -1e15, 1e15, 1e-300, -1e-300}) {
    Voigt h = Voigt::Zero();
    h.head<3>().setConstant(p);
    trials.push_back(h);
    // repeated eigenvalues, aligned and rotated, and a huge shear
    trials.push_back(from_principal(Vector3d(p, p, -3 * std::abs(p)), Matrix3d::Identity()));
    trials.push_back(
        from_principal(Vector3d(p, -3 * std::abs(p), -3 * std::abs(p)), random_rotation(rng)));
    trials.push_back(from_principal(Vector3d(p, p, p + 1e-9 * std::abs(p)), random_rotation(rng)));
    Voigt s = Voigt::Zero();
    s(3) = p;
    trials.push_back(s);
  }
  for (const Voigt& trial : trials) {
    const double scale = std::max(max_abs_principal(trial), 1e-300);
    for (const MohrCase& mc : mohr_cases) {
      Voigt t = trial;
      const double dl = cm::return_mohr_coulomb(t, el, cm::make_mohr_coulomb(mc.material()));
      ASSERT_TRUE(t.allFinite() && std::isfinite(dl)) << trial.transpose();
      EXPECT_LE(mc.yield(principal(t).values), surface_tol * scale + 1e-9) << trial.transpose();
    }
    for (const DruckerCase& dc : drucker_cases) {
      Voigt t = trial;
      const double dl = cm::return_drucker_prager(t, el, cm::make_drucker_prager(dc.material()));
      ASSERT_TRUE(t.allFinite() && std::isfinite(dl)) << trial.transpose();
      EXPECT_LE(dc.yield(t), surface_tol * scale + 1e-9) << trial.transpose();
    }
  }
}

}  // namespace
