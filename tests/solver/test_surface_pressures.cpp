// Drained surfaces where the ground is (issue 38, verification §13):
// Terzaghi's consolidation (§3) with its drained top posed by
// surface_pressures on the soil's own face: (0) on the grid's edge (1D),
// and with the grid going on above it: (a) the surface on a node row (1D
// and 2D), (b) the surface in the
// middle of a cell row (2D: a polygon body fills the half cell; a box
// fills whole cells, and with one particle per cell every particle face
// lies on a node row, so (b) has 2 particles per cell only). Every scheme
// and shape function, 1 and 2 particles per cell, against the closed form
// at the particles at least a cell below the surface at T_v = 0.05, 0.1,
// 0.15, 0.2; then refinement, a soft clay that settles through cells
// drained by a surface pressure, and the failure of a node condition the
// soil has left.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "closed_form.hpp"
#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

// A stiff skeleton (undrained over drained stiffness 6) keeps the explicit
// runs short at a small inertia number (test_terzaghi.cpp): 0.2 % of q at
// T_v = 0.05.
constexpr double H = 1.0, q = 1e3, E = 50e6, porosity = 0.3, rho_s = 2650, kw = 75e6, k = 1.2e-5;
constexpr double m_v = 1.0 / E;  // nu = 0
double cv() {
  return k / (1000.0 * 9.81 * (m_v + porosity / kw));
}
double time_of(double tv) {
  return tv * H * H / cv();
}

enum class Where { grid_edge, node_row, mid_cell };

struct Case {
  hmpm::Scheme scheme = hmpm::Scheme::explicit_scheme;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  int ppc = 1;
  int dim = 1;
  Where where = Where::node_row;
  int cells = 20;  ///< cells over the soil's height (b: and a half)
};

const char* name(hmpm::ShapeFunction s) {
  return s == hmpm::ShapeFunction::linear ? "linear"
                                          : (s == hmpm::ShapeFunction::gimp ? "gimp" : "bspline");
}
const char* name(hmpm::Scheme s) {
  return s == hmpm::Scheme::explicit_scheme
             ? "explicit"
             : (s == hmpm::Scheme::semi_implicit ? "semi_implicit" : "quasi_static");
}

/// The column of `c`: soil from 0 to H along the last axis, three empty
/// cells above it (none on the grid's edge), fixed and impermeable at the base, roller walls, the
/// load q on the top row of particles and p = 0 on their top face.
hmpm::Problem column(const Case& c) {
  const int up = c.dim - 1;
  const double h = c.where == Where::mid_cell ? H / (c.cells - 0.5) : H / c.cells;
  const int above = c.where == Where::grid_edge ? 0 : 3;  // empty cells above the soil
  hmpm::Problem p;
  p.dimension = c.dim;
  p.shape_function = c.shape;
  p.time.scheme = c.scheme;
  for (int a = 0; a < c.dim; ++a) {
    p.grid.min[a] = 0.0;
    // Two cells across (2D): the 3-node shape functions' stencil spans
    // three node columns; a one-cell-wide grid has two (check.cpp rejects it).
    p.grid.cells[a] = a == up ? static_cast<int>(std::ceil(H / h - 1e-9)) + above : 2;
    p.grid.max[a] = p.grid.cells[a] * h;
  }
  p.materials.push_back(problems::saturated_elastic(rho_s, E, 0.0, porosity, k, kw));
  hmpm::Body b;
  b.particles_per_cell = c.ppc;
  if (c.where != Where::mid_cell) {
    b.box.min = p.grid.min;
    b.box.max = p.grid.max;
    b.box.max[up] = H;
  } else {
    const double w = p.grid.max[0];
    b.polygon = hmpm::Polygon{{{0.0, 0.0}, {w, 0.0}, {w, H}, {0.0, H}}};
  }
  b.initial.pore_pressure = [](const hmpm::Vec3&) { return q; };
  p.bodies.push_back(b);
  if (c.dim == 2) {
    hmpm::Boundary roller;
    roller.nodes.all = true;
    roller.has_velocity = true;
    roller.velocity[0] = problems::constant(0.0);
    p.boundaries.push_back(roller);
  }
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, up, 0.0), up));
  const double spacing = h / c.ppc;
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  t.particles.min[up] = H - spacing;  // the top row of particles
  t.axis = up;
  t.side = +1;
  t.traction[up] = problems::constant(-q);
  p.tractions.push_back(t);
  hmpm::SurfacePressure s;
  s.particles = t.particles;
  s.axis = up;
  s.side = +1;
  s.pore_pressure = [](const hmpm::Vec3&, double) { return 0.0; };
  p.surface_pressures.push_back(s);
  return p;
}

