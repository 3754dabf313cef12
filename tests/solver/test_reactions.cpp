// Boundary reactions (OutputRequest::reactions_interval, RunResult::
// reactions, solver/src/phases/reactions.hpp) against the statics of a
// column at rest: a soil column of height H and width W on a fixed base
// between roller walls weighs rho g H W (per metre in 2D, per square metre in
// 1D), so the base pushes up on it with exactly that force; rollers carry no
// vertical force; a traction q on a width B of the top adds q B; in a
// saturated column the base carries the total weight, water included
// (rho_sat = (1 - n) rho_s + n rho_w), not the buoyant weight the effective
// stress alone gives. In 2D the rollers hold the at-rest horizontal stress:
// K0 rho g H^2 / 2 each (dry, geostatic). Every time scheme, 1D and 2D.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

constexpr double g = 9.81, H = 1.0, h = 0.1, rho_dry = 2000.0;
constexpr double rho_s = 2650.0, porosity = 0.4, rho_w = 1000.0, k0 = 0.5;
constexpr int width_cells = 4;

struct Case {
  int dim = 2;
  hmpm::Scheme scheme = hmpm::Scheme::explicit_scheme;
  bool saturated = false;
  bool geostatic = true;
};

double width(int dim) {
  return dim == 1 ? 1.0 : width_cells * h;
}
double mixture_density(bool saturated) {
  return saturated ? (1 - porosity) * rho_s + porosity * rho_w : rho_dry;
}
double weight(const Case& c) {
  return mixture_density(c.saturated) * g * H * width(c.dim);
}

/// The column: boundaries[0] the fixed base, [1], [2] the rollers (2D),
/// then p = 0 at the surface when saturated. Two empty cells above the
/// surface. Reactions every `interval` seconds.
hmpm::Problem column(const Case& c, double end, double interval) {
  const int ax = c.dim - 1;
  hmpm::Problem p;
  p.dimension = c.dim;
  for (int a = 0; a < c.dim; ++a) {
    p.grid.cells[a] = a == ax ? 12 : width_cells;
    p.grid.max[a] = p.grid.cells[a] * h;
  }
  p.gravity[ax] = -g;
  hmpm::Material m;
  m.name = "soil";
  m.density = c.saturated ? rho_s : rho_dry;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  if (c.saturated)
    m.hydraulic =
        hmpm::Hydraulic{porosity, 1e-4, 2.2e9, rho_w, std::numeric_limits<double>::infinity()};
  p.materials.push_back(m);
  hmpm::Body b;
  b.box.max = p.grid.max;
  b.box.max[ax] = H;
  b.particles_per_cell = 2;
  p.bodies.push_back(b);
  hmpm::Boundary base;
  base.nodes = problems::plane(p, ax, 0.0);
  base.has_velocity = true;
  for (int a = 0; a < c.dim; ++a) base.velocity[a] = problems::constant(0.0);
  p.boundaries.push_back(base);
  for (int a = 0; a < ax; ++a) {
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, a, 0.0), a));
    p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, a, p.grid.max[a]), a));
  }
  if (c.saturated) p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, ax, H), 0.0));
  if (c.geostatic) {
    hmpm::Geostatic geo;
    if (c.saturated) geo.water_table = H;
    geo.k0 = k0;
    p.initial_state.geostatic = geo;
  }
  p.time.scheme = c.scheme;
  p.time.end = end;
  p.time.implicit.tolerance = 1e-12;
  p.output.reactions_interval = interval;
  return p;
}

std::string label(const Case& c) {
  return std::to_string(c.dim) + "D " + hmpm::scheme_name(c.scheme) +
         (c.saturated ? " saturated" : " dry") + (c.geostatic ? " geostatic" : "");
}

/// Component `a` of boundary `b`'s reaction at sample `row`.
double force(const hmpm::RunResult& r, std::size_t b, std::size_t row, int a) {
  const auto d = static_cast<std::size_t>(r.reactions.dimension);
  return r.reactions.force.at(b).at(row * d + static_cast<std::size_t>(a));
}

/// Largest |base vertical reaction - expected| over the samples (relative
/// to `expected`), and the same for the rollers' vertical force.
struct Errors {
  double base = 0, rollers = 0;
};
Errors vertical_errors(const hmpm::RunResult& r, int dim, double expected) {
  Errors e;
  const int ax = dim - 1;
  for (std::size_t row = 0; row < r.reactions.time.size(); ++row) {
    e.base = std::max(e.base, std::abs(force(r, 0, row, ax) - expected) / expected);
    if (dim == 2)
      for (std::size_t b : {1, 2})
        e.rollers = std::max(e.rollers, std::abs(force(r, b, row, ax)) / expected);
  }
  return e;
}

