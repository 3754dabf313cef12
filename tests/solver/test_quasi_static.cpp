// The quasi-static implicit u-p scheme (time.scheme = quasi_static,
// schemes/quasi_static_scheme.hpp): real soft clay over years (verification
// §9), Mandel with incompressible constituents and the pressure
// stabilisation (§10), large-deformation consolidation, and the failure of a
// run that cannot converge.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <vector>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// ------------------------------------------------------------------ real clay
struct ClayCase {
  int dim = 1;
  int cells = 40;
  int ppc = 2;
  double H = 5.0, E = 5e6, nu = 0.3, porosity = 0.5, k = 1e-9, kw = 2.2e9, q = 50e3;
  double rho_s = 2650;
  double growth_max_tv = 0.001;  // largest step, in T_v
  // First step, in T_v: h^2/(6 c_v) for 40 cells (1.0e-4), the step below
  // which backward Euler with the consistent coupling matrix overshoots
  // next to the drained face (Vermeer & Verruijt 1981).
  double initial_tv = 1e-4;
  double consolidation_tv = 0.01;  // output.consolidation's interval (steps land on it)
  double m_v() const { return (1 + nu) * (1 - 2 * nu) / (E * (1 - nu)); }
  double storage() const { return porosity / kw; }
  double cv() const { return k / (1000.0 * 9.81 * (m_v() + storage())); }
  double time_of(double tv) const { return tv * H * H / cv(); }
};

hmpm::Problem clay(const ClayCase& c, double end) {
  const int axis = c.dim - 1;  // vertical axis: the last one
  hmpm::Problem p = problems::column(c.dim, axis, c.H, c.cells, c.ppc);
  hmpm::Material m = problems::saturated_elastic(c.rho_s, c.E, c.nu, c.porosity, c.k, c.kw);
  m.name = "soft clay";
  p.materials.push_back(m);
  // The state just after loading: the water carries the load (as in the
  // explicit Terzaghi test; with Kw = 2.2 GPa the undrained share of the
  // skeleton is Q/(m_v + Q) = 0.15 %, which c_v with Q accounts for).
  // Drained through the fixed base: a pressure condition acts on grid nodes,
  // and the loaded top moves by up to 0.8 h over the consolidation, away
  // from the node plane z = H (which would then drain less and less). The
  // solution is Terzaghi's with z measured from the base.
  problems::load_consolidation(p, axis, c.H, c.cells, c.ppc, c.q, 0.0);
  p.time.end = end;
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.growth = hmpm::StepGrowth{c.time_of(c.initial_tv), c.time_of(c.growth_max_tv), 1.2};
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::strain};
  return p;
}

struct ClayErrors {
  double pressure = 0;  // max |p - p_exact| / q over interior particles and the times
  double degree = 0;    // max |U - U_exact|, U from the settlement
  // max |U - U_exact| of output.consolidation (U from the pore pressure)
  // at the same times, and the relative errors of its t50 and t90
  double degree_p = 0, t50 = 0, t90 = 0;
  int times = 0;
  double seconds = 0;
  hmpm::RunResult result;
};

ClayErrors run_clay(const ClayCase& c) {
  const std::vector<double> targets = {0.05, 0.1, 0.2, 0.5, 1.0};
  hmpm::Problem p = clay(c, c.time_of(1.0));
  p.output.series_interval = c.time_of(0.05);
  p.output.consolidation.interval = c.time_of(c.consolidation_tv);  // no gravity: excess = p
  const auto t0 = std::chrono::steady_clock::now();
  ClayErrors e;
  e.result = hmpm::run(p);
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(e.result.status, hmpm::RunStatus::successful) << e.result.message;
  const hmpm::Series& s = e.result.series;
  const std::size_t np = s.particles.size();
  const int axis = c.dim - 1;
  const double h = c.H / c.cells;
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    const double tv = s.time[row] / c.time_of(1.0);
    bool wanted = false;
    for (double target : targets) wanted = wanted || std::abs(tv - target) < 1e-6;
    if (!wanted) continue;
    ++e.times;
    double settlement = 0;
    for (std::size_t i = 0; i < np; ++i) {
      const double z = s.initial_positions[i][axis];
      settlement -= s.values[1][(row * np + i) * 6 + axis];
      if (z < h) continue;  // interior: beyond the cell at the drained face
      const double pe = closed_form::terzaghi_pressure(z, tv, c.H, c.q);
      e.pressure = std::max(e.pressure, std::abs(s.values[0][row * np + i] - pe) / c.q);
    }
    settlement *= c.H / static_cast<double>(np);  // equal initial volumes
    const double u = settlement / (c.m_v() * c.q * c.H);
    e.degree = std::max(e.degree, std::abs(u - closed_form::terzaghi_degree(tv)));
  }
  const hmpm::RunResult::Consolidation& con = e.result.consolidation;
  EXPECT_EQ(con.time.size(), static_cast<std::size_t>(std::lround(1 / c.consolidation_tv)) + 1);
  for (std::size_t k = 0; k < con.time.size(); ++k) {
    const double tv = con.time[k] / c.time_of(1.0);
    for (double target : targets)
      if (std::abs(tv - target) < 1e-6)
        e.degree_p =
            std::max(e.degree_p, std::abs(con.degree[k] - closed_form::terzaghi_degree(tv)));
  }
  // T_v of U = 50 % and 90 % (Terzaghi): 0.196731 and 0.848085.
  e.t50 = std::abs(con.t50 / c.time_of(0.196731) - 1);
  e.t90 = std::abs(con.t90 / c.time_of(0.848085) - 1);
  std::printf(
      "real clay %dD, %d cells x %d ppc, dt up to T_v %.3g: max |p - p_exact|/q = %.4g "
      "(interior), max |U - U_exact| = %.4g over %d times (from p: %.4g; t50 %.3g, t90 %.3g "
      "off); %lld steps to %.3g years, "
      "%lld Newton iterations, %lld solves, %.3f s\n",
      c.dim, c.cells, c.ppc, c.growth_max_tv, e.pressure, e.degree, e.times, e.degree_p, e.t50,
      e.t90, static_cast<long long>(e.result.steps), c.time_of(1.0) / (365.25 * 86400),
      static_cast<long long>(e.result.iterations.nonlinear),
      static_cast<long long>(e.result.iterations.solves), e.seconds);
  return e;
}

