// The semi-implicit scheme (time.scheme = "semi_implicit"): Terzaghi's
// consolidation with real water (verification §9) at a time step far above
// the explicit limit, against the closed form; agreement with the explicit
// scheme on a softened fluid; 2D and the other shape functions; the
// scheme's stable-step rule and its refusal of a dt above it.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

struct Column {
  int dim = 1;
  int axis = 0;  // vertical axis; base at 0, drained top at H
  double H = 1.0;
  int cells = 40;
  int ppc = 2;
  int across = 1;  // cells across the column (GIMP and B-splines need 2 or more)
  // Verification §9: real water.
  double porosity = 0.3, rho_s = 2650, E = 10e6, nu = 0.0, kw = 2.2e9, q = 1e4, k = 1e-3;
  hmpm::Scheme scheme = hmpm::Scheme::semi_implicit;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  hmpm::LinearSolver solver = hmpm::LinearSolver::automatic;
  double m_v() const { return (1 + nu) * (1 - 2 * nu) / (E * (1 - nu)); }
  double cv() const { return k / (1000.0 * 9.81 * (m_v() + porosity / kw)); }
  double time_of(double tv) const { return tv * H * H / cv(); }
};

hmpm::Problem terzaghi(const Column& c, double end) {
  hmpm::Problem p = problems::column(c.dim, c.axis, c.H, c.cells, c.ppc);
  for (int a = 0; a < c.dim; ++a) {
    if (a == c.axis) continue;
    p.grid.cells[a] = c.across;
    p.grid.max[a] = c.across * c.H / c.cells;
  }
  p.bodies[0].box.max = p.grid.max;
  p.shape_function = c.shape;
  p.materials.push_back(problems::saturated_elastic(c.rho_s, c.E, c.nu, c.porosity, c.k, c.kw));
  problems::load_consolidation(p, c.axis, c.H, c.cells, c.ppc, c.q, c.H);
  p.time.end = end;
  p.time.scheme = c.scheme;
  p.time.implicit.linear_solver = c.solver;
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure};
  return p;
}

struct Samples {
  std::vector<double> tv;
  std::vector<std::vector<double>> z;  ///< per row: depth below the drained top
  std::vector<std::vector<double>> p;  ///< per row: pore pressure
  hmpm::RunResult result;
  double seconds = 0;
};

// Runs to T_v = targets.back(), sampling every `interval` in T_v, and keeps
// the rows at the targets.
Samples run_column(const Column& c, const std::vector<double>& targets, double interval) {
  hmpm::Problem p = terzaghi(c, c.time_of(targets.back()));
  p.output.series_interval = c.time_of(interval);
  const auto start = std::chrono::steady_clock::now();
  Samples out;
  out.result = hmpm::run(p);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(out.result.status, hmpm::RunStatus::successful) << out.result.message;
  const hmpm::Series& s = out.result.series;
  const std::size_t np = s.particles.size();
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    const double tv = s.time[row] / c.time_of(1.0);
    bool wanted = false;
    for (double target : targets) wanted = wanted || std::abs(tv - target) < 0.02 * target;
    if (!wanted) continue;
    out.tv.push_back(tv);
    out.z.emplace_back();
    out.p.emplace_back();
    for (std::size_t i = 0; i < np; ++i) {
      out.z.back().push_back(c.H - s.initial_positions[i][c.axis]);
      out.p.back().push_back(s.values[0][row * np + i]);
    }
  }
  return out;
}

/// Largest |p - p_exact| / q over the sampled rows and the particles deeper
/// than `skin` below the drained top (the interior).
double max_error(const Column& c, const Samples& s, double skin) {
  double e = 0;
  for (std::size_t r = 0; r < s.tv.size(); ++r)
    for (std::size_t i = 0; i < s.z[r].size(); ++i) {
      if (s.z[r][i] < skin) continue;
      const double pe = closed_form::terzaghi_pressure(s.z[r][i], s.tv[r], c.H, c.q);
      e = std::max(e, std::abs(s.p[r][i] - pe) / c.q);
    }
  return e;
}

double explicit_limit(const Column& c) {
  Column e = c;
  e.scheme = hmpm::Scheme::explicit_scheme;
  return hmpm::stable_step(terzaghi(e, 1.0)).limit;
}

const std::vector<double> tv_targets = {0.1, 0.2, 0.5, 1.0};

}  // namespace

