// Absorbing (Lysmer) boundaries and base motion (verification §12;
// Boundary::absorbing). Three closed-form facts:
//  - a plane wave meeting a dashpot of the medium's own impedance rho c
//    leaves without reflection (a drained column; a saturated one for the
//    fast, undrained wave, c1 = sqrt((E_oed + 1/Q) / rho));
//  - an elastic layer of height H on a half-space of impedance Z_r, shaken
//    by an outcrop motion V sin(w t), moves at depth d with amplitude
//    V cos(k d) / sqrt(cos^2(k H) + alpha^2 sin^2(k H)), k = w / c_s,
//    alpha = Z_soil / Z_r (Kramer, Geotechnical Earthquake Engineering,
//    §7.2): 1/alpha at the first resonance k H = pi/2;
//  - a column at rest under gravity on an absorbing base stays at rest (the
//    base carries the force it needed in the first step).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

using std::numbers::pi;

// Verification §12: E = 50 MPa, nu = 0.3, rho_s = 2700, n = 0.3; drained,
// the column's density is (1 - n) rho_s = 1890 kg/m^3 and c = sqrt(E_oed /
// rho) = 188.7 m/s.
constexpr double E = 50e6, nu = 0.3, rho_dry = 1890.0, L = 10.0;
const double e_oed = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));

hmpm::Boundary absorbing_plane(const hmpm::Problem& p, int axis, std::size_t material = 0) {
  hmpm::Boundary b;
  b.nodes = problems::plane(p, axis, 0.0);
  b.absorbing = hmpm::Absorbing{axis, material};
  return b;
}

/// A 2D block of the §12 soil filling the grid [0, width] x [0, height] of
/// nx x ny cells, 2 x 2 particles per cell, no boundaries yet.
hmpm::Problem soil_block_2d(double width, double height, int nx, int ny) {
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.max = {width, height, 0.0};
  p.grid.cells = {nx, ny, 1};
  hmpm::Body b;
  b.box.max = p.grid.max;
  b.particles_per_cell = 2;
  p.bodies.push_back(b);
  p.materials.push_back(problems::elastic(rho_dry, E, nu));
  return p;
}

struct Pulse {
  int cells = 100;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  bool absorbing = true;
  bool saturated = false;
};

struct PulseResult {
  double incident = 0;  // peak |v| of the incident pulse at mid-depth
  double returned = 0;  // peak |v| when its reflection would pass there, over `incident`
  double incident_p = 0, returned_p = 0;  // the same for the pore pressure (saturated)
};

