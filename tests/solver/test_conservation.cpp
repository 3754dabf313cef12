// Conservation laws, the gravity column, the stability of the Darcy inertia
// term, and how runs end: failures with reasons, cancellation, progress.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <thread>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

using problems::elastic;

// A free 2D block spinning and shearing in the middle of a large grid: no
// boundary, no gravity. Internal forces sum to zero at the nodes (the
// gradients of a partition of unity sum to zero), so the FLIP update keeps the
// total momentum to round-off: asserted at 1e-12 of the momentum scale.
TEST(Conservation, FreeBodyMomentumAndMass) {
  for (auto shape :
       {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline}) {
    hmpm::Problem p;
    p.dimension = 2;
    p.grid.max = {2.0, 2.0, 0};
    p.grid.cells = {20, 20, 1};
    p.shape_function = shape;
    p.materials.push_back(elastic(1000, 1e6, 0.3));
    hmpm::Body b;
    b.box.min = {0.6, 0.6, 0};
    b.box.max = {1.4, 1.4, 0};
    b.particles_per_cell = 2;
    b.initial.velocity[0] = [](const hmpm::Vec3& x) { return 0.5 - 2.0 * (x[1] - 1.0); };
    b.initial.velocity[1] = [](const hmpm::Vec3& x) {
      return -0.3 + 2.0 * (x[0] - 1.0) + 1.5 * (x[0] - 1.0) * (x[0] - 1.0);
    };
    p.bodies.push_back(b);
    p.time.end = 0.1;
    p.output.snapshot_interval = 0.02;
    p.output.snapshot_fields = {hmpm::Field::velocity};
    std::vector<std::array<double, 3>> totals;  // px, py, mass
    hmpm::RunOptions opt;
    opt.on_snapshot = [&](const hmpm::Snapshot& s) {
      std::array<double, 3> t{0, 0, 0};
      for (std::int64_t i = 0; i < s.particles; ++i) {
        t[0] += s.mass[i] * s.velocity[3 * i];
        t[1] += s.mass[i] * s.velocity[3 * i + 1];
        t[2] += s.mass[i];
      }
      totals.push_back(t);
    };
    const hmpm::RunResult r = hmpm::run(p, opt);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    ASSERT_GE(totals.size(), 5u);
    const double scale = totals[0][2] * 1.0;  // mass x 1 m/s
    for (const auto& t : totals) {
      EXPECT_NEAR(t[0], totals[0][0], 1e-12 * scale);
      EXPECT_NEAR(t[1], totals[0][1], 1e-12 * scale);
      EXPECT_EQ(t[2], totals[0][2]);
    }
  }
}

// Solid mass (1 - n) rho_s V of every particle is conserved exactly by the
// volume and porosity updates, while the column consolidates (1e-12 relative).
TEST(Conservation, SolidMassDuringConsolidation) {
  hmpm::Problem p = problems::column(1, 0, 1.0, 20, 2);
  hmpm::Material m = elastic(2650, 1e6, 0.0);
  m.hydraulic = hmpm::Hydraulic{0.4, 1e-4, 50e6, 1000.0, std::numeric_limits<double>::infinity()};
  p.materials.push_back(m);
  p.bodies[0].initial.pore_pressure = [](const hmpm::Vec3&) { return 1e4; };
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, 1.0), 0.0));
  hmpm::Traction t;
  t.particles.min = {0.975, 0, 0};
  t.particles.max = {1.0, 0, 0};
  t.traction[0] = problems::constant(-1e4);
  p.tractions.push_back(t);
  p.time.end = 0.5;
  p.output.snapshot_interval = 0.1;
  p.output.snapshot_fields = {hmpm::Field::porosity, hmpm::Field::strain};
  std::vector<double> solid;
  double total_strain = 0;
  hmpm::RunOptions opt;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) {
    double sum = 0;
    total_strain = 0;
    for (std::int64_t i = 0; i < s.particles; ++i) {
      sum += (1 - s.porosity[i]) * s.volume[i];
      total_strain += s.strain[6 * i];
    }
    solid.push_back(sum);
  };
  const hmpm::RunResult r = hmpm::run(p, opt);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_LT(total_strain, -1e-3);  // it did consolidate
  for (double s : solid) EXPECT_NEAR(s, solid[0], 1e-12 * solid[0]);
}

