// Terzaghi one-dimensional consolidation (verification §3): a saturated
// column, fixed and impermeable at the base, drained and loaded by q at the
// top, starting from p = q and zero effective stress. Coupled u-p, automatic
// time step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

struct TerzaghiCase {
  int dim = 1;
  int axis = 0;  // vertical axis; base at 0, drained top at H
  double H = 1.0;
  int cells = 40;
  int ppc = 1;
  // The public case (Anura3D §2.3) does not give k; 1e-5 m/s keeps the
  // problem quasi-static, as Terzaghi's solution assumes (see InertiaNumber).
  double porosity = 0.3, rho_s = 2650, E = 10e6, nu = 0.0, kw = 75e6, q = 1e3, k = 1e-5;
  double m_v() const { return (1 + nu) * (1 - 2 * nu) / (E * (1 - nu)); }
  double storage() const { return porosity / kw; }
  double cv() const { return k / (1000.0 * 9.81 * (m_v() + storage())); }
  double time_of(double tv) const { return tv * H * H / cv(); }
  double rho() const { return (1 - porosity) * rho_s + porosity * 1000.0; }
  double c_undrained() const { return std::sqrt((1 / m_v() + 1 / storage()) / rho()); }
  /// Terzaghi's settlement rate q m_v sqrt(c_v/(pi t)) times the impedance
  /// rho c1, over q: the size of the pressure waves the dynamic equations add
  /// to the quasi-static solution at T_v.
  double inertia_number(double tv) const {
    return rho() * c_undrained() * m_v() * cv() / (H * std::sqrt(closed_form::pi * tv));
  }
};

hmpm::Problem terzaghi(const TerzaghiCase& c, double end) {
  hmpm::Problem p = problems::column(c.dim, c.axis, c.H, c.cells, c.ppc);
  p.materials.push_back(problems::saturated_elastic(c.rho_s, c.E, c.nu, c.porosity, c.k, c.kw));
  // Zero effective stress initially: the total stress -q is carried by the water.
  problems::load_consolidation(p, c.axis, c.H, c.cells, c.ppc, c.q, c.H);
  p.time.end = end;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::strain};
  return p;
}

struct Errors {
  double max_pressure = 0;  // over particles, relative to q
  double max_degree = 0;    // |U - U_exact|
  std::vector<double> tv;
};

// Runs to T_v = 0.5 sampling at T_v = 0.05, 0.1, 0.2, 0.5; the pressure error is
// the largest over all particles at those times.
Errors run_terzaghi(const TerzaghiCase& c) {
  const std::vector<double> targets = {0.05, 0.1, 0.2, 0.5};
  hmpm::Problem p = terzaghi(c, c.time_of(0.5));
  p.output.series_interval = c.time_of(0.05);
  // rows at T_v = 0, .05, .1, ..., .5
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  Errors e;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size();
  const int strain_axis = c.axis;  // Voigt xx, yy, zz = axis index
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    const double tv = s.time[row] / c.time_of(1.0);
    bool wanted = false;
    for (double target : targets) wanted = wanted || std::abs(tv - target) < 0.01;
    if (!wanted) continue;
    e.tv.push_back(tv);
    double settlement = 0;
    for (std::size_t i = 0; i < np; ++i) {
      const double z = c.H - s.initial_positions[i][c.axis];
      const double pe = closed_form::terzaghi_pressure(z, tv, c.H, c.q);
      e.max_pressure = std::max(e.max_pressure, std::abs(s.values[0][row * np + i] - pe) / c.q);
      settlement -= s.values[1][(row * np + i) * 6 + strain_axis];
    }
    // All particles have the same initial volume: settlement = H * mean(-strain).
    settlement *= c.H / static_cast<double>(np);
    const double u = settlement / (c.m_v() * c.q * c.H);
    e.max_degree = std::max(e.max_degree, std::abs(u - closed_form::terzaghi_degree(tv)));
  }
  return e;
}

// Tolerances (issue 3): pore pressure within 1 % of q at every particle at
// T_v = 0.05, 0.1, 0.2 and 0.5, degree of consolidation within 1 %. With 40
// cells the boundary layer at T_v = 0.05 (sqrt(T_v) H = 0.22 H) spans 9
// cells, where linear elements with lumped storage err by a few 0.1 %; the
// inertia number at T_v = 0.05 is 0.2 %. Measured: 0.10 % and 0.06 %.
TEST(Terzaghi, PublicCaseWithAutomaticStep) {
  const TerzaghiCase c;
  ASSERT_LT(c.inertia_number(0.05), 0.003);
  const Errors e = run_terzaghi(c);
  std::printf("terzaghi: max |p - p_exact|/q = %.4g, max |U - U_exact| = %.4g over %zu times\n",
              e.max_pressure, e.max_degree, e.tv.size());
  ASSERT_EQ(e.tv.size(), 4u);
  EXPECT_LT(e.max_pressure, 0.01);
  EXPECT_LT(e.max_degree, 0.01);
}