/// A load on the top face (y+) of the top row of particles over x in [0, b].
hmpm::Traction top_strip(double b) {
  hmpm::Traction t;
  t.particles.min = {0.0, H - h / 2, 0.0};
  t.particles.max = {b, H, 0.0};
  t.axis = 1;
  t.side = +1;
  return t;
}

hmpm::RunResult run_ok(const hmpm::Problem& p, const std::string& what) {
  hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << what << ": " << r.message;
  return r;
}

// The geostatic state is in discrete equilibrium (test_geostatic.cpp): the
// nodal internal force balances the nodal weight at every free node to
// round-off, and stays so. The base reaction is then the weight up to the
// round-off of its sums: a nodal force is a sum of tens of terms of size
// rho g H h and the reaction adds W / (rho g H h) ~ 10-40 of them, so the
// relative error is ~1e-14; 1e-10 leaves room for the round-off drift of
// a few hundred steps (1e-12 in test_geostatic.cpp) and is eight orders
// below an O(h) imbalance of the quadrature. Saturated: the pore pressure's
// nodal force enters the same way (total stress).
class AtRest : public ::testing::TestWithParam<Case> {};

TEST_P(AtRest, TheBaseCarriesTheColumnsWeightAndTheRollersNone) {
  const Case c = GetParam();
  // Explicit: a few hundred steps; quasi_static: a few steps (consolidating
  // when saturated and not geostatic: the total weight is carried at every
  // converged step, whatever the water carries).
  const bool qs = c.scheme == hmpm::Scheme::quasi_static;
  const double end = qs ? 1e3 : 0.1, interval = qs ? 100.0 : 0.01;
  const hmpm::RunResult r = run_ok(column(c, end, interval), label(c));
  ASSERT_EQ(r.reactions.dimension, c.dim);
  const std::size_t boundaries = (c.dim == 2 ? 3 : 1) + (c.saturated ? 1 : 0);
  ASSERT_EQ(r.reactions.force.size(), boundaries);
  ASSERT_GE(r.reactions.time.size(), 10u);
  // The first sample ends the first step that reaches the interval.
  EXPECT_GE(r.reactions.time.front(), interval * (1 - 1e-9));
  EXPECT_LE(r.reactions.time.front(), interval + r.dt * 1.25);
  const double w = weight(c);
  const Errors e = vertical_errors(r, c.dim, w);
  // Quasi-static from zero stress: Newton converges to the scaled residual
  // tolerance 1e-12 (set in column()); what the free degrees of freedom
  // leave unbalanced is at most that fraction of the sum of the force
  // magnitudes (~W), so 1e-9 of W bounds it with room.
  const double tol = c.geostatic ? 1e-10 : 1e-9;
  std::printf("%s: base %.3e of W = %.6g N, rollers' vertical %.3e of W\n", label(c).c_str(),
              e.base, w, e.rollers);
  EXPECT_LT(e.base, tol) << label(c);
  EXPECT_EQ(e.rollers, 0.0) << "rollers constrain x only: no vertical component is charged";
  // The pressure boundary exerts no force on the mixture.
  if (c.saturated) {
    const std::size_t pb = r.reactions.force.size() - 1;
    for (double f : r.reactions.force[pb]) EXPECT_EQ(f, 0.0);
  }
  if (c.dim == 2 && c.geostatic && !c.saturated) {
    // Each roller holds the at-rest horizontal stress K0 rho g (H - y),
    // integrated over the height: K0 rho g H^2 / 2, pushing inwards. The
    // quadrature of the wall nodes' force (midpoint rule in each sub-cell,
    // exact for a stress linear in y) makes it exact up to round-off.
    const double lateral = k0 * rho_dry * g * H * H / 2;
    const std::size_t last = r.reactions.time.size() - 1;
    EXPECT_NEAR(force(r, 1, last, 0), lateral, 1e-10 * lateral);
    EXPECT_NEAR(force(r, 2, last, 0), -lateral, 1e-10 * lateral);
  }
}

INSTANTIATE_TEST_SUITE_P(Columns, AtRest,
                         ::testing::Values(Case{1, hmpm::Scheme::explicit_scheme, false, true},
                                           Case{2, hmpm::Scheme::explicit_scheme, false, true},
                                           Case{1, hmpm::Scheme::explicit_scheme, true, true},
                                           Case{2, hmpm::Scheme::explicit_scheme, true, true},
                                           Case{2, hmpm::Scheme::semi_implicit, false, true},
                                           Case{1, hmpm::Scheme::semi_implicit, true, true},
                                           Case{2, hmpm::Scheme::semi_implicit, true, true},
                                           Case{1, hmpm::Scheme::quasi_static, false, false},
                                           Case{2, hmpm::Scheme::quasi_static, false, false},
                                           Case{1, hmpm::Scheme::quasi_static, true, false},
                                           Case{2, hmpm::Scheme::quasi_static, true, false},
                                           Case{2, hmpm::Scheme::quasi_static, true, true}),
                         [](const auto& info) {
                           const Case& c = info.param;
                           return std::to_string(c.dim) + "D_" + hmpm::scheme_name(c.scheme) +
                                  (c.saturated ? "_saturated" : "_dry") +
                                  (c.geostatic ? "_geostatic" : "");
                         });