// Verification §9, real water. The interior is every particle below the
// first cell under the drained face (z > h), where at T_v = 0.1 the
// pressure drops from 0 to 0.25 q within one cell: that cell belongs to the
// boundary layer, not the interior. Tolerance 1 % of q (issue 16).
TEST(SemiImplicit, TerzaghiRealWaterAtTwentyTimesTheExplicitStep) {
  Column c;
  const double limit = explicit_limit(c);
  const hmpm::StableStep semi = hmpm::stable_step(terzaghi(c, 1.0));
  // The explicit limit is the hydraulic diffusion one (about 4e-7 s at
  // h = 0.025 m); the semi-implicit run uses Courant 0.5 on the skeleton's
  // wave: hundreds of times more.
  const double ratio = semi.chosen / limit;
  std::printf("semi_implicit dt = %.4g s, explicit limit = %.4g s, ratio %.1f\n", semi.chosen,
              limit, ratio);
  EXPECT_GE(ratio, 20.0);
  const Samples s = run_column(c, tv_targets, 0.1);
  ASSERT_EQ(s.tv.size(), tv_targets.size());
  EXPECT_DOUBLE_EQ(s.result.dt, semi.chosen);
  const double e = max_error(c, s, c.H / c.cells);
  std::printf(
      "real water, %d cells: max |p - p_exact|/q = %.4g (interior), %lld steps, "
      "%lld solves, %.2f s\n",
      c.cells, e, static_cast<long long>(s.result.steps),
      static_cast<long long>(s.result.iterations.solves), s.seconds);
  EXPECT_LT(e, 0.01);
  EXPECT_EQ(s.result.iterations.solves, s.result.steps);
  EXPECT_EQ(s.result.scheme, "semi_implicit");
}

// One particle per cell (2 per cell elsewhere), 20 and 40 cells: the case
// where the flux of the plain nodal predicted velocity, instead of the
// re-mapped one, left 1.0 % and 1.5 % next to the drained face. 1 % of q,
// and the finer grid smaller or within it.
TEST(SemiImplicit, TerzaghiRealWaterOneParticlePerCell) {
  std::vector<double> errors;
  for (int cells : {20, 40}) {
    Column c;
    c.cells = cells;
    c.ppc = 1;
    const Samples s = run_column(c, tv_targets, 0.1);
    errors.push_back(max_error(c, s, c.H / c.cells));
    std::printf("real water, 1 ppc, %d cells: max error %.4g of q\n", cells, errors.back());
  }
  EXPECT_LT(errors[0], 0.01);
  EXPECT_TRUE(errors[1] < errors[0] || errors[1] < 0.01);
  EXPECT_LT(errors[1], 0.01);
}

// Refinement: 20 and 40 cells (the same dt ratio: the step scales with h).
// The error at 40 cells must be below the error at 20 cells or within the
// 1 % tolerance.
TEST(SemiImplicit, TerzaghiRealWaterConvergesUnderRefinement) {
  std::vector<double> errors;
  for (int cells : {20, 40}) {
    Column c;
    c.cells = cells;
    const Samples s = run_column(c, tv_targets, 0.1);
    errors.push_back(max_error(c, s, c.H / c.cells));
    std::printf("real water, %d cells: max error %.4g of q\n", cells, errors.back());
  }
  EXPECT_TRUE(errors[1] < errors[0] || errors[1] < 0.01);
  EXPECT_LT(errors[1], 0.01);
}

// Largest difference / q between two runs of the same column (the same
// particles and sampled rows), interior particles only. The runs' rows lie
// up to a step apart in time; the closed form's change over that interval
// is removed (the difference of their errors), so a time shift of the
// sampling does not count as disagreement.
double max_difference(const Column& c, const Samples& a, const Samples& b, double skin) {
  double d = 0;
  EXPECT_EQ(a.tv.size(), b.tv.size());
  for (std::size_t r = 0; r < std::min(a.tv.size(), b.tv.size()); ++r)
    for (std::size_t i = 0; i < a.z[r].size(); ++i) {
      if (a.z[r][i] < skin) continue;
      const double shift = closed_form::terzaghi_pressure(a.z[r][i], a.tv[r], c.H, c.q) -
                           closed_form::terzaghi_pressure(a.z[r][i], b.tv[r], c.H, c.q);
      d = std::max(d, std::abs(a.p[r][i] - b.p[r][i] - shift) / c.q);
    }
  return d;
}

