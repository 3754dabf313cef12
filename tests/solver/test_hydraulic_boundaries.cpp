// Hydraulic boundaries (verification §11): a flux of water across particle
// faces (Problem::fluxes) and seepage faces (Boundary::seepage), on a column
// whose skeleton is held fixed, so the pore pressure obeys the diffusion
// equation dp/dt = c p_xx, c = k / (gamma_w S), S = n / Kf, and Darcy's law
// w = -(k / gamma_w) (p_x - rho_f b) with b the gravity.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double gamma_w = 1000.0 * 9.81;

struct Column {
  int dim = 1;
  int cells = 20;
  double L = 1.0;
  double k = 1e-3;
  double porosity = 0.3;
  double kf = 300e6;
  double gravity = 0.0;  // m/s^2 along -x
  hmpm::Scheme scheme = hmpm::Scheme::explicit_scheme;
  double c() const { return k / (gamma_w * (porosity / kf)); }
};

// The column along x, skeleton fixed, p = 0 initially, every particle in
// the series (pore pressure and Darcy velocity).
hmpm::Problem fixed_column(const Column& col, double end) {
  hmpm::Problem p = problems::column(col.dim, 0, col.L, col.cells, 1);
  p.materials.push_back(problems::saturated_elastic(2650, 1e7, 0.0, col.porosity, col.k, col.kf));
  hmpm::Boundary fixed;
  fixed.nodes.all = true;
  fixed.has_velocity = true;
  for (int a = 0; a < col.dim; ++a) fixed.velocity[a] = problems::constant(0.0);
  p.boundaries.push_back(fixed);
  p.gravity[0] = -col.gravity;
  p.time.end = end;
  p.time.scheme = col.scheme;
  // The implicit schemes' own step (semi_implicit: the skeleton's wave
  // limit, ~7e-4 s here, comparable to the diffusion time L^2 / c = 0.01 s)
  // would make the transient a test of backward Euler; 400 steps over the
  // run keep the time error well below the space error.
  if (col.scheme != hmpm::Scheme::explicit_scheme) p.time.dt = end / 400;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::darcy_velocity};
  return p;
}

// Inflow `rate` (m/s into the soil) across the top face x = L of the top
// particles, and p = 0 on the base plane x = 0.
void inflow_at_top(hmpm::Problem& p, const Column& col, double rate) {
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, 0.0), 0.0));
  hmpm::Flux f;
  f.particles.min = p.grid.min;
  f.particles.max = p.grid.max;
  f.particles.min[0] = col.L - col.L / col.cells;  // the top row of particles
  f.axis = 0;
  f.side = +1;
  f.rate = [rate](const hmpm::Vec3&, double) { return rate; };
  p.fluxes.push_back(f);
}

const char* name(hmpm::Scheme s) {
  return hmpm::scheme_name(s);
}