// A strip load q on the top of the column over x in [0, B]: the base carries
// W + q B, the rollers no vertical force, and the two rollers' horizontal
// forces cancel. A rigid tie under the load (a massless plate) exerts no net
// force. Quasi-static from zero stress (Newton tolerance, as above).
TEST(Reactions, AStripLoadAddsItsResultantToTheBaseReaction) {
  Case c;
  c.scheme = hmpm::Scheme::quasi_static;
  c.geostatic = false;
  hmpm::Problem p = column(c, 10.0, 1.0);
  const double q = 2e4, b = 0.2;
  hmpm::Traction t = top_strip(b);
  t.traction[1] = problems::constant(-q);
  p.tractions.push_back(t);
  hmpm::Boundary plate;
  plate.nodes.box.min = {0.0, H, 0.0};
  plate.nodes.box.max = {b, H, 0.0};
  plate.rigid[1] = true;
  p.boundaries.push_back(plate);
  const hmpm::RunResult r = run_ok(p, "strip load");
  const double w = weight(c), total = w + q * b;
  const Errors e = vertical_errors(r, 2, total);
  std::printf("strip load: base %.3e of W + qB = %.6g N/m\n", e.base, total);
  EXPECT_LT(e.base, 1e-9);
  EXPECT_EQ(e.rollers, 0.0);
  for (std::size_t row = 0; row < r.reactions.time.size(); ++row) {
    // The base is fixed horizontally too: with the rollers it balances
    // the horizontal forces (none applied).
    EXPECT_LT(std::abs(force(r, 0, row, 0) + force(r, 1, row, 0) + force(r, 2, row, 0)),
              1e-9 * total);
    EXPECT_LT(std::abs(force(r, 3, row, 1)), 1e-9 * total) << "the plate's net force";
  }
}

// A load that varies along the face (Traction::traction_field, a formula
// in x): q(x) = q0 (1 + 2 x / b) on [0, b]. Particles sit at the centres of
// equal sub-cells, so the midpoint rule integrates the linear q exactly:
// the base carries W + q0 b (1 + 1) = W + 2 q0 b to Newton's tolerance. A
// load evaluated once, at the origin, would give W + q0 b: the test tells
// the two apart by a third of the total.
TEST(Reactions, ALoadVaryingAlongTheFaceAddsItsIntegral) {
  Case c;
  c.scheme = hmpm::Scheme::quasi_static;
  c.geostatic = false;
  hmpm::Problem p = column(c, 10.0, 1.0);
  const double q0 = 1e4, b = 0.2;
  hmpm::Traction t = top_strip(b);
  t.traction_field[1] = [=](const hmpm::Vec3& x, double) { return -q0 * (1 + 2 * x[0] / b); };
  t.traction[1] = [=](double time) { return t.traction_field[1](hmpm::Vec3{0, 0, 0}, time); };
  p.tractions.push_back(t);
  const hmpm::RunResult r = run_ok(p, "varying load");
  const double total = weight(c) + 2 * q0 * b;
  const Errors e = vertical_errors(r, 2, total);
  std::printf("varying load: base %.3e of W + integral q = %.6g N/m\n", e.base, total);
  EXPECT_LT(e.base, 1e-9);
  EXPECT_EQ(e.rollers, 0.0);
}

// The same strip load on the explicit scheme, damped to rest from the
// geostatic state of the weight alone: the reaction settles on W + Q, Q the
// load as the explicit scheme applies it: q times the loaded particles'
// current volume over their initial height (boundary/tractions.hpp; it
// follows the particles' compression, q/M ~ 1.5e-3 here, so Q differs from
// q B by 5e-4 of W + qB). What is left of the transient is the particles'
// inertia (sum m a), which local damping 0.7 takes off by orders of
// magnitude per oscillation period (4 H / c ~ 0.05 s): after 2 s (40
// periods) it is below round-off; 1e-9 of W + Q leaves room for it.
TEST(Reactions, ExplicitDampedToRestUnderAStripLoad) {
  Case c;
  const double end = 2.0;
  hmpm::Problem p = column(c, end, 0.2);
  const double q = 2e4, b = 0.2;
  hmpm::Traction t = top_strip(b);
  t.traction[1] = problems::constant(-q);
  p.tractions.push_back(t);
  p.local_damping = problems::constant(0.7);
  p.output.snapshot_interval = end;
  hmpm::Snapshot last_snapshot;
  hmpm::RunOptions opt;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) { last_snapshot = s; };
  const hmpm::RunResult r = hmpm::run(p, opt);
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  ASSERT_EQ(last_snapshot.time, end);
  double load = 0;
  const std::vector<hmpm::Vec3> x0 = hmpm::initial_positions(p);
  for (std::size_t i = 0; i < x0.size(); ++i)
    if (hmpm::particle_selected(p, t, x0[i])) load += q * last_snapshot.volume[i] / (h / 2);
  EXPECT_NEAR(load, q * b, 2e-3 * q * b) << "the load follows the top particles' strain only";
  const double total = weight(c) + load;
  const std::size_t last = r.reactions.time.size() - 1;
  const double err = std::abs(force(r, 0, last, 1) - total) / total;
  std::printf(
      "explicit strip load at t = %g s: base %.3e of W + Q (Q = %.6g N/m, qB = %g); "
      "first sample (t = %g s) %.3e\n",
      r.reactions.time[last], err, load, q * b, r.reactions.time[0],
      std::abs(force(r, 0, 0, 1) - total) / total);
  EXPECT_LT(err, 1e-9);
  EXPECT_EQ(force(r, 1, last, 1), 0.0);
}