// The same spec with a softened fluid (Kw = 75 MPa, k = 1e-4 m/s: explicit
// runs in 7e4 steps, inertia number 2 % at T_v = 0.05) run explicit and
// semi_implicit, 20 cells. The semi-implicit solution lies within the
// explicit one's error band around the closed form (err_semi < err_expl;
// measured 0.090 % against 0.143 %), and the two differ by less than 1.5x
// the explicit error (measured 0.15 %, 1.06x: the errors differ in origin,
// the explicit's from undamped pressure waves, the semi-implicit's from the
// damped projection, so they partly add). The rows lie up to a step
// apart; max_difference removes the closed form's change between them.
TEST(SemiImplicit, AgreesWithExplicitOnSoftenedFluid) {
  Column c;
  c.cells = 20;
  c.kw = 75e6;
  c.k = 1e-4;
  const std::vector<double> targets = {0.1, 0.2, 0.5};
  const Samples semi = run_column(c, targets, 0.1);
  Column e = c;
  e.scheme = hmpm::Scheme::explicit_scheme;
  const Samples expl = run_column(e, targets, 0.1);
  const double skin = c.H / c.cells;
  const double err_semi = max_error(c, semi, skin), err_expl = max_error(e, expl, skin);
  const double diff = max_difference(c, semi, expl, skin);
  std::printf(
      "softened fluid: explicit error %.4g (%lld steps), semi_implicit error %.4g "
      "(%lld steps), difference %.4g\n",
      err_expl, static_cast<long long>(expl.result.steps), err_semi,
      static_cast<long long>(semi.result.steps), diff);
  EXPECT_LT(err_semi, err_expl);
  EXPECT_LT(diff, 1.5 * err_expl);
}

// 2D: the real-water column standing along y (roller walls), nu = 0.25,
// 2 x 2 particles per cell, linear shape functions: the 1D tolerance, 1 %
// of q (the same boundary layer and lumped storage; the 2D stencil adds no
// error to a 1D field).
TEST(SemiImplicit, TerzaghiRealWaterIn2D) {
  Column c;
  c.dim = 2;
  c.axis = 1;
  c.cells = 20;
  c.nu = 0.25;
  const Samples s = run_column(c, tv_targets, 0.1);
  ASSERT_EQ(s.tv.size(), tv_targets.size());
  const double e = max_error(c, s, c.H / c.cells);
  std::printf("2D: max error %.4g of q, %lld steps, %.2f s\n", e,
              static_cast<long long>(s.result.steps), s.seconds);
  EXPECT_LT(e, 0.01);
}

// GIMP and the clamped B-spline: both schemes on the softened column of
// AgreesWithExplicitOnSoftenedFluid (1D, 2 particles per cell). These
// shape functions err by several per cent of q next to the fixed base and
// the drained face (measured: GIMP 6.9 %, B-spline 3.4 % explicit; the
// clamped B-spline's boundary error, docs/verification.md), an error of
// the shape function, not of the scheme: the semi-implicit error must not
// exceed the explicit one by more than 0.2 % of q (measured: below it).
TEST(SemiImplicit, OtherShapeFunctionsMatchTheExplicitError) {
  for (auto shape : {hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline}) {
    Column c;
    c.cells = 20;
    c.kw = 75e6;
    c.k = 1e-4;
    c.shape = shape;
    const std::vector<double> targets = {0.1, 0.2, 0.5};
    const Samples semi = run_column(c, targets, 0.1);
    Column e = c;
    e.scheme = hmpm::Scheme::explicit_scheme;
    const Samples expl = run_column(e, targets, 0.1);
    const double err_semi = max_error(c, semi, c.H / c.cells);
    const double err_expl = max_error(e, expl, c.H / c.cells);
    std::printf("shape %d: semi_implicit error %.4g (%.2f s), explicit %.4g (%.2f s)\n",
                static_cast<int>(shape), err_semi, semi.seconds, err_expl, expl.seconds);
    EXPECT_LT(err_semi, err_expl + 0.002);
  }
}

// 3D: the column along z, 20 cells, one particle per cell.
TEST(SemiImplicit, TerzaghiRealWaterIn3D) {
  Column c;
  c.dim = 3;
  c.axis = 2;
  c.cells = 20;
  c.ppc = 1;
  const Samples s = run_column(c, tv_targets, 0.1);
  ASSERT_EQ(s.tv.size(), tv_targets.size());
  const double e = max_error(c, s, c.H / c.cells);
  std::printf("3D: max error %.4g of q\n", e);
  EXPECT_LT(e, 0.01);
}