// Steady inflow r through a column drained at its base: w = -r everywhere,
// so p_x = r gamma_w / k - gamma_w (gravity along -x), p linear and exact.
// The nodal pressure then solves the discrete steady equation, whose
// solution with a flux at the end node is exactly linear; particles report
// it interpolated: round-off, asserted at 1e-6 of the pressure scale (w at
// 1e-6 of r). The semi-implicit scheme carries a steady error of its own in
// this fixed skeleton, alternating from particle to particle, with
// prescribed pressures and no flux as well (the same column between p = 0
// and p = 981 Pa, 20 cells: 0.017 Pa, 1.8e-5 of the scale, and the Darcy
// velocity 0.9 % off). Measured here 9e-6 / 3.6e-5 of the scale and 1.1 % /
// 4.3 % of r without / with gravity: asserted at 1e-4 and 6e-2. Found
// with this test and left for the scheme's own issue. Run to
// c t / L^2 = 8: the slowest mode, exp(-(pi/2)^2 c t / L^2), has decayed by
// e^-19.7 = 3e-9.
TEST(HydraulicBoundaries, SteadyInflowGivesTheExactLinearPressureInEveryScheme) {
  for (hmpm::Scheme scheme :
       {hmpm::Scheme::explicit_scheme, hmpm::Scheme::semi_implicit, hmpm::Scheme::quasi_static})
    for (int dim : {1, 2})
      for (double gravity : {0.0, 9.81}) {
        Column col;
        col.dim = dim;
        col.scheme = scheme;
        col.gravity = gravity;
        const double rate = 2e-4;  // m/s, 1/5 of k
        const double end = 8.0 * col.L * col.L / col.c();
        hmpm::Problem p = fixed_column(col, end);
        inflow_at_top(p, col, rate);
        p.output.series_interval = end;
        const hmpm::RunResult r = hmpm::run(p);
        ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message << " " << name(scheme);
        const hmpm::Series& s = r.series;
        const std::size_t last = s.time.size() - 1, np = s.particles.size();
        const double grad = rate * gamma_w / col.k - 1000.0 * gravity;
        const double scale = std::abs(rate * gamma_w / col.k) * col.L;
        const bool semi = scheme == hmpm::Scheme::semi_implicit;
        const double tol_p = semi ? 1e-4 : 1e-6, tol_w = semi ? 6e-2 : 1e-6;
        double worst_p = 0.0, worst_w = 0.0;
        for (std::size_t i = 0; i < np; ++i) {
          const double x = s.initial_positions[i][0];
          worst_p = std::max(worst_p, std::abs(s.values[0][last * np + i] - grad * x) / scale);
          worst_w = std::max(worst_w, std::abs(s.values[1][(last * np + i) * dim] + rate) / rate);
        }
        std::printf("steady inflow %s %dD g %.2f: max error p %.2e of r gw L/k, w %.2e of r\n",
                    name(scheme), dim, gravity, worst_p, worst_w);
        for (std::size_t i = 0; i < np; ++i) {
          const double x = s.initial_positions[i][0];
          EXPECT_NEAR(s.values[0][last * np + i], grad * x, tol_p * scale)
              << name(scheme) << " dim " << dim << " g " << gravity << " particle " << i;
          EXPECT_NEAR(s.values[1][(last * np + i) * dim], -rate, tol_w * rate)
              << name(scheme) << " dim " << dim << " g " << gravity << " particle " << i;
        }
      }
}

// The transient of the same column (no gravity) against its series
// solution (closed_form::flux_column_pressure), from c t / L^2 = 0.02 on,
// where the solution is smooth on the grid: linear shape functions with
// lumped storage err by O(h^2) (the Darcy problem with a prescribed
// pressure measured 0.43 % of its scale at 20 cells); assert 1 % of the
// pressure scale r gamma_w L / k, and that halving h cuts the error by at
// least 2.5 (second order: 4; measured explicit 0.063 % -> 0.016 %,
// semi-implicit at 400 steps 0.15 % -> 0.053 %, whose steady error above
// takes part).
double transient_error(const Column& col, double rate) {
  const double end = 0.5 * col.L * col.L / col.c();
  hmpm::Problem p = fixed_column(col, end);
  inflow_at_top(p, col, rate);
  p.output.series_interval = end / 50;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size();
  const double g = rate * gamma_w / col.k;
  double worst = 0.0;
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    if (s.time[row] * col.c() / (col.L * col.L) < 0.02) continue;
    for (std::size_t i = 0; i < np; ++i) {
      const double exact = closed_form::flux_column_pressure(s.initial_positions[i][0], s.time[row],
                                                             col.L, g, col.c());
      worst = std::max(worst, std::abs(s.values[0][row * np + i] - exact));
    }
  }
  return worst / (g * col.L);
}

TEST(HydraulicBoundaries, TransientInflowMatchesTheSeriesSolutionAndConverges) {
  const double rate = 2e-4;
  for (hmpm::Scheme scheme : {hmpm::Scheme::explicit_scheme, hmpm::Scheme::semi_implicit}) {
    Column coarse, fine;
    coarse.scheme = fine.scheme = scheme;
    fine.cells = 40;
    const double e20 = transient_error(coarse, rate), e40 = transient_error(fine, rate);
    std::printf("flux transient %s: max error %.3g %% (20 cells), %.3g %% (40 cells) of r gw L/k\n",
                name(scheme), 100 * e20, 100 * e40);
    EXPECT_LT(e20, 0.01) << name(scheme);
    EXPECT_GT(e20 / e40, 2.5) << name(scheme) << " " << e20 << " " << e40;
  }
}

