// Mandel's problem (verification §4): a plane-strain specimen of width 2a
// between rigid, smooth, impermeable plates carrying 2F; lateral faces
// drained and traction-free. The pore pressure at the centre first rises
// above its initial value (Mandel-Cryer effect), then decays.
//
// Model: the quarter x in [0, a], y in [0, b] with symmetry planes x = 0
// (u_x = 0) and y = 0 (u_y = 0), both impermeable (no pressure condition is
// the natural no-flux one). The plate is a rigid tie of the top node row
// (Boundary::rigid along y): its nodes share one vertical velocity from
// their summed momenta and forces, so the plate stays flat and carries the
// load F = q a however the soil pushes on it, and it is free to slide along
// x (smooth) and impermeable (no pressure condition). Mandel's solution does
// not depend on b (the vertical strain is uniform), so a thin specimen of a
// few cells suffices. The run starts from the undrained state the load
// creates at t = 0+ (as Terzaghi's test starts from p = q), with p = 0
// prescribed on the drained face.
//
// Local damping: the sudden drop of p on the drained face launches lateral
// waves (±2 % of p0) that Biot damping at k = 5e-5 m/s removes only slowly.
// (With M = E_oed, 0.87 of the limit where the u-p equations with Darcy's
// rho_f a grow, they grew to ±40 % by T = 0.5 while rho_f a used the plain
// nodal acceleration; with the re-mapped one they decay, see
// Mandel.UndampedNearTheDarcyInertiaLimit and docs/verification.md.) A small Cundall
// coefficient removes them: it opposes at most alpha times the unbalanced nodal force, which in a
// quasi-static process is the inertia force, a fraction D (the inertia number) of the load, so it
// biases the solution by at most alpha D. Mandel.DampingDoesNotBiasTheHistory checks that halving
// or doubling it does not change the history.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

struct MandelCase {
  double a = 1.0;  // half width, m
  int cells = 20;  // across a
  int rows = 2;    // cells over the height b
  int ppc = 2;
  // nu = 0 and Biot modulus M = Kf/n equal to the constrained modulus give
  // nu_u = 1/3 and a Mandel-Cryer peak of 9 % at the centre.
  double E = 10e6, nu = 0.0, porosity = 0.3, kf = 3e6, rho_s = 2650, rho_f = 1000;
  double k = 5e-5;        // m/s; sets the inertia number, see below
  double q = 1e4;         // plate stress F / a, Pa
  double damping = 0.02;  // local (Cundall) coefficient, see the file comment
  double gamma_w = 1000.0 * 9.81;

  double h() const { return a / cells; }
  double b() const { return rows * h(); }
  double shear_modulus() const { return E / (2 * (1 + nu)); }
  double lambda() const { return E * nu / ((1 + nu) * (1 - 2 * nu)); }
  double biot_modulus() const { return kf / porosity; }  // incompressible grains: Biot modulus Kf/n
  double oedometric() const { return lambda() + 2 * shear_modulus(); }
  double bulk_modulus() const { return lambda() + 2 * shear_modulus() / 3; }
  double skempton_b() const { return biot_modulus() / (bulk_modulus() + biot_modulus()); }
  double nu_u() const {
    const double ku = bulk_modulus() + biot_modulus();
    return (3 * ku - 2 * shear_modulus()) / (2 * (3 * ku + shear_modulus()));
  }
  double c() const { return k / gamma_w / (1 / biot_modulus() + 1 / oedometric()); }
  double p0() const { return q * skempton_b() * (1 + nu_u()) / 3; }
  double time_of(double T) const { return T * a * a / c(); }
  double rho() const { return (1 - porosity) * rho_s + porosity * rho_f; }
  double c_undrained() const { return std::sqrt((oedometric() + biot_modulus()) / rho()); }
  /// Quasi-static measure: the lateral face moves by about
  /// a q (nu_u - nu) / (2G) over the consolidation, at the rate of a
  /// diffusion front, times the undrained impedance rho c1, over p0 — the
  /// relative size of the pressure waves inertia adds at T (cf. Terzaghi).
  double inertia_number(double T) const {
    const double du = a * q * (nu_u() - nu) / (2 * shear_modulus());
    const double rate = du * std::sqrt(c() / (closed_form::pi * time_of(T))) / a;
    return rho() * c_undrained() * rate / p0();
  }
};