// A 2D elastic column under its own weight, bottom fixed, rollers on the
// sides, reaches sigma_yy = -rho g (H - y0) and sigma_xx = nu/(1-nu) sigma_yy.
// The waves of the sudden gravity load are removed by local (Cundall)
// damping, which vanishes at equilibrium and so does not bias the static
// state (checked: 1.5 s and 3 s give the same stresses). Tolerance 2 % of
// rho g H at every particle (issue 3): linear elements give a constant
// stress per cell, so particles a quarter cell from the centre differ from
// the exact stress by rho g h/4 = 1.25 % of rho g H with 20 cells. E = 10 MPa
// keeps strains at 0.1 % (with E = 1 MPa, 1.3 % strain, the error grows by
// about 1 % of rho g H: see docs/verification.md).
TEST(GravityColumn, ReachesSelfWeightStress) {
  const double H = 1.0, W = 0.4, rho = 1800, g = 9.81, nu = 0.3;
  const int ny = 20;
  for (auto shape : {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp}) {
    hmpm::Problem p;
    p.dimension = 2;
    p.shape_function = shape;
    p.grid.max = {W, H + 2 * H / ny, 0};
    p.grid.cells = {8, ny + 2, 1};
    p.materials.push_back(elastic(rho, 10e6, nu));
    hmpm::Body b;
    b.box.max = {W, H, 0};
    b.particles_per_cell = 2;
    p.bodies.push_back(b);
    p.gravity = {0, -g, 0};
    p.local_damping = problems::constant(0.15);
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, W), 0));
    hmpm::Boundary bottom = problems::fixed_velocity(problems::plane(p, 1, 0.0), 1);
    bottom.velocity[0] = problems::constant(0.0);
    p.boundaries.push_back(bottom);
    p.time.end = 1.5;  // 30 periods of the column's first mode (4H/c = 0.05 s)
    p.output.snapshot_interval = p.time.end;
    p.output.snapshot_fields = {hmpm::Field::effective_stress};
    double worst_yy = 0, worst_xx = 0;
    const auto x0 = hmpm::initial_positions(p);
    hmpm::RunOptions opt;
    opt.on_snapshot = [&](const hmpm::Snapshot& s) {
      if (s.index == 0) return;
      for (std::int64_t i = 0; i < s.particles; ++i) {
        const double yy = -rho * g * (H - x0[i][1]);
        worst_yy = std::max(worst_yy, std::abs(s.effective_stress[6 * i + 1] - yy));
        worst_xx = std::max(worst_xx, std::abs(s.effective_stress[6 * i] - nu / (1 - nu) * yy));
      }
    };
    const hmpm::RunResult r = hmpm::run(p, opt);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    std::printf("gravity column (%s): worst |syy - exact| = %.3g of rho g H, sxx %.3g\n",
                shape == hmpm::ShapeFunction::linear ? "linear" : "gimp", worst_yy / (rho * g * H),
                worst_xx / (rho * g * H));
    EXPECT_LT(worst_yy, 0.02 * rho * g * H);
    EXPECT_LT(worst_xx, 0.02 * rho * g * H);
  }
}

// Kinetic + elastic + fluid storage energy of a 1D saturated bar (storage Q).
double bar_energy(const hmpm::Snapshot& s, double Q) {
  double e = 0;
  for (std::int64_t i = 0; i < s.particles; ++i) {
    e += 0.5 * s.mass[i] * s.velocity[3 * i] * s.velocity[3 * i];
    e += 0.5 * s.volume[i] * s.effective_stress[6 * i] * s.strain[6 * i];
    e += 0.5 * Q * s.volume[i] * s.pore_pressure[i] * s.pore_pressure[i];
  }
  return e;
}