// Tolerances (issue 16): pore pressure within 1 % of q in the interior (every
// particle beyond the first cell at the drained face) at T_v = 0.05, 0.1,
// 0.2, 0.5, 1, and U within 1 %. Measured (40 linear cells, 2 particles
// per cell, steps growing 1.2x from 1e-4 to 1e-3 in T_v): 0.76 % and 0.23 %.
// What remains: the time error of backward Euler at the diffusion front at
// T_v = 0.05 (0.9 % with steps up to 2.5e-3, 1.2 % with 1e-2), and the
// projection of the initial jump at the drained face onto the slowest mode,
// of order h/H (the far end starts 0.8 % below q, which decays with that
// mode). The particles move (the settlement is 0.7 % of H, a third of a
// cell); with linear shape functions a finer grid makes particles cross
// cells, which adds the stress noise of cell crossing (docs/schemes.md), so
// the refinement test below refines the step.
TEST(QuasiStatic, RealSoftClayOverYears) {
  const ClayCase c;
  const ClayErrors e = run_clay(c);
  EXPECT_EQ(e.times, 5);
  EXPECT_LT(e.pressure, 0.01);
  EXPECT_LT(e.degree, 0.01);
  // output.consolidation: U from the pore pressure, the same tolerance;
  // t50 and t90 follow from U through the slope of U(T_v): an error of
  // 0.5 % in U moves them by 0.005 / (T U'(T)) = 2.0 % and 2.4 %, hence
  // 2.5 % (measured 0.23 %, 0.92 % and 0.78 %). Both measures of U come
  // from one solution: 1D mass balance makes them agree to the storage
  // of the water (Q/(m_v + Q) = 0.15 % of U).
  EXPECT_LT(e.degree_p, 0.01);
  EXPECT_LT(std::abs(e.degree_p - e.degree), 0.002);
  EXPECT_LT(e.t50, 0.025);
  EXPECT_LT(e.t90, 0.025);
  // Linear elasticity: one Newton solve per step (the second evaluation of
  // the residual confirms convergence).
  EXPECT_EQ(e.result.iterations.max_nonlinear, 1);
  EXPECT_EQ(e.result.iterations.cutbacks, 0);
  EXPECT_LT(e.result.steps, 1500);
}

// Convergence under refinement of the step: with the largest step 0.04 and
// 0.02 in T_v the error of U (where the time error dominates) must fall by
// at least a quarter (backward Euler is first order: about half; measured
// 1.07 % -> 0.36 %), the pressure error must not grow (it is set by the
// front at T_v = 0.05, where both runs take the same small steps).
TEST(QuasiStatic, RealSoftClayConvergesWithTheStep) {
  ClayCase coarse;
  coarse.growth_max_tv = 0.04;
  coarse.consolidation_tv = 0.05;  // the output's landings must not cap the step
  ClayCase fine = coarse;
  fine.growth_max_tv = 0.02;
  const ClayErrors a = run_clay(coarse), b = run_clay(fine);
  EXPECT_LE(b.pressure, a.pressure);
  EXPECT_LT(b.degree, 0.75 * a.degree);
  EXPECT_LT(b.degree_p, 0.75 * a.degree_p);  // U of output.consolidation likewise
}

}  // namespace

// ------------------------------------------------------------------ Mandel
// Verification §10: incompressible grains and water (B = 1, nu_u = 1/2),
// the quarter specimen of test_mandel.cpp (symmetry planes x = 0, y = 0,
// drained lateral face x = a, a rigid smooth impermeable plate tying the top
// node row), here starting from rest: the plate load F = q a is applied in
// the first step, whose response is the undrained one (p = p0 = q/2).
struct QsMandel {
  double a = 1.0;
  int cells = 20, rows = 2, ppc = 2;
  double E = 10e6, nu = 0.2, k = 1e-8, q = 1e4, gamma_w = 1000.0 * 9.81;
  double stabilisation = 1.0;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  double h() const { return a / cells; }
  double shear_modulus() const { return E / (2 * (1 + nu)); }
  double lambda() const { return E * nu / ((1 + nu) * (1 - 2 * nu)); }
  double c() const { return k / gamma_w * (lambda() + 2 * shear_modulus()); }
  double p0() const { return q / 2; }  // F B (1 + nu_u) / (3 a), B = 1, nu_u = 1/2
  double time_of(double T) const { return T * a * a / c(); }
};

hmpm::Problem qs_mandel(const QsMandel& c) {
  const double h = c.h(), a = c.a, b = c.rows * h;
  hmpm::Problem p;
  p.dimension = 2;
  p.shape_function = c.shape;
  p.grid.max = {a + 2 * h, b + h, 0};
  p.grid.cells = {c.cells + 2, c.rows + 1, 1};
  hmpm::Material m;
  m.name = "soil";
  m.density = 2650;
  m.youngs_modulus = c.E;
  m.poisson_ratio = c.nu;
  m.hydraulic = hmpm::Hydraulic{0.3, c.k, inf, 1000.0, inf};
  p.materials.push_back(m);
  hmpm::Body body;
  body.box.max = {a, b, 0};
  body.particles_per_cell = c.ppc;
  p.bodies.push_back(body);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 1, 0.0), 1));
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, a), 0.0));
  hmpm::Boundary plate;
  plate.nodes = problems::plane(p, 1, b);
  plate.rigid[1] = true;
  p.boundaries.push_back(plate);
  hmpm::Traction t;
  t.particles.min = {0, b - h / c.ppc, 0};
  t.particles.max = {a, b, 0};
  t.axis = 1;
  t.side = +1;
  t.traction[1] = problems::constant(-c.q);
  p.tractions.push_back(t);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.implicit.pressure_stabilisation = c.stabilisation;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure};
  return p;
}