// A Hann pulse of traction, q0 sin^2(pi t / T), on the top of a column along
// x (base x = 0), observed at the particle nearest mid-depth. T makes the
// pulse 3.8 m long (38 cells at 100 cells over 10 m): the MPM discretisation
// must carry the pulse before a boundary can be judged by it (the §12 load
// ramped over 2.5 ms, 5 cells long at 100 cells, trails a numerical
// dispersion tail of up to 50 % of its amplitude behind it, which would hide
// any reflection).
PulseResult run_pulse(const Pulse& c) {
  hmpm::Problem p = problems::column(1, 0, L, c.cells, 2);
  p.shape_function = c.shape;
  double speed = 0.0;
  if (c.saturated) {
    // Water of 2.2 GPa and k = 1e-9 m/s: undrained over the run (the slow
    // wave does not move on this time scale), E_oed Q = 0.009, far from the
    // Darcy-inertia limit.
    p.materials.push_back(problems::saturated_elastic(2700, E, nu, 0.3, 1e-9, 2.2e9));
    const double rho = 0.7 * 2700 + 0.3 * 1000;
    speed = std::sqrt((e_oed + 2.2e9 / 0.3) / rho);
  } else {
    p.materials.push_back(problems::elastic(rho_dry, E, nu));
    speed = std::sqrt(e_oed / rho_dry);
  }
  const double T = 3.77 / speed;
  p.boundaries.push_back(c.absorbing ? absorbing_plane(p, 0)
                                     : problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  t.particles.min[0] = L - L / (2 * c.cells);  // the top particle
  t.axis = 0;
  t.side = +1;
  t.traction[0] = [T](double time) {
    const double s = std::sin(pi * time / T);
    return time < T ? -1e4 * s * s : 0.0;
  };
  p.tractions.push_back(t);
  const double x = L / 2;
  const double back = (2 * L - x) / speed;  // the reflection's arrival at x
  p.time.end = back + 1.6 * T;
  p.output.series_particles = {c.cells};  // the first particle above x = 5 m
  p.output.series_fields = {hmpm::Field::velocity, hmpm::Field::pore_pressure};
  p.output.series_interval = T / 40;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  PulseResult out;
  const hmpm::Series& s = r.series;
  for (std::size_t k = 0; k < s.time.size(); ++k) {
    const double v = std::abs(s.values[0][k]), pp = std::abs(s.values[1][k]);
    if (s.time[k] < back - 0.1 * T) {
      out.incident = std::max(out.incident, v);
      out.incident_p = std::max(out.incident_p, pp);
    } else {
      out.returned = std::max(out.returned, v);
      out.returned_p = std::max(out.returned_p, pp);
    }
  }
  out.returned /= out.incident;
  if (c.saturated) out.returned_p /= out.incident_p;
  return out;
}

const char* name(hmpm::ShapeFunction s) {
  return s == hmpm::ShapeFunction::linear ? "linear"
                                          : (s == hmpm::ShapeFunction::gimp ? "gimp" : "bspline");
}

// A pulse leaving a drained column through the absorbing base: what comes
// back is at most 2 % of it (the bound; measured 1.3-1.8 % at 100
// cells, 0.4-0.6 % at 200, which also bounds the dispersion tail of the
// incident pulse itself, counted here as "returned"), and no more at 200
// cells than at 100. A fixed base sends it all back (the control: the
// measure sees a reflection).
TEST(Absorbing, PulseLeavesADrainedColumnThroughTheBase) {
  const PulseResult fixed = run_pulse({100, hmpm::ShapeFunction::linear, false, false});
  EXPECT_GT(fixed.returned, 0.9);
  for (hmpm::ShapeFunction shape :
       {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline}) {
    const PulseResult coarse = run_pulse({100, shape, true, false});
    const PulseResult fine = run_pulse({200, shape, true, false});
    std::printf("[ absorbing ] drained %s: returned %.4f (100 cells), %.4f (200 cells)\n",
                name(shape), coarse.returned, fine.returned);
    EXPECT_LT(coarse.returned, 0.02) << name(shape);
    EXPECT_LT(fine.returned, 0.02) << name(shape);
    EXPECT_LT(fine.returned, coarse.returned) << name(shape);
    // The incident amplitude is the plane wave's q0 / (rho c).
    EXPECT_NEAR(coarse.incident, 1e4 / std::sqrt(rho_dry * e_oed), 0.08 * coarse.incident)
        << name(shape);
  }
}

// The same for the fast wave of a saturated column, undrained: the dashpot
// takes the mixture's impedance rho sqrt((E_oed + 1/Q) / rho) on the total
// traction; the pore pressure, which the wave carries with the effective
// stress, leaves with it (the base is impermeable: no pressure is
// prescribed there). What comes back is a longer, weaker wave than the
// drained column's: 2.3 % of the velocity (1.4 % of the pressure) at 100
// cells, 0.6 % at 200 (second order); the 2 % is asserted at 200
// cells, 3 % at 100, and the fall under refinement.
TEST(Absorbing, FastWaveLeavesASaturatedColumn) {
  const PulseResult fixed = run_pulse({100, hmpm::ShapeFunction::linear, false, true});
  EXPECT_GT(fixed.returned, 0.9);
  const PulseResult coarse = run_pulse({100, hmpm::ShapeFunction::linear, true, true});
  const PulseResult fine = run_pulse({200, hmpm::ShapeFunction::linear, true, true});
  for (const auto& [cells, r] : {std::pair{100, coarse}, std::pair{200, fine}})
    std::printf("[ absorbing ] saturated, %d cells: returned velocity %.4f, pore pressure %.4f\n",
                cells, r.returned, r.returned_p);
  EXPECT_LT(coarse.returned, 0.03);
  EXPECT_LT(coarse.returned_p, 0.03);
  EXPECT_LT(fine.returned, 0.02);
  EXPECT_LT(fine.returned_p, 0.02);
  EXPECT_LT(fine.returned, 0.5 * coarse.returned);
  EXPECT_LT(fine.returned_p, 0.5 * coarse.returned_p);
}

struct Shaking {
  int cells = 20;
  double frequency_ratio = 1.0;  // of the first resonance c_s / (4 H)
  double alpha = 0.25;           // Z_soil / Z_rock
};

// An elastic layer (the §12 soil) of height L in a 2D column one cell wide,
// every node held vertically (pure shear: u_x(y, t)), on a compliant base
// of rock with impedance Z_soil / alpha, shaken by the rock outcrop's
// velocity V sin(w t) (an acceleration in the job spec is integrated to
// this by the api: tests/api/test_base_motion.cpp).
// Returns the steady amplitude at the top particle over the closed form.
double shaken_amplitude_ratio(const Shaking& c, double* expected_out = nullptr) {
  hmpm::Problem p = soil_block_2d(L / c.cells, L, 1, c.cells);
  const double g_soil = E / (2 * (1 + nu));
  const double cs = std::sqrt(g_soil / rho_dry);
  // Rock: density 2400, shear impedance Z_soil / alpha (nu 0.3).
  const double rho_rock = 2400.0;
  const double cs_rock = std::sqrt(rho_dry * g_soil) / c.alpha / rho_rock;
  p.materials.push_back(
      problems::elastic(rho_rock, 2 * (1 + nu) * rho_rock * cs_rock * cs_rock, nu));
  hmpm::Boundary vertical;
  vertical.nodes.all = true;
  vertical.has_velocity = true;
  vertical.velocity[1] = problems::constant(0.0);
  p.boundaries.push_back(vertical);
  const double omega = 2 * pi * c.frequency_ratio * cs / (4 * L);
  constexpr double V = 0.1;
  hmpm::Boundary base = absorbing_plane(p, 1, 1);
  base.velocity[0] = [omega](double t) { return V * std::sin(omega * t); };
  p.boundaries.push_back(base);
  const double period = 2 * pi / omega;
  p.time.end = 14 * period;
  const std::int64_t top = hmpm::count_particles(p) - 1;  // at depth h/4
  p.output.series_particles = {top};
  p.output.series_fields = {hmpm::Field::velocity};
  p.output.series_interval = period / 200;
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  double amplitude = 0;
  for (std::size_t k = 0; k < r.series.time.size(); ++k)
    if (r.series.time[k] > p.time.end - 2 * period)
      amplitude = std::max(amplitude, std::abs(r.series.values[0][2 * k]));
  const double k = omega / cs, depth = L - r.series.initial_positions[0][1];
  const double kh = k * L;
  const double expected =
      V * std::cos(k * depth) /
      std::sqrt(std::cos(kh) * std::cos(kh) + c.alpha * c.alpha * std::sin(kh) * std::sin(kh));
  if (expected_out) *expected_out = expected / V;
  return amplitude / expected;
}

// The first resonance of the layer: amplification 1/alpha = 4 within 5 %
// (the bound) at 20 and 40 cells (measured 2.8 % and 1.6 % above
// the closed form: the discrete layer's resonance, first order in h, the
// particle one quarter cell below the top); at twice the resonance
// frequency (k H = pi) the layer passes the outcrop motion through
// unamplified, |H| = 1 (measured +3.7 %, +1.3 %). Transients decay by the
// base's reflection coefficient (1 - alpha)/(1 + alpha) = 0.6 per round
// trip: 0.6^20 = 4e-5 by the last two of the 14 periods measured.
TEST(Absorbing, ShakenLayerFollowsTheTransferFunction) {
  for (int cells : {20, 40}) {
    double expected = 0;
    const double resonance = shaken_amplitude_ratio({cells, 1.0, 0.25}, &expected);
    std::printf("[ absorbing ] %d cells: amplification at resonance %.4f x the closed form %.3f\n",
                cells, resonance, expected);
    EXPECT_NEAR(resonance, 1.0, 0.05) << cells;
    const double twice = shaken_amplitude_ratio({cells, 2.0, 0.25}, &expected);
    std::printf("[ absorbing ] %d cells: at twice the frequency %.4f x the closed form %.3f\n",
                cells, twice, expected);
    EXPECT_NEAR(twice, 1.0, 0.05) << cells;
  }
}

// Geostatic column under gravity on an absorbing base: the base takes the
// column's weight in the first step and holds it, so nothing moves (a
// dashpot alone would let it sink at the speed the weight drives through
// the dashpot, rho g L / (rho c) = 0.5 m/s here). Round-off: the largest
// particle velocity stays below 1e-9 of that speed.
TEST(Absorbing, ColumnAtRestUnderGravityStaysAtRest) {
  hmpm::Problem p = problems::column(1, 0, L, 50, 2);
  p.materials.push_back(problems::elastic(rho_dry, E, nu));
  p.boundaries.push_back(absorbing_plane(p, 0));
  p.gravity[0] = -9.81;
  p.initial_state.geostatic = hmpm::Geostatic{};
  p.time.end = 0.2;  // four passes of a wave through the column
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::velocity};
  p.output.series_interval = 0.01;
  p.output.reactions_interval = 0.05;
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  const double sink = 9.81 * L / std::sqrt(e_oed / rho_dry);
  double worst = 0;
  for (double v : r.series.values[0]) worst = std::max(worst, std::abs(v));
  EXPECT_LT(worst, 1e-9 * sink);
  // The base's reaction is the column's weight per unit area.
  ASSERT_FALSE(r.reactions.force.empty());
  const double weight = rho_dry * 9.81 * L;
  EXPECT_NEAR(r.reactions.force[0].back(), weight, 1e-9 * weight);
}

}  // namespace