struct Measured {
  double interior = 0;  ///< max |p - p_exact| / q, a cell or more below the surface
  double all = 0;       ///< the same over every particle
  bool ok = false;
  std::string message;
};

Measured measure(const Case& c, double tv_end = 0.2) {
  hmpm::Problem p = column(c);
  const int up = c.dim - 1;
  const double h = (p.grid.max[up] - p.grid.min[up]) / p.grid.cells[up];
  p.time.end = time_of(tv_end);
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure};
  p.output.series_interval = time_of(0.05);
  const hmpm::RunResult r = hmpm::run(p);
  Measured m;
  m.ok = r.status == hmpm::RunStatus::successful;
  m.message = r.message;
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size();
  for (std::size_t row = 0; row < s.time.size(); ++row) {
    const double tv = s.time[row] / time_of(1.0);
    if (tv < 0.049) continue;
    for (std::size_t i = 0; i < np; ++i) {
      const double z = H - s.initial_positions[i][static_cast<std::size_t>(up)];
      const double err =
          std::abs(s.values[0][row * np + i] - closed_form::terzaghi_pressure(z, tv, H, q)) / q;
      m.all = std::max(m.all, err);
      if (z >= h) m.interior = std::max(m.interior, err);
    }
  }
  return m;
}

// The matrix. Bound: 1.5 % of q (issue 38) in the interior at T_v >= 0.05.
TEST(SurfacePressures, TerzaghiDrainedByTheSoilsOwnSurface) {
  struct Geometry {
    int dim;
    Where where;
    const char* what;
  };
  const Geometry geometries[] = {
      {1, Where::grid_edge, "1D grid edge"},
      {1, Where::node_row, "1D node row"},
      {2, Where::node_row, "2D node row"},
      {2, Where::mid_cell, "2D mid cell"},
  };
  for (const Geometry& g : geometries)
    for (auto scheme :
         {hmpm::Scheme::explicit_scheme, hmpm::Scheme::semi_implicit, hmpm::Scheme::quasi_static})
      for (auto shape :
           {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline})
        for (int ppc : {1, 2}) {
          if (g.where == Where::mid_cell && ppc == 1) continue;  // file comment
          Case c;
          c.scheme = scheme;
          c.shape = shape;
          c.ppc = ppc;
          c.dim = g.dim;
          c.where = g.where;
          const Measured m = measure(c);
          std::printf("[ surface ] %-11s %-13s %-7s %d per cell: interior %.4f, all %.4f of q\n",
                      g.what, name(scheme), name(shape), ppc, m.interior, m.all);
          EXPECT_TRUE(m.ok) << m.message;
          // Open (measured 3.1-3.2 % explicit, 1.5 % semi-implicit): the
          // B-spline at 2 per cell. The cause is the fixed base on the grid's
          // edge, not the surface: the folded B-spline gives the node above
          // the base 1/8 of a uniform stress at 2 per cell, so the column
          // rings at rest (2.4 % of q undrained, no drainage at all). A
          // basis linear in the edge half cells removes it (0.34 %, 0.21 %)
          // but locks elsewhere (docs/verification.md, Known limits).
          if (shape == hmpm::ShapeFunction::bspline && ppc == 2 &&
              scheme != hmpm::Scheme::quasi_static)
            continue;
          // The explicit and semi-implicit schemes: the inertia number
          // (0.2 % of q) and the grid's error (0.1-0.2 %), 0.5 % in all;
          // the quasi-static scheme: its automatic steps' error (1.0-1.3 %
          // measured with every shape function, the same at the grid's
          // edge), the 1.5 %.
          const double bound = scheme == hmpm::Scheme::quasi_static ? 0.015 : 0.005;
          EXPECT_LT(m.interior, bound)
              << g.what << " " << name(scheme) << " " << name(shape) << " " << ppc << " per cell";
        }
}