/// Checkerboard measure: over the particles of the lower particle row with
/// x < a/2 (where the exact pressure is uniform to 1e-6 p0 at small t*),
/// max |p_i - (p_{i-1} + p_{i+1})/2| / p0 along x.
double checkerboard(const hmpm::Series& s, std::size_t row, double p0, double a) {
  std::map<double, double> line;  // x -> p, lowest particle row
  const std::size_t np = s.particles.size();
  double ymin = inf;
  for (std::size_t i = 0; i < np; ++i) ymin = std::min(ymin, s.initial_positions[i][1]);
  for (std::size_t i = 0; i < np; ++i)
    if (s.initial_positions[i][1] < ymin + 1e-9 && s.initial_positions[i][0] < 0.5 * a)
      line[s.initial_positions[i][0]] = s.values[0][row * np + i];
  std::vector<double> v;
  v.reserve(line.size());
  for (const auto& kv : line) v.push_back(kv.second);
  double worst = 0;
  for (std::size_t i = 1; i + 1 < v.size(); ++i)
    worst = std::max(worst, std::abs(v[i] - 0.5 * (v[i - 1] + v[i + 1])) / p0);
  return worst;
}

struct MandelErrors {
  double centre = 0, peak = 0, peak_exact = 0, checker = 0;
  hmpm::RunResult result;
};

MandelErrors run_qs_mandel(const QsMandel& c, double end_star, double sample_star,
                           double first_star = 1e-4) {
  hmpm::Problem p = qs_mandel(c);
  p.time.end = c.time_of(end_star);
  p.time.growth = hmpm::StepGrowth{c.time_of(first_star), c.time_of(sample_star), 1.2};
  p.output.series_interval =
      first_star >= sample_star ? c.time_of(sample_star) : 0.0;  // 0: every step
  MandelErrors e;
  e.result = hmpm::run(p);
  EXPECT_EQ(e.result.status, hmpm::RunStatus::successful) << e.result.message;
  const hmpm::Series& s = e.result.series;
  const std::size_t np = s.particles.size();
  const closed_form::Mandel exact(c.nu, 0.5, c.a, c.c(), c.p0());
  for (std::size_t row = 1; row < s.time.size(); ++row) {
    const double t = s.time[row];
    const double pc = s.values[0][row * np + 0];  // particle 0: nearest the centre
    const double pe = exact.pressure(s.initial_positions[0][0], t);
    e.centre = std::max(e.centre, std::abs(pc - pe) / c.p0());
    e.peak = std::max(e.peak, pc);
    e.peak_exact = std::max(e.peak_exact, pe);
    e.checker = std::max(e.checker, checkerboard(s, row, c.p0(), c.a));
  }
  std::printf(
      "quasi-static mandel nu %.2f, stabilisation %.2g: max |p_c - exact|/p0 = %.4g, peak %.4f "
      "p0 (closed form %.4f), checkerboard %.3g; %lld steps, %lld solves\n",
      c.nu, c.stabilisation, e.centre, e.peak / c.p0(), e.peak_exact / c.p0(), e.checker,
      static_cast<long long>(e.result.steps), static_cast<long long>(e.result.iterations.solves));
  return e;
}

// Tolerances (issue 16): the centre pressure within 1 % of p0 over t* =
// 0.002 ... 0.5 (sampled every 0.002, which also brackets the peak at t* =
// 0.072 / 0.064 to better than 0.1 % of p0), the peak within 1 % of p0, no
// checkerboard (measure above below 1 %). Measured: 0.37 % / 0.35 %, peaks
// 1.1056 / 1.0751 p0 against 1.1068 / 1.0763 (verification §10), checkerboard
// 0.1 % (the boundary layer at the drained face at t* = 0.002 is inside
// x < a/2 only through the plate). 20 linear cells across a: the first-order
// time error with steps of 0.002 is 0.1 % over t* = 0.5.
TEST(QuasiStatic, MandelIncompressible) {
  for (double nu : {0.2, 0.3}) {
    QsMandel c;
    c.nu = nu;
    const MandelErrors e = run_qs_mandel(c, 0.5, 0.002);
    EXPECT_LT(e.centre, 0.01);
    EXPECT_NEAR(e.peak, e.peak_exact, 0.01 * c.p0());
    EXPECT_LT(e.checker, 0.01);
  }
}

// The checkerboard the stabilisation removes: one step of t* = 1e-6 from
// rest (the undrained limit, where the flow term that otherwise couples the
// pressures is 1e-6 of the rest and equal-order pressure with Q = 0 violates
// the inf-sup condition), on a taller specimen (10 rows) so the interior has
// room for the mode. Measure: max |p_i - (p_{i-1} + p_{i+1})/2| / p0 along
// the lowest particle row over x < a/2, where the exact pressure is p0.
// Measured: 0.25 without the projection term, 4e-7 with it; the centre
// pressure then equals p0 within 0.5 %.
TEST(QuasiStatic, MandelCheckerboardWithoutStabilisation) {
  QsMandel c;
  c.rows = 10;
  c.stabilisation = 0.0;
  const MandelErrors off = run_qs_mandel(c, 1e-6, 1e-6, 1e-6);
  c.stabilisation = 1.0;
  const MandelErrors on = run_qs_mandel(c, 1e-6, 1e-6, 1e-6);
  EXPECT_GT(off.checker, 0.05);
  EXPECT_LT(on.checker, 1e-3);
  EXPECT_LT(on.centre, 0.01);
}