namespace {

// Energy in a 2D box of the §12 soil, 20 m wide and 10 m deep (0.5 m
// cells), after a pulse of pressure on a 1 m strip at the middle of its free
// top (a Hann pulse of 0.05 s: 19 cells per P wavelength, 10 per S; a
// shorter pulse trails a numerical dispersion tail that rings in the box
// whatever its walls): P, S and Rayleigh waves meet the sides and the base at
// every angle. With absorbing sides and base (normal x, x and y) the energy
// left in the box falls to a few percent of the largest it held; with roller
// walls it stays (the control, 97 %). Lysmer's dashpots are exact only for
// waves meeting them head-on (a few percent reflected at 30 degrees), and
// the Rayleigh wave meets the sides in the corners: measured 3.2 % left at
// 0.5 s and 1.7 % at 1 s, asserted below 3 % at 1 s and falling (below
// 0.75 of what was left at 0.5 s).
/// A Hann pulse of pressure q0 sin^2(pi t / T), t < T, on the y+ face of
/// the particles in [lo, hi] (2D).
hmpm::Traction hann_pulse(const hmpm::Vec3& lo, const hmpm::Vec3& hi, double q0, double T) {
  hmpm::Traction t;
  t.particles.min = lo;
  t.particles.max = hi;
  t.axis = 1;
  t.side = +1;
  t.traction[1] = [q0, T](double time) {
    const double s = std::sin(pi * time / T);
    return time < T ? -q0 * s * s : 0.0;
  };
  return t;
}

struct BoxEnergy {
  double peak = 0, at_half = 0, at_end = 0;
};

BoxEnergy pulse_in_a_box(bool absorbing) {
  hmpm::Problem p = soil_block_2d(20.0, 10.0, 40, 20);
  for (const auto& [axis, at] : {std::pair{0, 0.0}, std::pair{0, 20.0}, std::pair{1, 0.0}}) {
    hmpm::Boundary w;
    w.nodes = problems::plane(p, axis, at);
    if (absorbing) {
      w.absorbing = hmpm::Absorbing{axis, 0};
    } else {
      w.has_velocity = true;
      w.velocity[axis] = problems::constant(0.0);
    }
    p.boundaries.push_back(w);
  }
  p.tractions.push_back(hann_pulse({9.5, 9.75, 0.0}, {10.5, 10.0, 0.0}, 1e5, 0.05));
  p.time.end = 1.0;
  p.output.snapshot_interval = 0.02;
  p.output.snapshot_fields = {hmpm::Field::velocity, hmpm::Field::effective_stress,
                              hmpm::Field::strain};
  BoxEnergy e;
  hmpm::RunOptions opt;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) {
    double energy = 0;
    for (std::int64_t i = 0; i < s.particles; ++i) {
      for (int a = 0; a < 2; ++a)
        energy += 0.5 * s.mass[i] * s.velocity[3 * i + a] * s.velocity[3 * i + a];
      for (int k = 0; k < 6; ++k)
        energy += 0.5 * s.volume[i] * (k < 3 ? 1.0 : 2.0) * s.effective_stress[6 * i + k] *
                  s.strain[6 * i + k];
    }
    e.peak = std::max(e.peak, energy);
    if (std::abs(s.time - 0.5) < 0.01) e.at_half = energy;
    e.at_end = energy;
  };
  const hmpm::RunResult r = hmpm::run(p, opt);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  return e;
}