// A node component constrained by two boundaries is charged to the later
// one (the precedence of boundary/apply.hpp): the total is unchanged, the
// later boundary gets its nodes' share.
TEST(Reactions, ANodeOfTwoBoundariesIsChargedToTheLaterOne) {
  Case c;
  hmpm::Problem p = column(c, 0.05, 0.01);
  hmpm::Boundary half = problems::fixed_velocity(problems::plane(p, 1, 0.0), 1);
  half.nodes.box.max[0] = 0.2;  // the base nodes x in [0, 0.2]: 3 of 5
  p.boundaries.push_back(half);
  const hmpm::RunResult r = run_ok(p, "overlap");
  const double w = weight(c);
  for (std::size_t row = 0; row < r.reactions.time.size(); ++row) {
    const double base = force(r, 0, row, 1), later = force(r, 3, row, 1);
    EXPECT_NEAR(base + later, w, 1e-10 * w);
    // Its 3 nodes of 5 carry more than half the weight (the middle nodes
    // carry a cell's width each, the corner half of one): 2.5 of 4 cells.
    EXPECT_NEAR(later, w * 2.5 / 4, 1e-10 * w);
    // The base keeps the x components of its own nodes: zero horizontal
    // force under a laterally uniform column.
    EXPECT_NEAR(force(r, 0, row, 0), 0.0, 1e-10 * w);
  }
}

// A friction wall: an elastic block (no initial stress) against a roller at
// x = 0, free on its right, settles under gravity on a rough floor (a
// friction wall: vertical velocity prescribed, "rough": no slip) and is
// damped to rest. The floor carries the weight, and its friction holds the
// block's Poisson spreading: the floor's horizontal force balances the
// roller's (nothing else acts horizontally). At rest (local damping 0.7
// over 40 periods of the block, as above) both to 1e-9 of W.
TEST(Reactions, AFrictionFloorCarriesTheWeightAndBalancesTheWall) {
  Case c;
  c.geostatic = false;
  hmpm::Problem p = column(c, 2.0, 0.5);
  p.grid.cells[0] = 6;  // room to spread on the right
  p.grid.max[0] = 6 * h;
  p.boundaries.resize(2);  // the base and the left roller
  p.boundaries[0].velocity[0].reset();
  p.boundaries[0].friction = std::numeric_limits<double>::infinity();
  p.boundaries[0].nodes = problems::plane(p, 1, 0.0);
  p.boundaries[1].nodes = problems::plane(p, 0, 0.0);
  p.local_damping = problems::constant(0.7);
  const hmpm::RunResult r = run_ok(p, "friction floor");
  const double w = weight(c);
  const std::size_t last = r.reactions.time.size() - 1;
  const double floor_x = force(r, 0, last, 0), wall_x = force(r, 1, last, 0);
  std::printf(
      "friction floor at rest: vertical %.3e of W, horizontal floor %.4g N/m, wall %.4g N/m\n",
      std::abs(force(r, 0, last, 1) - w) / w, floor_x, wall_x);
  EXPECT_NEAR(force(r, 0, last, 1), w, 1e-9 * w);
  EXPECT_NEAR(floor_x + wall_x, 0.0, 1e-9 * w);
  EXPECT_GT(std::abs(floor_x), 1e-3 * w) << "the friction is engaged";
  EXPECT_EQ(force(r, 1, last, 1), 0.0);
}

TEST(Reactions, NoneAskedNoneReported) {
  Case c;
  const hmpm::RunResult r = run_ok(column(c, 0.02, 0.0), "no reactions");
  EXPECT_TRUE(r.reactions.time.empty());
  EXPECT_TRUE(r.reactions.force.empty());
}

}  // namespace