// The rho_f a term of Darcy's law uses the acceleration of the re-mapped
// nodal velocities of the same step. A saturated bar vibrating freely (closed: no drainage, no
// load) can only lose energy to Darcy flow; kinetic + elastic + fluid storage energy must never
// grow by more than the explicit scheme's O(w dt) oscillation (asserted 2 %), from low to very high
// permeability where the term dominates the flux, and the run must stay finite.
TEST(DarcyInertia, SameStepAccelerationIsStable) {
  for (double k : {1e-4, 1e-2, 0.3}) {  // at 0.3 m/s, (k/g) w = 20: the term dominates
    hmpm::Problem p = problems::column(1, 0, 1.0, 20, 2);
    hmpm::Material m = elastic(2000, 20e6, 0.0);
    m.hydraulic = hmpm::Hydraulic{0.3, k, 100e6, 1000.0, std::numeric_limits<double>::infinity()};
    p.materials.push_back(m);
    p.bodies[0].initial.velocity[0] = [](const hmpm::Vec3& x) {
      return 0.05 * std::sin(1.5707963 * x[0]);
    };
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
    p.time.end = 0.03;  // 3 periods of the undrained first mode
    p.output.snapshot_interval = 0.0005;
    p.output.snapshot_fields = {hmpm::Field::velocity, hmpm::Field::effective_stress,
                                hmpm::Field::strain, hmpm::Field::pore_pressure};
    const double Q = 0.3 / 100e6;
    std::vector<double> energy;
    hmpm::RunOptions opt;
    opt.on_snapshot = [&](const hmpm::Snapshot& s) {
      const double e = bar_energy(s, Q);
      energy.push_back(e);
    };
    const hmpm::RunResult r = hmpm::run(p, opt);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << "k " << k << ": " << r.message;
    const double peak = *std::max_element(energy.begin(), energy.end());
    std::printf("darcy inertia k=%g: peak/initial energy %.4f, final/initial %.4f\n", k,
                peak / energy[0], energy.back() / energy[0]);
    EXPECT_LT(peak, 1.02 * energy[0]) << "k " << k;
    EXPECT_LT(energy.back(), energy[0]) << "k " << k;
  }
}

