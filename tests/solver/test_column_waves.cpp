// Waves in a saturated column (verification §5, Verruijt; issue 18): the
// Anura3D parameters H = 0.5 m, n = 0.1, rho_s = 2222 kg/m^3, E = 180 kPa,
// nu = 0.2 (E_oed = 200 kPa), Kf = 20 kPa (E_oed Q = 1.0, at 0.91 of the
// Darcy-inertia limit (rho - rho_f)/rho_f = 1.1), k = 1e-4 m/s, a load
// ramped over 5 ms, 2 particles per cell; and a stiffer fluid far from the
// limit (Kf = 200 kPa, E_oed Q = 0.1). Reference: the exact solution of the
// u-p equations (Laplace transform, de Hoog's inversion; column_waves.hpp),
// checked below against the same equations solved by a staggered
// finite-difference scheme at 1600 cells, itself converged to 0.05 % of q.
// Measure: the RMS of the
// errors of sigma' and p at the particles nearest the depths H/4, H/2 and
// 3H/4, at every millisecond to 0.15 s (four passes of the fast wave), over
// q.
//
// The load is 20 Pa, not the manual's 2 kPa: the reference is the
// small-strain solution, and 2 kPa strains this soft column by 0.5 % as the
// fast wave passes and 1 % after its reflection doubles the stress; with
// n = 0.1 that changes the porosity by 9 % (n' = 1 - (1 - n)/J), so the
// fluid's share of the load and the wave speed move by a few percent: a
// finite-strain solver (hmpm) then differs from the small-strain solution
// by 3.5-4 % RMS at any resolution, which is physics, not error (measured:
// at 2 kPa linear 24 %/18 %, GIMP 3.8 %/4.2 %, B-spline 3.5 %/3.7 % at
// 100/200 cells; at 200 Pa already the 20 Pa figures). Linear shape
// functions at 2 kPa cross cells (particles move 5 mm, 1-2 cells) and ring:
// the default shape function for large deformation is not linear (docs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "column_waves.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

using column_waves::Column;
using Rows = std::vector<std::vector<double>>;

constexpr double q = 20.0, ramp = 0.005, end = 0.15, every = 1e-3;
const std::vector<double> depths = {0.125, 0.25, 0.375};

double load(double t) {
  return q * std::min(t / ramp, 1.0);
}

std::vector<double> output_times() {
  std::vector<double> t;
  for (int i = 0; i * every <= end + 1e-12; ++i) t.push_back(i * every);
  return t;
}

double rms(const Rows& a, const Rows& b) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t t = 0; t < std::min(a.size(), b.size()); ++t)
    for (std::size_t k = 0; k < a[t].size(); ++k) {
      sum += (a[t][k] - b[t][k]) * (a[t][k] - b[t][k]);
      ++n;
    }
  return std::sqrt(sum / static_cast<double>(n)) / q;
}

Column column(double kf) {
  Column c;
  c.storage = c.porosity / kf;
  return c;
}

// hmpm's RMS error against the reference at `cells` cells.
double hmpm_error(double kf, hmpm::ShapeFunction shape, int cells) {
  const Column c = column(kf);
  hmpm::Problem p = problems::column(1, 0, c.H, cells, 2);
  p.shape_function = shape;
  p.materials.push_back(
      problems::saturated_elastic(c.rho_s, 180e3, 0.2, c.porosity, c.kappa * 9810.0, kf));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, c.H), 0.0));
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  const double spacing = c.H / (2 * cells);
  t.particles.min[0] = c.H - spacing;  // the top particle
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [](double time) { return -load(time); };
  p.tractions.push_back(t);
  p.time.end = end;
  std::vector<double> at;  // the depths of the particles observed
  for (double z : depths) {
    const auto i = std::lround((c.H - z) / spacing - 0.5);
    p.output.series_particles.push_back(i);
    at.push_back(c.H - (static_cast<double>(i) + 0.5) * spacing);
  }
  p.output.series_fields = {hmpm::Field::effective_stress, hmpm::Field::pore_pressure};
  p.output.series_interval = every;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const std::vector<double> times = output_times();
  const Rows ref = column_waves::exact(c, q, ramp, times, at);
  Rows got;
  const hmpm::Series& s = r.series;
  EXPECT_EQ(s.time.size(), times.size());
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    std::vector<double> values;
    for (std::size_t k = 0; k < depths.size(); ++k) {
      values.push_back(s.values[0][(row * depths.size() + k) * 6]);  // sigma'_xx
      values.push_back(s.values[1][row * depths.size() + k]);
    }
    got.push_back(values);
  }
  return rms(got, ref);
}