hmpm::Problem mandel(const MandelCase& c, double end) {
  const double h = c.h(), a = c.a, b = c.b();
  hmpm::Problem p;
  p.dimension = 2;
  p.local_damping = problems::constant(c.damping);
  // Room to expand laterally and one empty row above the plate.
  p.grid.max = {a + 2 * h, b + h, 0};
  p.grid.cells = {c.cells + 2, c.rows + 1, 1};
  hmpm::Material m;
  m.name = "soil";
  m.density = c.rho_s;
  m.youngs_modulus = c.E;
  m.poisson_ratio = c.nu;
  m.hydraulic =
      hmpm::Hydraulic{c.porosity, c.k, c.kf, c.rho_f, std::numeric_limits<double>::infinity()};
  p.materials.push_back(m);
  hmpm::Body body;
  body.box.max = {a, b, 0};
  body.particles_per_cell = c.ppc;
  // Undrained state at t = 0+: total stress sigma_xx = 0, sigma_yy = -q,
  // eps_zz = 0 with the undrained modulus lambda_u = lambda + M.
  const double lu = c.lambda() + c.biot_modulus(), G = c.shear_modulus();
  const double e = -c.q / (2 * (lu + G));  // volumetric strain
  const double exx = 0.5 * (e + c.q / (2 * G)), eyy = 0.5 * (e - c.q / (2 * G));
  const double p0 = -c.biot_modulus() * e;
  const double sxx = c.lambda() * e + 2 * G * exx, syy = c.lambda() * e + 2 * G * eyy,
               szz = c.lambda() * e;
  body.initial.pore_pressure = [p0](const hmpm::Vec3&) { return p0; };
  body.initial.effective_stress[0] = [sxx](const hmpm::Vec3&) { return sxx; };
  body.initial.effective_stress[1] = [syy](const hmpm::Vec3&) { return syy; };
  body.initial.effective_stress[2] = [szz](const hmpm::Vec3&) { return szz; };
  p.bodies.push_back(body);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 1, 0.0), 1));
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, a), 0.0));
  hmpm::Boundary plate;
  plate.nodes = problems::plane(p, 1, b);
  plate.rigid[1] = true;
  p.boundaries.push_back(plate);
  hmpm::Traction t;
  t.particles.min = {0, b - h / c.ppc, 0};  // the top row only, at b - h/(2 ppc)
  t.particles.max = {a, b, 0};
  t.axis = 1;
  t.side = +1;
  t.traction[1] = problems::constant(-c.q);
  p.tractions.push_back(t);
  p.time.end = end;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::displacement};
  return p;
}

struct Result {
  double max_error_centre = 0;  // max over the history, / p0
  double max_error_all = 0;     // every particle, / p0
  double peak = 0, peak_exact = 0, exact_p0 = 0;
  std::vector<double> time, centre;  // centre pressure history
  int rows = 0;
};

Result run_mandel(const MandelCase& c, double T_end, int samples) {
  hmpm::Problem p = mandel(c, c.time_of(T_end));
  p.output.series_interval = c.time_of(T_end) / samples;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const closed_form::Mandel exact(c.nu, c.nu_u(), c.a, c.c(), c.p0());
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size();
  Result out;
  out.exact_p0 =
      -c.biot_modulus() * (-c.q / (2 * (c.lambda() + c.biot_modulus() + c.shear_modulus())));
  const double x_centre = s.initial_positions[0][0];  // particle 0: nearest the centre
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    const double t = s.time[row];
    ++out.rows;
    for (std::size_t i = 0; i < np; ++i) {
      const double pe = t > 0 ? exact.pressure(s.initial_positions[i][0], t) : c.p0();
      const double err = std::abs(s.values[0][row * np + i] - pe) / c.p0();
      out.max_error_all = std::max(out.max_error_all, err);
      if (i == 0) {
        out.time.push_back(t);
        out.centre.push_back(s.values[0][row * np + i]);
        out.max_error_centre = std::max(out.max_error_centre, err);
        out.peak = std::max(out.peak, s.values[0][row * np + i]);
        out.peak_exact = std::max(out.peak_exact, pe);
      }
    }
  }
  std::printf(
      "mandel: nu %.2f nu_u %.4f, x_centre %.4g a: max |p - p_exact| / p0 = %.4f at the "
      "centre, %.4f anywhere; peak %.4f p0 (closed form %.4f p0) over %d samples\n",
      c.nu, c.nu_u(), x_centre / c.a, out.max_error_centre, out.max_error_all, out.peak / c.p0(),
      out.peak_exact / c.p0(), out.rows);
  return out;
}