// With a compressible fluid the u-p equations themselves (with Darcy's
// rho_f a) have growing solutions. One Fourier mode of the 1D equations,
//   rho u'' = E u_xx - p_x,  Q p' = -v_x - w_x,  w = -kappa (p_x + rho_f u''),
// has the characteristic polynomial
//   rho Q s^3 + rho kappa' q^2 s^2 + q^2 (E Q + 1) s + E kappa q^4 = 0,
// kappa' = kappa (1 - rho_f/rho), unstable (Routh-Hurwitz) exactly when
// E Q > (rho - rho_f)/rho_f. A column fixed and closed at x = 0 and drained
// (p = 0) and free at x = L has u = sin(q x), p = cos(q x), q = pi/(2L), as an
// exact mode, so its energy must change at 2 Re(s) of the oscillating root
// pair. Checked on both sides of the limit (E Q = 0.5 and 2 times it), and
// with the term dropped (hydraulic.darcy_inertia = false), where the same
// soft fluid must decay. Tolerance: the fitted rate within 5 % of 2 Re(s)
// (the energy of a damped mode oscillates at twice the frequency about the
// exponential, and the 20-cell grid shifts the frequency by ~0.5 %; measured
// deviations 0.3-1.1 %, printed). The run's warnings flag materials from
// 0.9 of the limit on.
TEST(DarcyInertia, CompressibleFluidGrowsAtTheRateOfTheEquations) {
  const double E = 20e6, rho_s = 2000, rho_f = 1000, n = 0.3, k = 0.1, L = 1.0, g = 9.81;
  const double rho = (1 - n) * rho_s + n * rho_f, limit = (rho - rho_f) / rho_f;
  struct Case {
    double times_limit;
    bool inertia;
  };
  for (const Case c : {Case{0.5, true}, Case{2.0, true}, Case{2.0, false}}) {
    const double Q = c.times_limit * limit / E;  // E Q = times_limit x the limit
    hmpm::Problem p = problems::column(1, 0, L, 20, 2);
    hmpm::Material m = elastic(rho_s, E, 0.0);
    m.hydraulic =
        hmpm::Hydraulic{n, k, n / Q, rho_f, std::numeric_limits<double>::infinity(), c.inertia};
    p.materials.push_back(m);
    const double q = std::acos(-1.0) / (2 * L);
    p.bodies[0].initial.velocity[0] = [q](const hmpm::Vec3& x) {
      return 1e-3 * std::sin(q * x[0]);
    };
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
    p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 0, L), 0.0));
    p.time.end = 0.15;  // about 6 periods
    p.output.snapshot_interval = 0.0005;
    p.output.snapshot_fields = {hmpm::Field::velocity, hmpm::Field::effective_stress,
                                hmpm::Field::strain, hmpm::Field::pore_pressure};
    std::vector<double> time, log_energy;
    hmpm::RunOptions opt;
    opt.on_snapshot = [&](const hmpm::Snapshot& s) {
      const double e = bar_energy(s, Q);
      // Skip the first period, while the non-oscillating root decays.
      if (s.time < 0.03) return;
      time.push_back(s.time);
      log_energy.push_back(std::log(e));
    };
    const hmpm::RunResult r = hmpm::run(p, opt);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    // Least-squares slope of log(energy) against time.
    const double tm = std::accumulate(time.begin(), time.end(), 0.0) / time.size();
    const double lm =
        std::accumulate(log_energy.begin(), log_energy.end(), 0.0) / log_energy.size();
    double stt = 0, stl = 0;
    for (std::size_t i = 0; i < time.size(); ++i) {
      stt += (time[i] - tm) * (time[i] - tm);
      stl += (time[i] - tm) * (log_energy[i] - lm);
    }
    const double measured = stl / stt;
    // 2 Re(s) of the oscillating pair: the cubic's real root r by bisection
    // (all coefficients are positive, so f(0) > 0 and r lies above minus the
    // Cauchy bound), then the pair from the deflated quadratic a3 s^2 + b s + c.
    const double kappa = k / (rho_f * g), kappa_i = c.inertia ? kappa : 0.0;
    const double kappa_p = kappa - kappa_i * rho_f / rho;
    const double a3 = rho * Q, a2 = rho * kappa_p * q * q, a1 = q * q * (E * Q + 1),
                 a0 = E * (kappa_p + kappa_i * rho_f / rho) * std::pow(q, 4);
    const auto cubic = [&](double x) { return ((a3 * x + a2) * x + a1) * x + a0; };
    double lo = -1 - (a2 + a1 + a0) / a3, hi = 0;
    for (int it = 0; it < 200; ++it) (cubic(0.5 * (lo + hi)) > 0 ? hi : lo) = 0.5 * (lo + hi);
    const double b = a2 + a3 * lo, cq = a1 + b * lo;
    ASSERT_LT(b * b, 4 * a3 * cq) << "the remaining pair must oscillate";
    const double predicted = -b / a3;  // 2 Re(s) = 2 (-b / (2 a3))
    std::printf("darcy inertia %s, E Q = %.1f x limit: energy rate %.2f /s, equations %.2f /s\n",
                c.inertia ? "on" : "off", c.times_limit, measured, predicted);
    EXPECT_NEAR(measured, predicted, 0.05 * std::abs(predicted));
    const bool warned = !r.warnings.empty();
    EXPECT_EQ(warned, c.inertia && c.times_limit > 0.9) << (warned ? r.warnings[0] : "");
    if (warned) {
      EXPECT_NE(r.warnings[0].find("darcy_inertia"), std::string::npos);
    }
  }
}