// ------------------------------------------------------------------ failure
// A tolerance below round-off cannot be met: every step is cut back
// max_cutbacks times, then the run fails naming the step, the residual
// reached and what to change.
TEST(QuasiStatic, UnconvergedRunFailsWithStepResidualAndAdvice) {
  ClayCase c;
  hmpm::Problem p = clay(c, c.time_of(0.1));
  p.time.implicit.tolerance = 1e-300;
  p.time.implicit.max_iterations = 3;
  p.time.implicit.max_cutbacks = 2;
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  std::printf("%s\n", r.message.c_str());
  EXPECT_NE(r.message.find("step 1 "), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("did not converge in 3 iterations after 2 cut-backs"), std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("residual reached"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("time.implicit.tolerance"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("smaller step"), std::string::npos) << r.message;
  EXPECT_EQ(r.iterations.cutbacks, 2);
  EXPECT_EQ(r.iterations.solves, 9);  // 3 attempts of 3 iterations
}

// ------------------------------------------------------------------ large deformation
// Self-weight consolidation of a very soft 5 m column (E_oed = E = 160 kPa,
// a weightless pore fluid, see below), drained at the fixed
// base, starting from zero effective stress (the water carries the weight
// at t = 0+). The scheme's stress update adds D : sym(grad du) with the
// gradient on the configuration at the start of each step (plus the
// Jaumann spin, zero in uniaxial strain), which for small steps integrates
// to sigma' = E_oed ln(dx/dX) in uniaxial strain: a Hencky-elastic skeleton
// under Cauchy stress. The drained state of the final geometry: p = 0 and
// sigma'(X) = -gamma0 (H - X) (gamma0 = rho0 g, the weight per reference
// volume: mass is conserved), so dx/dX = exp(-gamma0 (H - X)/E) and
//   x(X) = (E/gamma0) [exp(-gamma0 (H - X)/E) - exp(-gamma0 H/E)],
// a settlement of 1 - (E/(gamma0 H))(1 - exp(-gamma0 H/E)) = 17.6 % of H.
// The fluid density is 1e-3 kg/m3 (k scaled to keep k/gamma_w), so the
// pore pressure is the excess one and vanishes at the drained state; with
// real water a hydrostatic part would be added. Quadratic B-splines: with
// linear shape functions the particles crossing cells (here by up to 7
// cells) leave cells whose particles carry different stress histories but
// get equal strains, a noise linear MPM cannot remove (docs/schemes.md).
TEST(QuasiStatic, LargeSettlementEndsDrainedAndConservesSolidMass) {
  const int cells = 40, ppc = 2;
  const double H = 5.0, E = 1.6e5, porosity = 0.5, rho_s = 2650, g = 9.81;
  const double rho0 = (1 - porosity) * rho_s, gamma0 = rho0 * g;
  const double k_over_gamma = 1e-9 / (1000.0 * 9.81);
  const double cv = k_over_gamma * E;
  hmpm::Problem p = problems::column(1, 0, H, cells, ppc);
  p.shape_function = hmpm::ShapeFunction::bspline;
  hmpm::Material m;
  m.name = "very soft clay";
  m.density = rho_s;
  m.youngs_modulus = E;
  m.poisson_ratio = 0.0;
  m.hydraulic = hmpm::Hydraulic{porosity, k_over_gamma * 1e-3 * 9.81, 2.2e9, 1e-3, inf};
  p.materials.push_back(m);
  p.gravity = {-g, 0, 0};
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, 0.0), 0.0));
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 5.0 * H * H / cv;
  p.time.growth = hmpm::StepGrowth{1e-4 * H * H / cv, 0.02 * H * H / cv, 1.1};
  p.output.snapshot_interval = p.time.end;
  p.output.snapshot_fields = {hmpm::Field::position, hmpm::Field::pore_pressure,
                              hmpm::Field::effective_stress, hmpm::Field::porosity};
  std::vector<hmpm::Snapshot> snaps;
  hmpm::RunOptions options;
  options.on_snapshot = [&](const hmpm::Snapshot& s) { snaps.push_back(s); };
  const hmpm::RunResult r = hmpm::run(p, options);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  ASSERT_EQ(snaps.size(), 2u);
  const hmpm::Snapshot &s0 = snaps.front(), &s1 = snaps.back();
  const std::size_t np = s0.volume.size();
  auto x_exact = [&](double X) {
    return E / gamma0 * (std::exp(-gamma0 * (H - X) / E) - std::exp(-gamma0 * H / E));
  };
  double solid0 = 0, solid1 = 0, max_p = 0, max_stress = 0, max_x = 0;
  const double settlement_exact = 1 - E / (gamma0 * H) * (1 - std::exp(-gamma0 * H / E));
  for (std::size_t i = 0; i < np; ++i) {
    solid0 += (1 - s0.porosity[i]) * s0.volume[i];
    solid1 += (1 - s1.porosity[i]) * s1.volume[i];
    const double X = s0.position[3 * i];
    max_p = std::max(max_p, std::abs(s1.pore_pressure[i]) / (gamma0 * H));
    max_stress = std::max(max_stress,
                          std::abs(s1.effective_stress[6 * i] + gamma0 * (H - X)) / (gamma0 * H));
    max_x = std::max(max_x, std::abs(s1.position[3 * i] - x_exact(X)) / (settlement_exact * H));
  }
  const double X_top = s0.position[3 * (np - 1)];
  const double settle = (X_top - s1.position[3 * (np - 1)]) / H;
  const double settle_exact = (X_top - x_exact(X_top)) / H;
  std::printf(
      "large settlement: top particle %.3f %% of H (exact %.3f %%); drained: max |p|/(gamma0 H) "
      "= %.3g, max |sigma' - exact|/(gamma0 H) = %.3g, max |x - x_exact| / settlement = %.3g; "
      "solid mass change %.3g; %lld steps, %lld solves\n",
      100 * settle, 100 * settle_exact, max_p, max_stress, max_x,
      std::abs(solid1 - solid0) / solid0, static_cast<long long>(r.steps),
      static_cast<long long>(r.iterations.solves));
  EXPECT_GT(settle, 0.10);
  EXPECT_LT(std::abs(solid1 - solid0) / solid0, 1e-13);
  EXPECT_LT(max_p, 1e-4);
  // Tolerances: the settlement within 3 % of the large-strain answer
  // (measured 2.7 %; 2.1 % with 80 cells, 1.6 % with 80 cells and 10x
  // smaller steps: the spatial error of the clamped B-splines at the base,
  // whose particle is over-compressed by 13 %, and the first-order geometry
  // update); the small-strain answer gamma0 H / (2 E) = 20 % of H is 12 %
  // away, so the test tells the two apart. Positions within 5 % of the
  // settlement everywhere (measured 2.7 %). Particle stresses carry a
  // cell-crossing noise (up to 0.4 gamma0 H at single particles) that the
  // positions, integrals of the strain, do not show: not asserted.
  EXPECT_NEAR(settle, settle_exact, 0.03 * settle_exact);
  EXPECT_LT(max_x, 0.05);
}