// The reference converges (the differences to 1600 cells fall by 2.5x and
// 2.7x per halving, 0.35 %, 0.14 %, 0.05 % of q at 200, 400, 800 cells;
// the error of 800 cells is about 4/3 of its difference to 1600 for a
// second-order scheme) and at 800 cells is within 0.1 % of q of 1600: its
// own error at 1600 cells is a few 0.01 %.
TEST(ColumnWaves, FiniteDifferenceReferenceConverges) {
  const Column c = column(20e3);
  const std::vector<double> times = output_times();
  const Rows r200 = column_waves::reference(c, load, 200, times, depths);
  const Rows r400 = column_waves::reference(c, load, 400, times, depths);
  const Rows r800 = column_waves::reference(c, load, 800, times, depths);
  const Rows r1600 = column_waves::reference(c, load, 1600, times, depths);
  const double e200 = rms(r200, r1600), e400 = rms(r400, r1600), e800 = rms(r800, r1600);
  std::printf("[ column waves ] reference against 1600 cells: %.5f (200), %.5f (400), %.5f (800)\n",
              e200, e400, e800);
  EXPECT_GT(e200, 2.0 * e400);
  EXPECT_GT(e400, 2.0 * e800);
  EXPECT_LT(e800, 0.001);
  // And the load arrives: sigma' - p at mid-depth after the first pass is -q.
  EXPECT_NEAR(r1600[30][2] - r1600[30][3], -q, 0.01 * q);
}

// The exact solution against the converged finite differences, both
// fluids: RMS within 0.05 % of q (measured 0.021 % at Kf = 20 kPa, the
// finite differences' own error at 1600 cells, and 0.001 % at 200 kPa;
// the inversion itself converges: 0.064 %, 0.021 %, 0.022 % with 80, 120,
// 160 terms at 20 kPa). And the load arrives: at Kf = 20 kPa sigma' - p at
// mid-depth after the first pass is -q.
TEST(ColumnWaves, ExactSolutionMatchesTheFiniteDifferences) {
  const std::vector<double> times = output_times();
  for (double kf : {20e3, 200e3}) {
    const Column c = column(kf);
    const Rows exact = column_waves::exact(c, q, ramp, times, depths);
    const Rows fd = column_waves::reference(c, load, 1600, times, depths);
    const double e = rms(exact, fd);
    std::printf(
        "[ column waves ] exact against finite differences (1600 cells), Kf %.0f Pa: %.5f\n", kf,
        e);
    EXPECT_LT(e, 0.0005) << "Kf " << kf;
    // (At Kf = 200 kPa the fast wave has come back from the base by then.)
    if (kf < 100e3) {
      EXPECT_NEAR(exact[30][2] - exact[30][3], -q, 0.001 * q);
    }
  }
}

// Every shape function, near the Darcy-inertia limit and far from it: the
// error at 200 cells at most 1.5 % of q (the bound; linear 5 %)
// and no larger than at 100 cells. Measured (100 -> 200 cells), Kf = 20
// kPa: linear 2.2 % -> 0.87 %, GIMP 2.2 % -> 0.87 %, B-spline 3.5 % ->
// 1.4 %; Kf = 200 kPa: 1.0 % -> 0.30 %, 1.0 % -> 0.30 %, 3.2 % -> 1.5 %.
// (GIMP was 4.3 % -> 3.8 % before a face load's weights were made whole at
// the grid's edge: the load on the top face arrived 6 % short, its share of
// the node beyond the grid lost; boundary/tractions.hpp, for_face_nodes.)
TEST(ColumnWaves, ConvergeForEveryShapeFunctionNearAndFarFromTheDarcyInertiaLimit) {
  for (double kf : {20e3, 200e3})
    for (hmpm::ShapeFunction shape :
         {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline}) {
      const double coarse = hmpm_error(kf, shape, 100), fine = hmpm_error(kf, shape, 200);
      const char* name = shape == hmpm::ShapeFunction::linear
                             ? "linear"
                             : (shape == hmpm::ShapeFunction::gimp ? "gimp" : "bspline");
      std::printf("[ column waves ] Kf %.0f Pa, %s: RMS %.4f (100 cells), %.4f (200 cells)\n", kf,
                  name, coarse, fine);
      EXPECT_LT(fine, shape == hmpm::ShapeFunction::linear ? 0.05 : 0.015)
          << "Kf " << kf << " " << name;
      EXPECT_LE(fine, coarse) << "Kf " << kf << " " << name;
    }
}

}  // namespace