hmpm::Problem small_block(double vx, double vgrad) {
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.max = {1, 1, 0};
  p.grid.cells = {10, 10, 1};
  p.materials.push_back(elastic(1000, 1e5, 0.2));
  hmpm::Body b;
  b.box.min = {0.4, 0.4, 0};
  b.box.max = {0.6, 0.6, 0};
  b.initial.velocity[0] = [=](const hmpm::Vec3& x) { return vx - vgrad * (x[0] - 0.5); };
  p.bodies.push_back(b);
  p.time.end = 1.0;
  return p;
}

/// A B-spline column whose bottom row of particles lies on the floor
/// (y = 0), loaded by gravity all at once: the clamped spline gives a
/// particle on the floor 1/8 of the downward velocity of the node above,
/// so without the wall rule (phases/grid_to_particle.hpp) it leaves the
/// grid in the first step. With it the run settles (local damping) to the
/// oedometric closed form of the column's settlement under its own weight
/// (nu = 0). Tolerance 5 %: the clamped spline errs next to the floor (up to
/// 31 % of rho g H in the bottom row's stress, docs/verification.md), and
/// the bottom half-cell carries 1/16 of the column's compliance.
TEST(Walls, ParticlesOnAFloorStayInTheGrid) {
  hmpm::Problem p;
  p.dimension = 2;
  p.shape_function = hmpm::ShapeFunction::bspline;
  const double h = 0.05, sp = h / 2, rho = 1000.0, e = 1e5;
  p.grid.max = {2 * h, 10 * h, 0};
  p.grid.cells = {2, 10, 1};
  p.materials.push_back(elastic(rho, e, 0.0));
  hmpm::Body b;
  hmpm::ParticleList list;
  const int rows = 16;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < 4; ++i) {
      list.positions.push_back({(i + 0.5) * sp, j * sp, 0.0});
      list.volumes.push_back(sp * sp);
    }
  b.points = list;
  p.bodies.push_back(b);
  p.gravity = {0, -9.81, 0};
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 2 * h), 0));
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 1, 0.0), 1));
  p.local_damping = problems::constant(0.3);
  p.time.end = 1.5;
  p.output.snapshot_interval = p.time.end;
  p.output.snapshot_fields = {hmpm::Field::position};
  std::vector<double> last;
  hmpm::RunOptions opt;
  opt.threads = 1;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) { last = s.position; };
  const hmpm::RunResult r = hmpm::run(p, opt);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  ASSERT_EQ(last.size(), static_cast<std::size_t>(rows) * 4 * 3);
  double lowest = 1.0, top = 0.0;
  for (std::size_t k = 0; k < last.size(); k += 3) {
    lowest = std::min(lowest, last[k + 1]);
    if (k / 3 >= static_cast<std::size_t>(rows - 1) * 4) top += last[k + 1] / 4;
  }
  EXPECT_GE(lowest, 0.0);
  // The top row at y_top = (rows - 1) sp; the material above a height y
  // reaches y_top + sp/2 (the particles' domains), so the top moves by
  // int_0^y_top rho g (y_top + sp/2 - y) / E dy.
  const double y_top = (rows - 1) * sp;
  const double expected = 9.81 * rho / e * (y_top * y_top / 2 + sp * y_top / 2);
  EXPECT_NEAR(y_top - top, expected, 0.05 * expected);
}