// Refinement (1D, surface on a node row, explicit, 2 per cell, linear and
// GIMP): the error falls with the cell size. (B-spline at 2 per cell: the
// fixed base's ringing above, 1.1, 3.1, 1.5 % at 10, 20, 40 cells.)
TEST(SurfacePressures, ErrorFallsUnderRefinement) {
  for (auto shape : {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp}) {
    double previous = 1.0;
    for (int cells : {10, 20, 40}) {
      Case c;
      c.shape = shape;
      c.ppc = 2;
      c.cells = cells;
      const Measured m = measure(c);
      std::printf("[ surface ] refinement %s %d cells: interior %.5f, all %.5f of q\n", name(shape),
                  cells, m.interior, m.all);
      EXPECT_TRUE(m.ok) << m.message;
      EXPECT_LT(m.all, previous) << name(shape) << " " << cells << " cells";
      previous = m.all;
    }
  }
}

// A soft clay that settles through cells (issue 38): 8 m, k = 2e-9 m/s,
// real water, E_oed = 1 MPa under q = 50 kPa (a final log strain of 5 %:
// the top settles 0.39 m, two cells of 0.2 m), quasi-static with automatic
// steps, drained at its top by a surface pressure. The degree of
// consolidation from the settlement (sum over particles of l0 (1 -
// exp(strain)) over its final value H (1 - exp(-q/E_oed)), the log strain
// of a hypoelastic column) and from the pore pressure (1 - mean p / q)
// agree within 1 % (their difference from the large strain alone is below
// 0.6 %: q/E_oed/2 times the variance of the local degree), the
// settlement reaches 99 % of its final value, and no suction appears.
struct Clay {
  double h = 8.0, q = 50e3, e = 1e6, kw = 2.2e9, k = 2e-9, porosity = 0.5;
  int cells = 40, ppc = 2;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  bool node_condition = false;  ///< drained by p = 0 on the nodes from the surface up instead
  double cv() const { return k / (1000.0 * 9.81 * (1.0 / e + porosity / kw)); }
  double time_of(double tv) const { return tv * h * h / cv(); }
};

hmpm::Problem clay_column(const Clay& c) {
  const double dh = c.h / c.cells;
  hmpm::Problem p;
  p.dimension = 1;
  p.shape_function = c.shape;
  p.time.scheme = hmpm::Scheme::quasi_static;
  p.grid.min[0] = 0.0;
  p.grid.cells[0] = c.cells + 3;
  p.grid.max[0] = p.grid.cells[0] * dh;
  p.materials.push_back(problems::saturated_elastic(2650.0, c.e, 0.0, c.porosity, c.k, c.kw));
  hmpm::Body b;
  b.particles_per_cell = c.ppc;
  b.box.min = p.grid.min;
  b.box.max = p.grid.max;
  b.box.max[0] = c.h;
  b.initial.pore_pressure = [q = c.q](const hmpm::Vec3&) { return q; };
  p.bodies.push_back(b);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::Traction t;
  t.particles.min = p.grid.min;
  t.particles.max = p.grid.max;
  t.particles.min[0] = c.h - dh / c.ppc;
  t.axis = 0;
  t.traction[0] = problems::constant(-c.q);
  p.tractions.push_back(t);
  if (c.node_condition) {
    hmpm::NodeSelection above;
    above.box.min = p.grid.min;
    above.box.max = p.grid.max;
    above.box.min[0] = c.h;
    p.boundaries.push_back(problems::fixed_pressure(above, 0.0));
  } else {
    hmpm::SurfacePressure s;
    s.particles = t.particles;
    s.axis = 0;
    s.seepage = true;  // a drained top: water leaves, never enters
    p.surface_pressures.push_back(s);
  }
  p.time.end = c.time_of(2.5);
  const auto n = hmpm::count_particles(p);
  for (std::int64_t i = 0; i < n; ++i) p.output.series_particles.push_back(i);
  p.output.series_fields = {hmpm::Field::pore_pressure, hmpm::Field::strain};
  p.output.series_interval = c.time_of(0.05);
  return p;
}