// ------------------------------------------------------------------ solvers, dimensions
// The iterative solver (BiCGSTAB + ILUT) solves the same saddle-point
// systems as the direct one: the Mandel history agrees to the linear
// tolerance (1e-12 relative, times the condition of the scaled system:
// 1e-6 p0 is a loose bound).
TEST(QuasiStatic, IterativeSolverMatchesDirect) {
  QsMandel c;
  hmpm::Problem p = qs_mandel(c);
  p.time.end = c.time_of(0.1);
  p.time.growth = hmpm::StepGrowth{c.time_of(1e-4), c.time_of(0.01), 1.2};
  p.output.series_interval = c.time_of(0.01);
  p.time.implicit.linear_solver = hmpm::LinearSolver::direct;
  const hmpm::RunResult direct = hmpm::run(p);
  p.time.implicit.linear_solver = hmpm::LinearSolver::iterative;
  const hmpm::RunResult iterative = hmpm::run(p);
  ASSERT_EQ(direct.status, hmpm::RunStatus::successful) << direct.message;
  ASSERT_EQ(iterative.status, hmpm::RunStatus::successful) << iterative.message;
  ASSERT_EQ(direct.series.values[0].size(), iterative.series.values[0].size());
  double worst = 0;
  for (std::size_t i = 0; i < direct.series.values[0].size(); ++i)
    worst = std::max(worst, std::abs(direct.series.values[0][i] - iterative.series.values[0][i]));
  std::printf(
      "direct vs iterative: max |dp| / p0 = %.3g; %lld BiCGSTAB iterations in %lld solves\n",
      worst / c.p0(), static_cast<long long>(iterative.iterations.linear),
      static_cast<long long>(iterative.iterations.solves));
  EXPECT_LT(worst, 1e-6 * c.p0());
  EXPECT_EQ(direct.iterations.linear, 0);
  EXPECT_GT(iterative.iterations.linear, 0);
}

// The same soft clay as a 2D and a 3D column (one cell across, roller
// walls) matches the 1D run: the stencil abstraction is generic. 20 cells
// (a smoke test; tolerances of the 1D case at 40 cells would be too tight):
// the errors against Terzaghi agree with 1D to 1e-3 q.
TEST(QuasiStatic, ColumnIn2DAnd3DMatches1D) {
  ClayCase c;
  c.cells = 20;
  c.growth_max_tv = 0.005;
  const ClayErrors one = run_clay(c);
  for (int dim : {2, 3}) {
    c.dim = dim;
    const ClayErrors e = run_clay(c);
    EXPECT_NEAR(e.pressure, one.pressure, 1e-3) << dim << "D";
    EXPECT_NEAR(e.degree, one.degree, 1e-3) << dim << "D";
    EXPECT_LT(e.pressure, 0.02) << dim << "D";
  }
}

// ------------------------------------------------------------------ plasticity
// Quadratic convergence: r_{i+1} <= C r_i^2 in the asymptotic range. The
// largest r_{i+1} / r_i^2 over the iterations with r_i < 0.1 whose next
// residual is above the round-off floor (1e-10: the residuals are relative
// to the force scale, and the last iterate of a converged step often lands
// there, where the ratio means nothing); -1 when no iteration qualifies
// (Newton ended in the iteration after the active set was found, as it
// does for a piecewise-linear problem). Linear convergence r_{i+1} = rho r_i
// gives C = rho / r_i, which grows without bound along the sequence.
double quadratic_constant(const std::vector<double>& r) {
  double c = -1.0;
  for (std::size_t i = 0; i + 1 < r.size(); ++i)
    if (r[i] < 0.1 && r[i + 1] > 1e-10) c = std::max(c, r[i + 1] / (r[i] * r[i]));
  return c;
}

// A dry Mohr-Coulomb oedometer (phi = 30 deg, c = 0, psi = 0, nu = 0.1):
// the elastic at-rest ratio nu/(1-nu) = 0.11 is below the active ratio
// Ka = (1 - sin phi)/(1 + sin phi) = 1/3, so the loaded column yields and
// ends at sigma_v = -q (equilibrium) and sigma_h = Ka sigma_v (on the
// triaxial-compression corner of the yield surface). Newton with the
// algorithmic tangent converges quadratically at plastic points; with the
// elastic one (time.implicit.elastic_tangent) linearly.
hmpm::RunResult mohr_coulomb_oedometer(bool elastic_tangent) {
  hmpm::Problem p = problems::column(1, 0, 1.0, 10, 2);
  hmpm::Material m;
  m.name = "sand";
  m.density = 2000;
  m.youngs_modulus = 10e6;
  m.poisson_ratio = 0.1;
  m.plasticity = hmpm::MohrCoulomb{30.0, 0.0, 0.0, 0.0};
  p.materials.push_back(m);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  const double q = 1e5;
  hmpm::Traction t;
  t.particles.min = {1.0 - 0.05, 0, 0};
  t.particles.max = {1.0, 1, 1};
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [q](double time) { return -q * std::min(1.0, time); };  // ramp over 1 s
  p.tractions.push_back(t);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 2.0;
  p.time.dt = 0.1;
  p.time.implicit.max_iterations = 60;
  p.time.implicit.elastic_tangent = elastic_tangent;
  p.output.series_particles = {0, 5, 10, 15, 17};  // below the loaded top cell
  p.output.series_fields = {hmpm::Field::effective_stress};
  return hmpm::run(p);
}