// Rain into the top of a column that swells (no gravity, no load: the
// pore pressure the rain raises is the skeleton's tension, so it expands)
// with an impermeable base: every drop must be stored. Stored water, from
// the particles (incompressible grains): sum (V - V0) + sum V n / Kf p.
// The top face soon lies above the grid's last node row the soil reaches;
// the water a stencil gives to nodes beyond the soil goes to the others
// (apply_fluxes). Before, the quasi-static scheme dropped it: 5.1 % of the
// rain short here (the top rises 10 cm above the row). Tolerance 1e-4 of
// the rain: measured 1.2e-5, the same with 60 and 120 steps (so not the
// step's second-order volume change); the water's own compression is 4e-4
// of the stored volume, and the particles' pressures in the sum are nodal
// interpolations, so a few percent of that term is the sum's accuracy.
TEST(HydraulicBoundaries, RainIntoASwellingColumnIsAllStored) {
  const double H = 10.0, r = 5e-6, kf = 2.2e9, n = 0.35, k = 2e-6;
  hmpm::Problem p = problems::column(1, 0, H + 2.0, 12, 2);
  p.bodies[0].box.max[0] = H;
  p.materials.push_back(problems::saturated_elastic(2650, 2e6, 0.3, n, k, kf));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Flux rain;
  rain.particles.min[0] = H - 0.5;
  rain.particles.max[0] = H;
  rain.axis = 0;
  rain.side = +1;
  rain.rate = [r](const hmpm::Vec3&, double) { return r; };
  p.fluxes.push_back(rain);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 6.0 * 3600;
  p.time.dt = p.time.end / 60;
  p.output.snapshot_interval = p.time.end;
  p.output.snapshot_fields = {hmpm::Field::position, hmpm::Field::pore_pressure,
                              hmpm::Field::porosity};
  std::vector<hmpm::Snapshot> snaps;
  hmpm::RunOptions opt;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) { snaps.push_back(s); };
  const hmpm::RunResult res = hmpm::run(p, opt);
  ASSERT_EQ(res.status, hmpm::RunStatus::successful) << res.message;
  ASSERT_EQ(snaps.size(), 2u);
  const hmpm::Snapshot &a = snaps.front(), &b = snaps.back();
  double stored = 0.0, top = 0.0;
  for (std::size_t i = 0; i < b.volume.size(); ++i) {
    stored += b.volume[i] - a.volume[i] +
              b.volume[i] * b.porosity[i] / kf * (b.pore_pressure[i] - a.pore_pressure[i]);
    top = std::max(top, b.position[3 * i]);
  }
  const double rain_in = r * p.time.end;
  std::printf(
      "swelling column: top particle at %.4f m (started at %.4f), stored %.8g m of %.8g "
      "m of rain (%.2e off)\n",
      top, H - 0.25, stored, rain_in, stored / rain_in - 1);
  EXPECT_GT(top - (H - 0.25), 0.01);  // the top face left the node row x = H
  EXPECT_NEAR(stored, rain_in, 1e-4 * rain_in);
}

// The column under gravity with p_b at its base and a seepage face at its
// top (a steady end: c t / H^2 = 8, as the inflow column), run.
hmpm::RunResult seepage_column(const Column& col, double pb) {
  const double end = 8.0 * col.L * col.L / col.c();
  hmpm::Problem p = fixed_column(col, end);
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, 0.0), pb));
  hmpm::Boundary face;
  face.nodes = problems::plane(p, 0, col.L);
  face.seepage = true;
  p.boundaries.push_back(face);
  p.output.series_interval = end;
  return hmpm::run(p);
}