/// The degree of consolidation of a settling clay run: the worst
/// |U_settlement - U_pressure| while U_pressure <= 99 %, the last U from the
/// settlement, and the least pore pressure.
struct Settling {
  double worst = 0, last_u = 0, min_p = 0, settlement = 0;
};
Settling settling(const Clay& c, const hmpm::RunResult& r) {
  const hmpm::Series& s = r.series;
  const std::size_t np = s.particles.size();
  const double l0 = c.h / static_cast<double>(np);
  const double final_settlement = c.h * (1.0 - std::exp(-c.q / c.e));
  Settling out;
  for (std::size_t row = 1; row < s.time.size(); ++row) {
    double settlement = 0, mean_p = 0;
    for (std::size_t i = 0; i < np; ++i) {
      const double pi = s.values[0][row * np + i];
      mean_p += pi / static_cast<double>(np);
      out.min_p = std::min(out.min_p, pi);
      settlement += l0 * (1.0 - std::exp(s.values[1][(row * np + i) * 6]));
    }
    const double u_s = settlement / final_settlement, u_p = 1.0 - mean_p / c.q;
    if (u_p <= 0.99) out.worst = std::max(out.worst, std::abs(u_s - u_p));
    out.last_u = u_s;
    out.settlement = settlement;
  }
  return out;
}

// With GIMP and B-splines (the shape functions for soil that moves through
// cells). Linear shape functions settle 1.5 % short here (U_s - U_p 1.2 %):
// their particles crossing cells is an error of its own, and the run says
// so (the crossing warning, asserted). Before the face weights balanced the
// load (issue 38), linear showed suction (-0.097 q) and B-spline 1.5 %.
TEST(SurfacePressures, SoftClaySettlingThroughCellsKeepsDraining) {
  for (auto shape :
       {hmpm::ShapeFunction::gimp, hmpm::ShapeFunction::bspline, hmpm::ShapeFunction::linear}) {
    Clay c;
    c.shape = shape;
    const hmpm::RunResult r = hmpm::run(clay_column(c));
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    ASSERT_GT(c.h * (1.0 - std::exp(-c.q / c.e)), 1.5 * c.h / c.cells);  // crosses a cell and more
    const Settling m = settling(c, r);
    std::printf(
        "[ surface ] settling clay %s: |U_settlement - U_pressure| <= %.4f to U = 99 %%, final "
        "U %.4f, min p %.5f of q\n",
        name(shape), m.worst, m.last_u, m.min_p / c.q);
    if (shape == hmpm::ShapeFunction::linear) {
      bool warned = false;
      for (const std::string& w : r.warnings) warned |= w.find("crossed") != std::string::npos;
      EXPECT_TRUE(warned) << "linear shape functions crossing cells warn";
      continue;
    }
    EXPECT_LT(m.worst, 0.01);
    EXPECT_GT(m.last_u, 0.99);
    EXPECT_LT(m.last_u, 1.005);
    EXPECT_GT(m.min_p, -0.005 * c.q);  // no suction
  }
}

// A 10 % strain (q = E_oed ln(1/0.9) = 0.105 E_oed: the top settles
// 0.8 m, four cells of 0.2 m), GIMP, under refinement (20, 40, 80 cells):
// the final settlement against the closed form of the hypoelastic column,
// H (1 - exp(-q/E_oed)), and the settlement at T_v = 0.2 between grids,
// whose differences fall.
TEST(SurfacePressures, TenPerCentStrainConvergesUnderRefinement) {
  double previous_gap = 1.0, previous_mid = 0.0;
  for (int cells : {20, 40, 80}) {
    Clay c;
    c.shape = hmpm::ShapeFunction::gimp;
    c.q = -c.e * std::log(0.9);  // a final log strain of ln 0.9
    c.cells = cells;
    hmpm::Problem p = clay_column(c);
    p.output.series_interval = c.time_of(0.2);
    const hmpm::RunResult r = hmpm::run(p);
    ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
    const Settling m = settling(c, r);
    const double exact = c.h * 0.1;
    // The settlement at T_v = 0.2 (row 1).
    const hmpm::Series& s = r.series;
    const std::size_t np = s.particles.size();
    double mid = 0;
    for (std::size_t i = 0; i < np; ++i)
      mid += c.h / static_cast<double>(np) * (1.0 - std::exp(s.values[1][(np + i) * 6]));
    std::printf(
        "[ surface ] 10 %% strain, %d cells: final settlement %.5f m (closed form %.5f), at T_v = "
        "0.2 %.5f m, |U_s - U_p| <= %.4f, min p %.5f of q\n",
        cells, m.settlement, exact, mid, m.worst, m.min_p / c.q);
    EXPECT_NEAR(m.settlement, exact, 0.005 * exact);
    EXPECT_GT(m.min_p, -0.005 * c.q);
    if (previous_mid > 0) {
      const double gap = std::abs(mid - previous_mid);
      EXPECT_LT(gap, previous_gap) << cells << " cells";
      previous_gap = gap;
    }
    previous_mid = mid;
  }
}