// Variants: a stiffer, taller column with nu > 0 standing along y in 2D
// (roller walls) with 2x2 particles per cell, and one along z in 3D. Same
// tolerances; each is quasi-static (inertia number asserted small). The
// product of the inertia number and the step count is fixed by the ratio of
// undrained to drained stiffness, so stiffer skeletons keep these cheap.
TEST(Terzaghi, VariantsEmbeddedIn2DAnd3D) {
  TerzaghiCase a;
  a.dim = 2;
  a.axis = 1;
  a.H = 2.0;
  a.cells = 20;
  a.ppc = 2;
  a.E = 50e6;
  a.nu = 0.25;
  a.k = 2e-5;
  a.q = 5e4;
  a.porosity = 0.4;
  TerzaghiCase b;
  b.dim = 3;
  b.axis = 2;
  b.cells = 20;
  b.E = 50e6;
  b.k = 1e-5;
  for (const TerzaghiCase& c : {a, b}) {
    ASSERT_LT(c.inertia_number(0.05), 0.003) << "dim " << c.dim;
    const Errors e = run_terzaghi(c);
    std::printf("terzaghi dim %d: max |p - p_exact|/q = %.4g, max |U - U_exact| = %.4g\n", c.dim,
                e.max_pressure, e.max_degree);
    ASSERT_EQ(e.tv.size(), 4u);
    EXPECT_LT(e.max_pressure, 0.01) << "dim " << c.dim;
    EXPECT_LT(e.max_degree, 0.01) << "dim " << c.dim;
  }
}

// Inertia: Terzaghi's solution neglects it; the u-p equations keep it. For a
// permeable column (k = 1e-3 m/s) consolidating in about a second, the
// settlement rate times the undrained impedance makes pressure waves of the
// size of the inertia number. The deviation must be explained by it: below
// it (the sampled phase of the waves sets how far below) and shrinking with k.
TEST(Terzaghi, DeviationAtHighPermeabilityIsInertia) {
  TerzaghiCase fast;
  fast.k = 1e-3;
  TerzaghiCase slower = fast;
  slower.k = 1e-4;
  const double d_fast = fast.inertia_number(0.05), d_slow = slower.inertia_number(0.05);
  const Errors e_fast = run_terzaghi(fast), e_slow = run_terzaghi(slower);
  std::printf("inertia number %.3g -> deviation %.3g; %.3g -> %.3g\n", d_fast, e_fast.max_pressure,
              d_slow, e_slow.max_pressure);
  EXPECT_LT(e_fast.max_pressure, d_fast);
  EXPECT_LT(e_slow.max_pressure, d_slow);
  EXPECT_GT(e_fast.max_pressure, e_slow.max_pressure);
}

}  // namespace

namespace {

// Early times (issue 18): from T_v = 0.02, every 0.01 to 0.12, the pore
// pressure at every particle deeper than 0.1 H (the interior: the drained
// boundary layer's first four cells are left to the tests above) within
// 0.5 % of q, for nu = 0 and 0.3, water softened to 50 MPa and real water
// (2.2 GPa), 1 and 2 particles per cell, the automatic step. The
// permeability of each variant makes its inertia number 0.2 % at T_v = 0.02
// (Terzaghi's solution is the dynamic one's only where that is small; the
// explicit step count grows as the inertia number falls, with the real
// water's wave speed: 2 million steps here).
TEST(Terzaghi, EarlyTimesAcrossPoissonFluidsAndParticles) {
  for (double nu : {0.0, 0.3})
    for (double kw : {50e6, 2.2e9})
      for (int ppc : {1, 2}) {
        TerzaghiCase c;
        c.E = 50e6;
        c.nu = nu;
        c.kw = kw;
        c.ppc = ppc;
        c.k = 1.0;
        c.k = 0.002 / c.inertia_number(0.02);  // the number is proportional to k
        ASSERT_NEAR(c.inertia_number(0.02), 0.002, 1e-9);
        hmpm::Problem p = terzaghi(c, c.time_of(0.12));
        p.output.series_fields = {hmpm::Field::pore_pressure};
        p.output.series_interval = c.time_of(0.01);
        const hmpm::RunResult r = hmpm::run(p);
        ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
        const hmpm::Series& s = r.series;
        const std::size_t np = s.particles.size();
        double worst = 0, worst_tv = 0;
        for (std::size_t row = 0; row < s.time.size(); ++row) {
          const double tv = s.time[row] / c.time_of(1.0);
          if (tv < 0.0199) continue;
          for (std::size_t i = 0; i < np; ++i) {
            const double z = c.H - s.initial_positions[i][0];
            if (z < 0.1 * c.H) continue;
            const double e = std::abs(s.values[0][row * np + i] -
                                      closed_form::terzaghi_pressure(z, tv, c.H, c.q)) /
                             c.q;
            if (e > worst) {
              worst = e;
              worst_tv = tv;
            }
          }
        }
        std::printf(
            "terzaghi early: nu %.1f, Kw %.3g, %d per cell, k %.3g: %lld steps, worst "
            "%.4f of q (T_v = %.2f)\n",
            nu, kw, ppc, c.k, static_cast<long long>(r.steps), worst, worst_tv);
        EXPECT_LT(worst, 0.005) << "nu " << nu << " Kw " << kw << " ppc " << ppc;
      }
}

}  // namespace