// Direct (sparse LDL^T) and iterative (conjugate gradients with incomplete
// Cholesky, relative residual 1e-12) solves give the same pressures (to
// 1e-6 q, far above the iterative tolerance times the condition number's
// effect on a smooth field) and the iterations are counted.
TEST(SemiImplicit, DirectAndIterativeSolversAgree) {
  Column c;
  c.dim = 2;
  c.axis = 1;
  c.cells = 20;
  c.across = 4;  // wide enough for the incomplete Cholesky factor to drop fill
  const std::vector<double> targets = {0.1, 0.2};
  c.solver = hmpm::LinearSolver::direct;
  const Samples d = run_column(c, targets, 0.1);
  c.solver = hmpm::LinearSolver::iterative;
  const Samples it = run_column(c, targets, 0.1);
  EXPECT_EQ(d.result.iterations.linear, 0);
  EXPECT_GT(it.result.iterations.linear, 0);
  EXPECT_EQ(it.result.iterations.solves, it.result.steps);
  std::printf("direct %.3f s, iterative %.3f s (%.2f iterations per solve)\n", d.seconds,
              it.seconds,
              static_cast<double>(it.result.iterations.linear) /
                  static_cast<double>(it.result.iterations.solves));
  EXPECT_LT(max_difference(c, d, it, 0.0), 1e-6);
}

// The Laplacian's assembly runs on the solver threads like the explicit
// phases (private boxes per thread, added in thread order; issue 16): two
// runs at 2 threads are identical, 1 and 2 threads differ only in the
// order of the sums, round-off (1e-16 per operation) that the stable,
// linear step does not amplify: 1e-12 of q over the history. A 2D column
// four cells wide (the threads' bands share nodes).
TEST(SemiImplicit, ThreadsAgree) {
  Column c;
  c.dim = 2;
  c.axis = 1;
  c.cells = 20;
  c.across = 4;
  hmpm::Problem p = terzaghi(c, c.time_of(0.05));
  p.output.series_interval = c.time_of(0.01);
  hmpm::RunOptions two;
  two.threads = 2;
  two.min_particles_per_thread = 1;
  const hmpm::RunResult r1 = hmpm::run(p), r2 = hmpm::run(p, two), r2b = hmpm::run(p, two);
  for (const hmpm::RunResult* r : {&r1, &r2, &r2b})
    ASSERT_EQ(r->status, hmpm::RunStatus::successful) << r->message;
  EXPECT_EQ(r1.threads, 1);
  EXPECT_EQ(r2.threads, 2);
  ASSERT_EQ(r1.series.values[0].size(), r2.series.values[0].size());
  ASSERT_GT(r1.series.values[0].size(), 0u);
  double worst = 0;
  for (std::size_t i = 0; i < r1.series.values[0].size(); ++i) {
    worst = std::max(worst, std::abs(r1.series.values[0][i] - r2.series.values[0][i]));
    EXPECT_EQ(r2.series.values[0][i], r2b.series.values[0][i]) << i;
  }
  std::printf("threads 1 vs 2: max |dp| / q = %.3g over %lld steps\n", worst / c.q,
              static_cast<long long>(r1.steps));
  EXPECT_LT(worst, 1e-12 * c.q);
}

// check_problem refuses a user dt above the semi-implicit limit, naming the
// limit; a dt between the explicit and the semi-implicit limits is fine.
TEST(SemiImplicit, RefusesADtAboveItsLimit) {
  Column c;
  hmpm::Problem p = terzaghi(c, 0.01);
  const hmpm::StableStep s = hmpm::stable_step(p);
  // drained P-wave speed sqrt(E_oed / rho_mix), rho_mix = 0.7 * 2650 + 300
  EXPECT_NEAR(s.wave_speed, std::sqrt(10e6 / 2155.0), 1e-9 * s.wave_speed);
  EXPECT_NEAR(s.limit, (1.0 / 40) / s.wave_speed, 1e-12);
  EXPECT_TRUE(std::isinf(s.hydraulic));
  p.time.dt = 100 * explicit_limit(c);
  ASSERT_LT(*p.time.dt, s.limit);
  EXPECT_TRUE(hmpm::check_problem(p).empty());
  p.time.dt = 1.5 * s.limit;
  const std::vector<hmpm::ProblemIssue> issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.parts, (std::vector<std::string>{"time", "dt"}));
  EXPECT_NE(issues[0].message.find("semi_implicit stable limit 0.000367"), std::string::npos)
      << issues[0].message;
}