// The same clay drained by p = 0 on the nodes from its surface up (what
// a node condition offers): once the soil has settled out of their reach
// the node condition drains nothing, and the run stops saying so (rather
// than finishing `successful` with frozen settlement and suction), naming
// the condition and advising surface_pressures. Stop, not a warning: every
// result after that moment is wrong, and a warning would leave a
// successful run to be read.
TEST(SurfacePressures, NodeConditionTheSoilHasLeftStopsTheRun) {
  Clay c;
  c.node_condition = true;
  const hmpm::RunResult r = hmpm::run(clay_column(c));
  EXPECT_EQ(r.status, hmpm::RunStatus::failed);
  EXPECT_NE(r.message.find("boundaries[1].pore_pressure reaches no soil"), std::string::npos)
      << r.message;
  EXPECT_NE(r.message.find("surface_pressures"), std::string::npos) << r.message;
  // It stopped after some consolidation, before the end.
  ASSERT_FALSE(r.series.time.empty());
  EXPECT_LT(r.series.time.back(), c.time_of(2.5));
}

}  // namespace

namespace {

// A pore pressure held where the soil no longer is (issue 38: a water
// table posed on every node, "nodes": "all", keeps its pressure in space):
// here 1.5 MPa on every node of a soft saturated column with a free top
// (E_oed = 1 MPa), so that its effective stress becomes that pressure in
// tension and the column swells to 2.5 times its volume and overshoots.
// Soil does not do that; the run says so, naming the likely cause and
// surface_pressures. With a grid too short for the swelling, the particle
// that leaves it fails the run, and the advice names the swelling before
// the grid's size.
hmpm::Problem swelling_column(double grid_height) {
  hmpm::Problem p;
  p.dimension = 1;
  p.grid.min[0] = 0.0;
  p.grid.max[0] = grid_height;
  p.grid.cells[0] = static_cast<int>(std::lround(grid_height / 0.05));
  p.materials.push_back(problems::saturated_elastic(2650.0, 1e6, 0.0, 0.4, 1e-6, 2.2e9));
  hmpm::Body b;
  b.particles_per_cell = 2;
  b.box.min = p.grid.min;
  b.box.max = p.grid.max;
  b.box.max[0] = 1.0;
  p.bodies.push_back(b);
  p.boundaries.push_back(problems::fixed_velocity(problems::plane(p, 0, 0.0), 0));
  hmpm::NodeSelection all;
  all.all = true;
  p.boundaries.push_back(problems::fixed_pressure(all, 1.5e6));
  p.local_damping = problems::constant(0.2);
  p.time.end = 0.5;
  return p;
}

}  // namespace

TEST(SurfacePressures, APressureHeldWhereTheSoilWasSwellsItAndTheRunSaysSo) {
  const hmpm::RunResult r = hmpm::run(swelling_column(8.0));
  ASSERT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  bool warned = false;
  for (const std::string& w : r.warnings)
    if (w.find("particle volumes outside 0.5-1.5") != std::string::npos) {
      std::printf("[ surface ] warning: %s\n", w.c_str());
      warned = true;
      EXPECT_NE(w.find("surface_pressures"), std::string::npos) << w;
      EXPECT_NE(w.find("held where the soil no longer is"), std::string::npos) << w;
    }
  EXPECT_TRUE(warned) << "no volume warning";

  const hmpm::RunResult short_grid = hmpm::run(swelling_column(1.5));
  ASSERT_EQ(short_grid.status, hmpm::RunStatus::failed) << short_grid.message;
  std::printf("[ surface ] failure: %s\n", short_grid.message.c_str());
  EXPECT_NE(short_grid.message.find("left the grid"), std::string::npos) << short_grid.message;
  EXPECT_NE(short_grid.message.find("but first: the particle's volume is"), std::string::npos)
      << short_grid.message;

  // A consolidating column (the settling clay above) gives no such warning.
  Clay c;
  c.shape = hmpm::ShapeFunction::gimp;
  const hmpm::RunResult clay = hmpm::run(clay_column(c));
  for (const std::string& w : clay.warnings)
    EXPECT_EQ(w.find("particle volumes outside"), std::string::npos) << w;
}