TEST(QuasiStatic, MohrCoulombOedometerReachesTheActiveRatio) {
  const hmpm::RunResult r = mohr_coulomb_oedometer(false);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const hmpm::RunResult re = mohr_coulomb_oedometer(true);
  ASSERT_EQ(re.status, hmpm::RunStatus::successful) << re.message;
  const hmpm::Series& s = r.series;
  const std::size_t last = s.time.size() - 1;
  const double q = 1e5;
  const double ka = (1 - std::sin(closed_form::pi / 6)) / (1 + std::sin(closed_form::pi / 6));
  double worst_v = 0, worst_h = 0, differ = 0;
  const std::size_t np = s.particles.size();
  for (std::size_t i = 0; i < np; ++i) {
    const double sv = s.values[0][(last * np + i) * 6 + 0],
                 sh = s.values[0][(last * np + i) * 6 + 1];
    worst_v = std::max(worst_v, std::abs(sv + q) / q);
    worst_h = std::max(worst_h, std::abs(sh - ka * sv) / q);
    for (int c = 0; c < 2; ++c) {
      const std::size_t k = (last * np + i) * 6 + static_cast<std::size_t>(c);
      differ = std::max(differ, std::abs(s.values[0][k] - re.series.values[0][k]) / q);
    }
  }
  std::printf(
      "Mohr-Coulomb oedometer: max |sigma_v + q|/q = %.3g, max |sigma_h - Ka sigma_v|/q = %.3g; "
      "algorithmic tangent: %lld Newton iterations in %lld steps (at most %d in one); elastic "
      "tangent: %lld (at most %d in one); |difference|/q = %.2g\n",
      worst_v, worst_h, static_cast<long long>(r.iterations.nonlinear),
      static_cast<long long>(r.steps), r.iterations.max_nonlinear,
      static_cast<long long>(re.iterations.nonlinear), re.iterations.max_nonlinear, differ);
  for (double v : r.iterations.worst_residuals) std::printf("  residual %.3e\n", v);
  // The vertical stress: -q up to the particle quadrature of compressed
  // cells (the particles fill 1 - eps of each cell, eps = 1 %, so nodal
  // equilibrium gives sigma = -q / (1 - eps)); 2 %. The top cell is left
  // out: the load lands inside it, at the particle's face, and splits
  // between its nodes. The yield condition (sigma_h = Ka sigma_v on the
  // triaxial-compression corner): to 1e-6 q (return mapping and Newton
  // tolerance).
  EXPECT_LT(worst_v, 0.02);
  EXPECT_LT(worst_h, 1e-6);
  // Both tangents solve the same equations: the same answer to the
  // Newton tolerance (1e-8 of the force scale).
  EXPECT_LT(differ, 1e-6);
  // Iterations per step (tolerance 1e-8), measured: 13 at most with the
  // elastic tangent, 2 with the algorithmic one (the 1D return onto the
  // corner is piecewise linear: exact once the active set is found). Bounds
  // with one iteration of margin.
  EXPECT_GT(re.iterations.max_nonlinear, 8);
  EXPECT_LE(r.iterations.max_nonlinear, 3);
}

// Plane-strain compression of a Mohr-Coulomb or Drucker-Prager block
// between smooth rigid plates under a lateral confining traction sigma_3:
// the vertical stress rises elastically and stays at the closed-form
// strength sigma_1 = sigma_3 Kp + 2 c sqrt(Kp), Kp = (1 + sin phi)/(1 -
// sin phi) (compression positive here). The state is homogeneous (linear
// velocity field, represented exactly by the grid's linear shape
// functions). Mohr-Coulomb with psi = 0: the plastic flow has no zz part,
// sigma_zz stays intermediate, and the plateau is exact. Drucker-Prager,
// plane-strain match, associated: the match is exact once the plastic zz
// strain rate vanishes, which the flow reaches asymptotically (sigma_zz
// settles), so the plateau approaches the same sigma_1.
struct BiaxialResult {
  hmpm::RunResult run;
  double s1 = 0, s3 = 0, spread = 0;  // mean vertical, lateral stress (compression +)
};