TEST(Failure, ParticleLeavingTheGridIsNamed) {
  const hmpm::RunResult r = hmpm::run(small_block(5.0, 0.0));
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  EXPECT_NE(r.message.find("left the grid"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("particle "), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("step "), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("enlarge grid"), std::string::npos) << r.message;
  // 0.425 m to the edge at 5 m/s: about 0.085 s, not the whole run.
  EXPECT_LT(r.end_time, 0.1);
}

TEST(Failure, InvertedVolumeIsNamed) {
  // Compression rate 1e5 /s: the first step crushes the particles.
  const hmpm::RunResult r = hmpm::run(small_block(0.0, 1e5));
  ASSERT_EQ(r.status, hmpm::RunStatus::failed);
  EXPECT_NE(r.message.find("volume"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("What to change"), std::string::npos) << r.message;
}

TEST(Failure, UserStepAboveTheLimitIsRefusedBeforeRunning) {
  hmpm::Problem p = small_block(0.0, 0.0);
  p.time.dt = 1.0;
  EXPECT_THROW(hmpm::run(p), std::invalid_argument);
}

TEST(Control, CancellationStopsWithinAStepAndProgressIsReported) {
  hmpm::Problem p = small_block(0.0, 0.0);
  p.time.end = 100.0;
  std::atomic<bool> cancel{false};
  std::vector<hmpm::Progress> seen;
  hmpm::RunOptions opt;
  opt.cancel = &cancel;
  opt.progress_interval_s = 0.0;  // every step
  opt.on_progress = [&](const hmpm::Progress& pr) {
    seen.push_back(pr);
    if (pr.step == 50) cancel = true;
  };
  const hmpm::RunResult r = hmpm::run(p, opt);
  EXPECT_EQ(r.status, hmpm::RunStatus::cancelled);
  EXPECT_EQ(r.steps, 50);
  ASSERT_GE(seen.size(), 50u);
  EXPECT_GT(seen[10].total_steps, 1000);
  EXPECT_NEAR(seen[10].fraction, seen[10].time / 100.0, 1e-15);
  EXPECT_NE(r.message.find("cancelled"), std::string::npos);
}

// Issue 22 item 6: set-up (particle generation, initial-field formulas)
// honours the cancel flag and the wall-time limit, checked every few
// hundred particles, not only the time loop.
TEST(Control, SetUpHonoursCancellationAndTheWallTimeLimit) {
  hmpm::Problem p = small_block(0.0, 0.0);
  std::atomic<bool> cancel{false};
  std::atomic<int> evaluations{0};
  // An initial field that cancels the run at its first evaluation and,
  // for the wall-time case, takes 1 ms per particle.
  bool slow = false;
  p.bodies[0].initial.velocity[0] = [&](const hmpm::Vec3&) {
    ++evaluations;
    if (slow)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    else
      cancel = true;
    return 0.0;
  };
  hmpm::RunOptions opt;
  opt.cancel = &cancel;
  const hmpm::RunResult cancelled = hmpm::run(p, opt);
  EXPECT_EQ(cancelled.status, hmpm::RunStatus::cancelled);
  EXPECT_NE(cancelled.message.find("set-up"), std::string::npos) << cancelled.message;
  EXPECT_EQ(cancelled.steps, 0);
  EXPECT_LE(evaluations.load(), 257);  // stopped at the next check

  // The whole grid at 4 x 4 per cell: 1600 particles, 1.6 s of formulas
  // against a 0.05 s limit; the checks every 256 stop it after ~0.26 s.
  p.bodies[0].box.min = {0, 0, 0};
  p.bodies[0].box.max = {1, 1, 0};
  p.bodies[0].particles_per_cell = 4;
  ASSERT_EQ(hmpm::count_particles(p), 1600);
  cancel = false;
  slow = true;
  evaluations = 0;
  hmpm::RunOptions timed;
  timed.wall_time_limit_s = 0.05;
  const hmpm::RunResult failed = hmpm::run(p, timed);
  EXPECT_EQ(failed.status, hmpm::RunStatus::failed);
  EXPECT_NE(failed.message.find("wall-time limit"), std::string::npos) << failed.message;
  EXPECT_NE(failed.message.find("set-up"), std::string::npos) << failed.message;
  EXPECT_LT(evaluations.load(), hmpm::count_particles(p));
}

}  // namespace