// An artesian column (§11): base pressure p_b above the hydrostatic gamma_w
// H, a seepage face at the top. Water leaves through the face: p = 0 there,
// p linear, p = p_b (1 - x / H), and the outflow w = k (p_b / (gamma_w H) -
// 1) up the column, both exact at steady state (round-off, 1e-6; run to
// c t / H^2 = 8 as the inflow column: the slowest mode is the same).
TEST(HydraulicBoundaries, SeepageFaceOfAnArtesianColumnDrainsToZeroWithTheExactOutflow) {
  for (hmpm::Scheme scheme :
       {hmpm::Scheme::explicit_scheme, hmpm::Scheme::semi_implicit, hmpm::Scheme::quasi_static})
    for (int dim : {1, 2}) {
      SCOPED_TRACE(name(scheme));
      Column col;
      col.dim = dim;
      col.gravity = 9.81;
      col.scheme = scheme;
      const double pb = 1.5 * gamma_w * col.L;
      const hmpm::RunResult r = seepage_column(col, pb);
      ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
      const hmpm::Series& s = r.series;
      const std::size_t last = s.time.size() - 1, np = s.particles.size();
      const double outflow = col.k * (pb / (gamma_w * col.L) - 1.0);
      // The semi-implicit scheme's own steady error in a fixed skeleton
      // (the steady inflow test above): its tolerances there, 1e-4 and 6e-2.
      const bool semi = scheme == hmpm::Scheme::semi_implicit;
      const double tol_p = semi ? 1e-4 : 1e-6, tol_w = semi ? 6e-2 : 1e-6;
      double worst_p = 0, worst_w = 0;
      for (std::size_t i = 0; i < np; ++i) {
        const double x = s.initial_positions[i][0];
        const double pe = s.values[0][last * np + i] - pb * (1 - x / col.L);
        const double we = s.values[1][(last * np + i) * dim] - outflow;
        worst_p = std::max(worst_p, std::abs(pe) / pb);
        worst_w = std::max(worst_w, std::abs(we) / outflow);
        EXPECT_LT(std::abs(pe), tol_p * pb) << "dim " << dim << " particle " << i;
        EXPECT_LT(std::abs(we), tol_w * outflow) << "dim " << dim << " particle " << i;
      }
      std::printf("artesian seepage column, %s %dD: p %.2e of p_b, outflow %.2e off\n",
                  name(scheme), dim, worst_p, worst_w);
    }
}

// Below hydrostatic (§11): p_b < gamma_w H. Starting from p = 0 everywhere
// (the face node at zero, where a prescribed p = 0 would draw water in),
// the face takes no water in: the column goes to rest at the hydrostatic
// p = p_b - gamma_w x, negative at the top, with no flow (round-off).
TEST(HydraulicBoundaries, SeepageFaceBelowHydrostaticTakesNoWaterIn) {
  for (hmpm::Scheme scheme :
       {hmpm::Scheme::explicit_scheme, hmpm::Scheme::semi_implicit, hmpm::Scheme::quasi_static}) {
    SCOPED_TRACE(name(scheme));
    Column col;
    col.gravity = 9.81;
    col.scheme = scheme;
    const double pb = 0.6 * gamma_w * col.L;
    const double end = 8.0 * col.L * col.L / col.c();
    const hmpm::RunResult r = seepage_column(col, pb);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    const hmpm::Series& s = r.series;
    const std::size_t last = s.time.size() - 1, np = s.particles.size();
    // The semi-implicit scheme's steady error as above, the flux against
    // 0.4 k (what a face held at p = 0 would draw in).
    const bool semi = scheme == hmpm::Scheme::semi_implicit;
    const double tol_p = semi ? 1e-4 : 1e-6, tol_w = semi ? 6e-2 * 0.4 : 1e-6;
    double worst_p = 0, worst_w = 0;
    for (std::size_t i = 0; i < np; ++i) {
      const double x = s.initial_positions[i][0];
      const double pe = s.values[0][last * np + i] - (pb - gamma_w * x);
      worst_p = std::max(worst_p, std::abs(pe) / pb);
      worst_w = std::max(worst_w, std::abs(s.values[1][last * np + i]) / col.k);
      EXPECT_LT(std::abs(pe), tol_p * pb) << "particle " << i;
      EXPECT_LT(std::abs(s.values[1][last * np + i]), tol_w * col.k) << "particle " << i;
    }
    std::printf("seepage face below hydrostatic, %s: p %.2e of p_b, |w| %.2e of k\n", name(scheme),
                worst_p, worst_w);
    // The same column with p = 0 prescribed at the top instead: water enters
    // there (the test above can tell the difference).
    hmpm::Problem held = fixed_column(col, end);
    held.boundaries.push_back(problems::fixed_pressure(problems::plane(held, 0, 0.0), pb));
    held.boundaries.push_back(problems::fixed_pressure(problems::plane(held, 0, col.L), 0.0));
    held.output.series_interval = end;
    const hmpm::RunResult rh = hmpm::run(held);
    ASSERT_EQ(rh.status, hmpm::RunStatus::successful) << rh.message;
    EXPECT_LT(rh.series.values[1][(rh.series.time.size() - 1) * np], -0.1 * col.k)
        << "a face held at p = 0 should draw water down the column";
  }
}