BiaxialResult biaxial(bool drucker_prager, bool elastic_tangent, int dim = 2,
                      const hmpm::RunOptions& options = {}, double tolerance = 1e-8) {
  hmpm::Problem p;
  p.dimension = dim;
  p.grid.min = {0, 0, 0};
  p.grid.max = {1.5, 1.0, 1.0};
  p.grid.cells = {3, 4, 1};
  hmpm::Body b;
  b.box.min = {0, 0, 0};
  b.box.max = {1.0, 1.0, 1.0};
  b.particles_per_cell = 2;
  const double s3 = 1e5, c = 1e4, phi = 30.0;
  for (int a = 0; a < 3; ++a)
    b.initial.effective_stress[a] = [s3](const hmpm::Vec3&) { return -s3; };
  p.bodies.push_back(b);
  hmpm::Material m;
  m.name = "dense sand";
  m.density = 2000;
  m.youngs_modulus = 1e9;
  m.poisson_ratio = 0.3;
  if (drucker_prager)
    m.plasticity = hmpm::DruckerPrager{phi, phi, c, 0.0};
  else
    m.plasticity = hmpm::MohrCoulomb{phi, 0.0, c, 0.0};
  p.materials.push_back(m);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));  // smooth
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 1, 0.0), 1));  // base
  if (dim == 3) {  // plane strain between smooth walls z = 0, 1
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 2, 0.0), 2));
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 2, 1.0), 2));
  }
  hmpm::Boundary top = problems::fixed_velocity(problems::plane(p, 1, 1.0), 1);
  top.velocity[1] = problems::constant(-0.001);  // 0.1 % vertical strain per second
  p.boundaries.push_back(top);
  hmpm::Traction t;
  t.particles.min = {1.0 - 0.25, 0, 0};
  t.particles.max = {1.0, 1.0, 1.0};
  t.axis = 0;
  t.side = +1;
  t.traction[0] = problems::constant(-s3);
  p.tractions.push_back(t);
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.time.end = 1.0;
  p.time.dt = 0.05;
  p.time.implicit.max_iterations = 200;
  p.time.implicit.elastic_tangent = elastic_tangent;
  p.time.implicit.tolerance = tolerance;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::effective_stress};
  BiaxialResult r;
  r.run = hmpm::run(p, options);
  if (r.run.status != hmpm::RunStatus::successful) return r;
  const hmpm::Series& s = r.run.series;
  const std::size_t last = s.time.size() - 1, np = s.particles.size();
  double lo = inf, hi = -inf;
  for (std::size_t i = 0; i < np; ++i) {
    const double v = -s.values[0][(last * np + i) * 6 + 1];
    r.s1 += v / static_cast<double>(np);
    r.s3 -= s.values[0][(last * np + i) * 6 + 0] / static_cast<double>(np);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  r.spread = hi - lo;
  return r;
}

TEST(QuasiStatic, PlaneStrainCompressionReachesTheClosedFormStrength) {
  const double phi = closed_form::pi / 6, c = 1e4, s3 = 1e5;
  const double kp = (1 + std::sin(phi)) / (1 - std::sin(phi));
  for (bool dp : {false, true}) {
    const BiaxialResult r = biaxial(dp, false);
    ASSERT_EQ(r.run.status, hmpm::RunStatus::successful) << r.run.message;
    const BiaxialResult re = biaxial(dp, true);
    ASSERT_EQ(re.run.status, hmpm::RunStatus::successful) << re.run.message;
    const double s1 = s3 * kp + 2 * c * std::sqrt(kp);
    const double s1_measured = r.s3 * kp + 2 * c * std::sqrt(kp);
    std::printf(
        "%s plane-strain compression: sigma_1 = %.6g Pa (closed form %.6g, with the measured "
        "sigma_3 = %.6g: %.6g), spread %.2g Pa; Newton iterations: algorithmic %lld (at most %d "
        "per step, r_i+1 / r_i^2 <= %.3g), elastic %lld (at most %d, r_i+1 / r_i^2 up to %.3g)\n",
        dp ? "Drucker-Prager" : "Mohr-Coulomb", r.s1, s1, r.s3, s1_measured, r.spread,
        static_cast<long long>(r.run.iterations.nonlinear), r.run.iterations.max_nonlinear,
        quadratic_constant(r.run.iterations.worst_residuals),
        static_cast<long long>(re.run.iterations.nonlinear), re.run.iterations.max_nonlinear,
        quadratic_constant(re.run.iterations.worst_residuals));
    for (double v : r.run.iterations.worst_residuals) std::printf("  residual %.3e\n", v);
    // The lateral stress: the dead load maps at the particle face, which
    // moves out by the lateral strain (0.1-0.3 %) into the next, empty
    // cell; the share of the load on that cell's inactive far node, delta /
    // h = 0.13 % (MC) and 0.5 % (DP, which dilates), is lost: 1 %.
    EXPECT_NEAR(r.s3, s3, 0.01 * s3);
    // The strength against the closed form with the nominal sigma_3: the
    // lateral loss times Kp = 3: 1.5 % (measured 0.12 % MC, 0.47 % DP).
    EXPECT_NEAR(r.s1, s1, 0.015 * s1);
    // Against the closed form with the lateral stress the block carries:
    // MC exact to the return's round-off (measured 2e-16); DP reaches its
    // plane-strain match as sigma_zz settles (measured 9e-8 after 0.1 %
    // strain): 1e-6.
    EXPECT_NEAR(r.s1, s1_measured, 1e-6 * s1);
    // Iterations per step, measured with the algorithmic tangent: MC 2
    // (piecewise linear: exact once the active set is found), DP 5; with
    // the elastic one MC 33, DP 131. One iteration of margin.
    EXPECT_LE(r.run.iterations.max_nonlinear, dp ? 6 : 3);
    EXPECT_GT(re.run.iterations.max_nonlinear, 20);
    // Quadratic convergence of the worst step: DP measured C = 20 on
    // residuals 1.6e-3 -> 4.1e-5 -> 3.3e-8; the elastic tangent's linear
    // rate gives C of order 1e7 and more.
    if (dp) {
      EXPECT_GT(quadratic_constant(r.run.iterations.worst_residuals), 0.0);
      EXPECT_LT(quadratic_constant(r.run.iterations.worst_residuals), 100.0);
    }
  }
  // The same Mohr-Coulomb test in 3D between smooth walls z = 0, 1 (the
  // tangent's six components): the closed form with the carried sigma_3 to
  // round-off, in as many iterations. The 2D answer to 1e-5 (measured
  // 3e-6): the dead load's face position uses the volume stretch to the
  // power 1/d, so the lost share of the lateral load differs slightly.
  const BiaxialResult r2 = biaxial(false, false), r3 = biaxial(false, false, 3);
  ASSERT_EQ(r3.run.status, hmpm::RunStatus::successful) << r3.run.message;
  std::printf(
      "Mohr-Coulomb plane-strain compression in 3D: sigma_1 = %.6g Pa (2D %.6g), at most "
      "%d Newton iterations per step\n",
      r3.s1, r2.s1, r3.run.iterations.max_nonlinear);
  EXPECT_NEAR(r3.s1, r3.s3 * kp + 2 * c * std::sqrt(kp), 1e-6 * r2.s1);
  EXPECT_NEAR(r3.s1, r2.s1, 1e-5 * r2.s1);
  EXPECT_LE(r3.run.iterations.max_nonlinear, 3);
}