TEST(Absorbing, WavesLeaveABoxThroughItsSidesAndBase) {
  const BoxEnergy walls = pulse_in_a_box(false);
  const BoxEnergy dashpots = pulse_in_a_box(true);
  std::printf(
      "[ absorbing ] box: energy left at 0.5 s / 1 s of the peak: walls %.3f / %.3f, "
      "absorbing %.4f / %.4f\n",
      walls.at_half / walls.peak, walls.at_end / walls.peak, dashpots.at_half / dashpots.peak,
      dashpots.at_end / dashpots.peak);
  EXPECT_GT(walls.at_end, 0.8 * walls.peak);
  EXPECT_LT(dashpots.at_end, 0.03 * dashpots.peak);
  EXPECT_LT(dashpots.at_end, 0.75 * dashpots.at_half);
}

}  // namespace

namespace {

// The dashpots' face shares come from the particles next to the face; with
// cells 5x wider than tall (0.5 m x 0.1 m) a plane P pulse through a 2D
// column two cells wide must leave as it does in 1D (measured 1.0 %; the
// share taken from a square particle of the same volume halved the
// dashpots, and 33 % came back).
TEST(Absorbing, PlaneWaveLeavesThroughABaseOfFlatCells) {
  hmpm::Problem p = soil_block_2d(1.0, L, 2, 100);
  hmpm::Boundary rollers;
  rollers.nodes.all = true;
  rollers.has_velocity = true;
  rollers.velocity[0] = problems::constant(0.0);
  p.boundaries.push_back(rollers);
  p.boundaries.push_back(absorbing_plane(p, 1));
  p.tractions.push_back(hann_pulse({0.0, L - 0.05, 0.0}, {1.0, L, 0.0}, 1e4, 0.02));
  p.time.end = 0.12;
  const double speed = std::sqrt(e_oed / rho_dry), back = (L + L / 2) / speed;
  // The particle at x = 0.125 m nearest y = 5 m: particles are numbered x
  // fastest, 4 across (2 cells x 2), rows 0.05 m apart from y = 0.025 m.
  const std::int64_t nearest = std::int64_t{4} * 100;  // y = 0.025 + 0.05 * 100 = 5.025 m
  p.output.series_particles = {nearest};
  p.output.series_fields = {hmpm::Field::velocity};
  p.output.series_interval = 0.0005;
  const hmpm::RunResult r = hmpm::run(p);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  ASSERT_NEAR(r.series.initial_positions[0][0], 0.125, 1e-9);
  ASSERT_NEAR(r.series.initial_positions[0][1], 5.025, 1e-9);
  double incident = 0, returned = 0;
  for (std::size_t k = 0; k < r.series.time.size(); ++k) {
    double& peak = r.series.time[k] < back - 0.002 ? incident : returned;
    peak = std::max(peak, std::abs(r.series.values[0][2 * k + 1]));
  }
  std::printf("[ absorbing ] flat cells: returned %.4f\n", returned / incident);
  EXPECT_NEAR(incident, 1e4 / std::sqrt(rho_dry * e_oed), 0.05 * incident);
  EXPECT_LT(returned / incident, 0.02);
}

}  // namespace