// The checks every case shares (tolerances: see CentrePressureAndMandelCryerPeak).
void expect_within_tolerance(const Result& r, const MandelCase& c) {
  EXPECT_LT(r.max_error_centre, 0.03);
  EXPECT_GT(r.peak - c.p0(), 0.5 * (r.peak_exact - c.p0()));
  EXPECT_NEAR(r.peak, r.peak_exact, 0.03 * c.p0());
}

// Tolerance (task of issue 7): the centre pressure within 3 % of p0 over
// the whole history, T = c t / a^2 in (0, 0.5] (the peak is at T ~ 0.07).
// With 20 cells the boundary layer at the drained face is resolved from
// T ~ 0.005 (sqrt(T) a = 3.5 h), and the centre sees the drained face only
// through the plate, whose load redistribution is exact with the tie. The
// inertia number at T = 0.01 is asserted below 0.5 % (pressure waves of that
// relative size); the rest is spatial error of linear elements (Terzaghi:
// a few 0.1 %). The Mandel-Cryer peak must be present: above p0 by at least
// half the closed-form overshoot, and equal to it within the same 3 %.
TEST(Mandel, CentrePressureAndMandelCryerPeak) {
  const MandelCase c;
  ASSERT_LT(c.inertia_number(0.01), 0.005);
  const Result r = run_mandel(c, 0.5, 100);
  // The initial state is the undrained one: p0 from the moduli equals
  // Mandel's F B (1 + nu_u) / (3a).
  EXPECT_NEAR(r.exact_p0, c.p0(), 1e-12 * c.p0());
  expect_within_tolerance(r, c);
}

// Variant: nu = 0.2, a stiffer fluid (nu_u = 0.45, peak 8.4 %), 3 x 3
// particles per cell and a different width; same tolerances.
TEST(Mandel, VariantPoissonAndResolution) {
  MandelCase c;
  c.nu = 0.2;
  c.kf = 1e7;  // M = Kf/n = 3 E_oed
  c.a = 2.0;
  c.cells = 24;
  c.rows = 2;
  c.ppc = 3;
  c.q = 5e4;
  c.k = 5e-5;
  ASSERT_LT(c.inertia_number(0.01), 0.005);
  const Result r = run_mandel(c, 0.5, 100);
  expect_within_tolerance(r, c);
}

// Without damping: with a Biot
// modulus M = Kf/n of 3 E_oed the undamped run stays within the same 3 %
// (measured 1.3 %: the waves of the sudden drainage remain, Biot damping at
// k = 5e-5 m/s being weak).
TEST(Mandel, UndampedWithStifferFluid) {
  MandelCase c;
  c.kf = 9e6;  // M = 30 MPa = 3 E_oed: nu_u = 0.43, peak 13.6 %
  c.damping = 0.0;
  // 0.6 % at T = 0.01 with k = 5e-5 m/s: still a fifth of the tolerance.
  ASSERT_LT(c.inertia_number(0.01), 0.01);
  const Result r = run_mandel(c, 0.5, 100);
  expect_within_tolerance(r, c);
}

// The default moduli (M = E_oed, 0.87 of the limit where the u-p equations
// with Darcy's rho_f a grow) without damping: with the re-mapped
// acceleration in Darcy's law the drainage waves decay (with the nodal
// acceleration they grew to +-40 % of p0 by T = 0.5; docs/verification.md).
// Same tolerances as the damped case.
TEST(Mandel, UndampedNearTheDarcyInertiaLimit) {
  MandelCase c;
  c.damping = 0.0;
  const Result r = run_mandel(c, 0.5, 100);
  expect_within_tolerance(r, c);
}

// Damping is there to remove waves, not to shape the answer: with half and
// twice the coefficient the centre history after the initial transient
// (T >= 0.01) agrees within 0.3 % of p0 (a tenth of the tolerance; the
// bias bound alpha D is below 1e-4 here).
TEST(Mandel, DampingDoesNotBiasTheHistory) {
  MandelCase low, high;
  low.damping = 0.01;
  high.damping = 0.04;
  const Result a = run_mandel(low, 0.2, 40), b = run_mandel(high, 0.2, 40);
  ASSERT_EQ(a.centre.size(), b.centre.size());
  double diff = 0;
  for (std::size_t i = 0; i < a.centre.size(); ++i)
    if (a.time[i] * low.c() / (low.a * low.a) >= 0.01)
      diff = std::max(diff, std::abs(a.centre[i] - b.centre[i]) / low.p0());
  std::printf("mandel: damping 0.01 vs 0.04: max centre difference %.2e p0\n", diff);
  EXPECT_LT(diff, 0.003);
}

}  // namespace