// Stability where the Darcy terms dominate the pressure matrix: k = 1 m/s
// (dt k/gw = 1e3 times dt^2/rho), 53 534 steps at the automatic step, to
// T_v = 2e4. The load passes to the skeleton within a few steps and sets
// the column ringing (Darcy's rho_f a then makes a dynamic pressure of the
// order of q, physical), which the relative flow damps; a growing mode
// would show against the closed form's p = 0 at T_v = 1e4 and 2e4
// (measured 4.3e-5 q; asserted 1e-3 q).
TEST(SemiImplicit, StableWhenDarcyDominates) {
  Column c;
  c.cells = 20;
  c.k = 1.0;
  const Samples s = run_column(c, {1e4, 2e4}, 1e4);
  ASSERT_EQ(s.tv.size(), 2u);
  const double e = max_error(c, s, 0.0);
  std::printf("k = 1 m/s: max |p - p_exact|/q at T_v = 1e4, 2e4: %.3g (%lld steps, %.2f s)\n", e,
              static_cast<long long>(s.result.steps), s.seconds);
  EXPECT_LT(e, 1e-3);
}

// A run whose state becomes non-finite fails at that step with a message
// saying what to change (here a load that turns NaN at t = 0.01 s: the
// predicted velocity, hence the pressure system's right-hand side, is
// non-finite, and the step reports it before solving or moving anything).
namespace {

// The Terzaghi column `c` whose load becomes `late` after t = 0.01 s.
hmpm::Problem column_loaded_late(const Column& c, double late) {
  hmpm::Problem p = terzaghi(c, 0.02);
  const double q = c.q;
  p.tractions[0].traction[c.axis] = [q, late](double t) { return t > 0.01 ? late : -q; };
  return p;
}

}  // namespace

// A NaN load is reported as the formula's (the time loop checks load and
// boundary values before each step), never as a diverged state.
TEST(SemiImplicit, NaNLoadFailsNamingTheFormula) {
  Column c;
  c.cells = 20;
  const hmpm::RunResult r =
      hmpm::run(column_loaded_late(c, std::numeric_limits<double>::quiet_NaN()));
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  const std::string formula = "/tractions/0/traction/" + std::to_string(c.axis);
  EXPECT_NE(r.message.find("the formula at " + formula + " gave NaN at t = 0.01"),
            std::string::npos)
      << r.message;
  EXPECT_EQ(r.message.find("reduce time.dt"), std::string::npos) << r.message;
}

TEST(SemiImplicit, NonFiniteStateFailsWithWhatToChange) {
  Column c;
  c.cells = 20;
  // Finite, but so large that the state overflows.
  const hmpm::RunResult r = hmpm::run(column_loaded_late(c, -std::numeric_limits<double>::max()));
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  EXPECT_NE(r.message.find("became non-finite: the run diverged"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("What to change: reduce time.dt or time.courant"), std::string::npos)
      << r.message;
  std::printf("%s\n", r.message.c_str());
}

// Not a test: direct against iterative solves on larger grids (docs/schemes.md).
// Run with --gtest_also_run_disabled_tests --gtest_filter='*Benchmark*'.
TEST(SemiImplicit, DISABLED_BenchmarkLinearSolvers) {
  struct Case {
    int dim, cells, across;
  };
  for (const Case k : {Case{1, 4000, 1}, Case{2, 100, 100}, Case{2, 200, 200}, Case{3, 20, 20}}) {
    for (auto solver : {hmpm::LinearSolver::direct, hmpm::LinearSolver::iterative}) {
      Column c;
      c.dim = k.dim;
      c.axis = k.dim - 1;
      c.cells = k.cells;
      c.across = k.across;
      c.ppc = 1;
      c.solver = solver;
      hmpm::Problem p = terzaghi(c, 1.0);
      p.output.series_particles.clear();
      p.time.end = 20 * hmpm::stable_step(p).chosen;  // 20 steps
      const auto start = std::chrono::steady_clock::now();
      const hmpm::RunResult r = hmpm::run(p);
      const double sec =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
      std::printf(
          "dim %d, %lld nodes, %s: %.4f s per step, %.1f CG iterations per solve\n", k.dim,
          static_cast<long long>(r.nodes),
          solver == hmpm::LinearSolver::direct ? "direct" : "iterative",
          sec / static_cast<double>(r.steps),
          static_cast<double>(r.iterations.linear) / static_cast<double>(r.iterations.solves));
    }
  }
}