// A reservoir against a sloping face (issue 17): a 2D trapezoid of soil
// whose upstream face rises from (0, 0) to (0.5, 1), the skeleton fixed,
// gravity; the nodes on and beyond the face take p = gamma_w (h - y), a
// formula in y, with the water level h = 1.2 m above the crest; the other
// faces are impermeable. At rest the whole body is hydrostatic, p =
// gamma_w (h - y), with no flow: exact (linear in y, which the linear
// shape functions interpolate exactly), asserted at 1e-6 of gamma_w h.
TEST(HydraulicBoundaries, ReservoirHeadOnASlopingFaceIsHydrostaticAtRest) {
  const double h = 1.2;
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.max = {1.0, 1.0, 0.0};
  p.grid.cells = {10, 10, 1};
  hmpm::Body body;
  body.polygon = hmpm::Polygon{{{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.5, 1.0}}};
  body.particles_per_cell = 2;
  p.bodies.push_back(body);
  const double kf = 300e6, k = 1e-3;
  p.materials.push_back(problems::saturated_elastic(2650, 1e7, 0.3, 0.3, k, kf));
  hmpm::Boundary fixed;
  fixed.nodes.all = true;
  fixed.has_velocity = true;
  for (int a = 0; a < 2; ++a) fixed.velocity[a] = problems::constant(0.0);
  p.boundaries.push_back(fixed);
  hmpm::Boundary reservoir;  // the nodes on the face and upstream of it
  reservoir.nodes.polygon = hmpm::Polygon{{{0.0, 0.0}, {0.5, 1.0}, {0.0, 1.0}}};
  reservoir.pore_pressure = [h](double) { return gamma_w * h; };
  reservoir.pore_pressure_field = [h](const hmpm::Vec3& x, double) { return gamma_w * (h - x[1]); };
  p.boundaries.push_back(reservoir);
  p.gravity = {0.0, -9.81, 0.0};
  const double c = k / (gamma_w * (0.3 / kf));
  p.time.end = 8.0 / c;  // (1 m)^2 / c times 8: every mode has decayed (as above)
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::darcy_velocity};
  p.output.series_interval = p.time.end;
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::Series& s = r.series;
  const std::size_t last = s.time.size() - 1, np = s.particles.size();
  ASSERT_GT(np, 100u);
  for (std::size_t i = 0; i < np; ++i) {
    const double y = s.initial_positions[i][1];
    EXPECT_NEAR(s.values[0][last * np + i], gamma_w * (h - y), 1e-6 * gamma_w * h) << i;
    for (int a = 0; a < 2; ++a)
      EXPECT_NEAR(s.values[1][(last * np + i) * 2 + a], 0.0, 1e-6 * k) << i;
  }
}

// What the checks refuse, with the JSON path of the entry.
TEST(HydraulicBoundaries, ChecksNameTheEntryAndWhatToChange) {
  Column col;
  hmpm::Problem p = fixed_column(col, 0.01);
  hmpm::Boundary face;
  face.nodes = problems::plane(p, 0, col.L);
  face.seepage = true;
  face.pore_pressure = problems::constant(0.0);
  p.boundaries.push_back(face);
  const auto issues = hmpm::check_problem(p);
  std::vector<std::string> at;
  at.reserve(issues.size());
  for (const auto& i : issues) at.push_back(i.where.text() + ": " + i.message);
  ASSERT_EQ(at.size(), 1u) << ::testing::PrintToString(at);
  EXPECT_NE(at[0].find("boundaries/1/seepage: cannot share an entry with pore_pressure"),
            std::string::npos)
      << at[0];

  hmpm::Problem dry = problems::column(1, 0, 1.0, 10, 1);
  hmpm::Material m;
  m.name = "sand";
  m.density = 2000;
  m.youngs_modulus = 1e7;
  dry.materials.push_back(m);
  hmpm::Flux f;
  f.particles.min = dry.grid.min;
  f.particles.max = dry.grid.max;
  f.axis = 1;  // no y axis in 1D
  f.rate = [](const hmpm::Vec3&, double) { return 1e-5; };
  dry.fluxes.push_back(f);
  const auto dry_issues = hmpm::check_problem(dry);
  ASSERT_EQ(dry_issues.size(), 2u);
  EXPECT_EQ(dry_issues[0].where.text(), "fluxes/0");
  EXPECT_NE(dry_issues[0].message.find("no material has `hydraulic`"), std::string::npos);
  EXPECT_EQ(dry_issues[1].where.text(), "fluxes/0/face");
}

}  // namespace