// ------------------------------------------------------------------ threads
// The assembly and the particle update run on the solver threads (issue
// 16): each thread sums its chunk of particles into private copies of the
// residual and the matrix values, added in thread order. Two runs at 2
// threads are identical; 1 and 2 threads differ only in the order of the
// sums, round-off (1e-16 per operation) that the converged Newton steps do
// not amplify: 1e-12 of the largest value over the whole history. Mandel
// (u-p coupling, stabilisation, tied plate) and the Drucker-Prager
// plane-strain compression (algorithmic tangents at plastic points). The
// iterations stop anywhere below the Newton tolerance, so two round-off
// paths agree only to about it: the compression runs at tolerance 1e-12
// (at the default 1e-8 measured 7e-11; Mandel is linear, one iteration).
double history_difference(const hmpm::RunResult& a, const hmpm::RunResult& b) {
  EXPECT_EQ(a.status, hmpm::RunStatus::successful) << a.message;
  EXPECT_EQ(b.status, hmpm::RunStatus::successful) << b.message;
  EXPECT_EQ(a.series.values[0].size(), b.series.values[0].size());
  if (a.series.values[0].size() != b.series.values[0].size()) return inf;
  double worst = 0, scale = 0;
  for (std::size_t i = 0; i < a.series.values[0].size(); ++i) {
    worst = std::max(worst, std::abs(a.series.values[0][i] - b.series.values[0][i]));
    scale = std::max(scale, std::abs(a.series.values[0][i]));
  }
  return scale > 0 ? worst / scale : worst;
}

TEST(QuasiStatic, ThreadsAgree) {
  hmpm::RunOptions one, two;
  two.threads = 2;
  two.min_particles_per_thread = 1;
  QsMandel c;
  hmpm::Problem p = qs_mandel(c);
  p.time.end = c.time_of(0.05);
  p.time.growth = hmpm::StepGrowth{c.time_of(1e-4), c.time_of(0.01), 1.5};
  const hmpm::RunResult m1 = hmpm::run(p, one), m2 = hmpm::run(p, two), m2b = hmpm::run(p, two);
  EXPECT_EQ(m1.threads, 1);
  EXPECT_EQ(m2.threads, 2);
  const double dm = history_difference(m1, m2);
  EXPECT_EQ(history_difference(m2, m2b), 0.0);
  const BiaxialResult b1 = biaxial(true, false, 2, one, 1e-12),
                      b2 = biaxial(true, false, 2, two, 1e-12),
                      b2b = biaxial(true, false, 2, two, 1e-12);
  EXPECT_EQ(b2.run.threads, 2);
  const double db = history_difference(b1.run, b2.run);
  EXPECT_EQ(history_difference(b2.run, b2b.run), 0.0);
  std::printf("threads 1 vs 2: Mandel %.3g, Drucker-Prager compression %.3g (relative)\n", dm, db);
  EXPECT_LT(dm, 1e-12);
  EXPECT_LT(db, 1e-12);
  EXPECT_EQ(b1.run.iterations.nonlinear, b2.run.iterations.nonlinear);
}

// ------------------------------------------------------------------ step plans
// The three plans: a fixed dt (fixed steps, ceil(end/dt) of them), growth,
// and automatic (dt0 = 0.1 h^2/c_v, growth 1.2 up to end/20). Varying steps
// land on the output instants, and the step estimate is the plan's count
// (the landings add at most one step per output instant).
TEST(QuasiStatic, StepPlansAndOutputLandings) {
  ClayCase c;
  hmpm::Problem p = clay(c, c.time_of(1.0));
  p.output.series_interval = c.time_of(0.1);
  p.time.growth.reset();
  const hmpm::StableStep automatic = hmpm::stable_step(p);
  EXPECT_FALSE(automatic.fixed);
  const double h = c.H / c.cells;
  EXPECT_NEAR(automatic.chosen, 0.1 * h * h / c.cv(), 1e-9 * automatic.chosen);
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_GE(r.steps, automatic.steps);
  EXPECT_LE(r.steps, automatic.steps + 10);  // 10 output instants
  ASSERT_EQ(r.series.time.size(), 11u);
  for (std::size_t row = 0; row < r.series.time.size(); ++row)
    EXPECT_NEAR(r.series.time[row], static_cast<double>(row) * c.time_of(0.1),
                1e-9 * c.time_of(1.0));
  std::printf("automatic plan: dt0 = %.3g s, estimate %lld steps, ran %lld\n", automatic.chosen,
              static_cast<long long>(automatic.steps), static_cast<long long>(r.steps));
  p.time.dt = c.time_of(0.03);
  const hmpm::StableStep fixed = hmpm::stable_step(p);
  EXPECT_TRUE(fixed.fixed);
  EXPECT_EQ(fixed.steps, 34);  // ceil(1 / 0.03)
  const hmpm::RunResult rf = hmpm::run(p);
  ASSERT_EQ(rf.status, hmpm::RunStatus::successful) << rf.message;
  EXPECT_EQ(rf.steps, 34);
  // A fixed dt together with a growth object is refused.
  p.time.growth = hmpm::StepGrowth{1.0, 2.0, 1.1};
  const auto issues = hmpm::check_problem(p);
  bool named = false;
  for (const auto& i : issues) named = named || i.message.find("keep one") != std::string::npos;
  EXPECT_TRUE(named);
}
