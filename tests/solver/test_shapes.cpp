// Shaped bodies (issue 17): the point-in-polygon geometry, polygon, prism and
// points bodies, first-listed-wins overlaps and polygon selections.
//
// Mass of a polygon body. Particles sit at the centres of sub-cells of side
// s = h / particles_per_cell and each carries s^2 of area; a sub-cell whose
// centre lies inside (or on) the polygon counts whole. Only sub-cells
// crossed by the boundary contribute an error. Along a straight edge the
// centre is inside only when at least half the sub-cell is (a half-plane
// through a square covers at least half of it when it contains the centre,
// and at most half when it does not), so each crossed sub-cell errs by at
// most s^2 / 2; a straight edge of length L crosses at most
// L (|cos| + |sin|) / s + 2 <= sqrt(2) L / s + 2 sub-cells. Summed over the
// edges (vertex sub-cells counted with both edges, where the half-plane
// argument fails, err by at most s^2 each):
//   |A_particles - A| <= sqrt(2)/2 * P * s + 2 N s^2     (P perimeter, N vertices)
// which halves when s halves: first order in the sub-cell size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "../../solver/src/geometry/polygon.hpp"
#include "../../solver/src/particle_layout.hpp"
#include "hmpm/run.hpp"

namespace {

using hmpm::geometry::Point2;
using hmpm::geometry::Where;

std::vector<Point2> square() {
  return {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
}

TEST(Polygon, LocatesInsideOutsideAndOnTheBoundary) {
  const auto sq = square();
  const double tol = 1e-9;
  EXPECT_EQ(hmpm::geometry::locate(sq, {1, 1}, tol), Where::inside);
  EXPECT_EQ(hmpm::geometry::locate(sq, {3, 1}, tol), Where::outside);
  EXPECT_EQ(hmpm::geometry::locate(sq, {-1e-3, 1}, tol), Where::outside);
  EXPECT_EQ(hmpm::geometry::locate(sq, {2, 1}, tol), Where::boundary);      // on an edge
  EXPECT_EQ(hmpm::geometry::locate(sq, {2, 2}, tol), Where::boundary);      // a vertex
  EXPECT_EQ(hmpm::geometry::locate(sq, {1, 1e-10}, tol), Where::boundary);  // within tol
  // Clockwise order gives the same answers.
  std::vector<Point2> cw(sq.rbegin(), sq.rend());
  EXPECT_EQ(hmpm::geometry::locate(cw, {1, 1}, tol), Where::inside);
  EXPECT_EQ(hmpm::geometry::locate(cw, {3, 1}, tol), Where::outside);
}

TEST(Polygon, RayThroughAVertexCountsOnce) {
  // A diamond: the horizontal ray from (0, 0) passes through vertex (1, 0)
  // and (-1, 0) is behind; points level with the side vertices.
  const std::vector<Point2> diamond{{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  EXPECT_EQ(hmpm::geometry::locate(diamond, {0, 0}, 1e-12), Where::inside);
  EXPECT_EQ(hmpm::geometry::locate(diamond, {-2, 0}, 1e-12), Where::outside);
  EXPECT_EQ(hmpm::geometry::locate(diamond, {2, 0}, 1e-12), Where::outside);
  // A concave L: the ray from (0.5, 1) runs along the horizontal edge y = 1.
  const std::vector<Point2> ell{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_EQ(hmpm::geometry::locate(ell, {0.5, 1.5}, 1e-12), Where::inside);
  EXPECT_EQ(hmpm::geometry::locate(ell, {1.5, 1.5}, 1e-12), Where::outside);
  EXPECT_EQ(hmpm::geometry::locate(ell, {0.5, 1.0}, 1e-12), Where::inside);
  EXPECT_EQ(hmpm::geometry::locate(ell, {1.5, 1.0}, 1e-12), Where::boundary);
  EXPECT_DOUBLE_EQ(hmpm::geometry::signed_area(ell), 3.0);
  EXPECT_DOUBLE_EQ(hmpm::geometry::perimeter(ell), 8.0);
}

TEST(Polygon, FindsSelfIntersections) {
  EXPECT_FALSE(hmpm::geometry::self_intersection(square()));
  const std::vector<Point2> bowtie{{0, 0}, {2, 2}, {2, 0}, {0, 2}};
  ASSERT_TRUE(hmpm::geometry::self_intersection(bowtie));
  EXPECT_EQ(hmpm::geometry::self_intersection(bowtie)->first, 0u);
  EXPECT_EQ(hmpm::geometry::self_intersection(bowtie)->second, 2u);
  // An edge folding back onto the previous one.
  const std::vector<Point2> fold{{0, 0}, {2, 0}, {1, 0}, {1, 1}};
  EXPECT_TRUE(hmpm::geometry::self_intersection(fold));
  // A vertex touching a non-adjacent edge.
  const std::vector<Point2> touch{{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}};
  EXPECT_TRUE(hmpm::geometry::self_intersection(touch));
  // Collinear consecutive vertices along a straight side are fine.
  const std::vector<Point2> straight{{0, 0}, {1, 0}, {2, 0}, {2, 2}};
  EXPECT_FALSE(hmpm::geometry::self_intersection(straight));
}

hmpm::Problem ground(int cells_x, int cells_y) {
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.min = {0, 0, 0};
  p.grid.max = {10, 4, 0};
  p.grid.cells = {cells_x, cells_y, 1};
  hmpm::Material m;
  m.name = "fill";
  m.density = 2000.0;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  p.materials.push_back(m);
  p.time.end = 1e-3;
  return p;
}

hmpm::Body polygon_body(std::vector<Point2> vertices, int ppc) {
  hmpm::Body b;
  b.polygon = hmpm::Polygon{std::move(vertices)};
  b.particles_per_cell = ppc;
  return b;
}

double body_volume(const hmpm::Problem& p, std::size_t b) {
  const auto layouts = hmpm::body_layouts(p);
  double v = 0.0;
  for (double x : layouts[b].volumes) v += x;
  return v;
}

double area_bound(const std::vector<Point2>& poly, double s) {
  return std::numbers::sqrt2 / 2 * hmpm::geometry::perimeter(poly) * s +
         2.0 * static_cast<double>(poly.size()) * s * s;
}

TEST(PolygonBody, MassIsDensityTimesAreaToTheResolution) {
  // A trapezoid embankment (base 8 m, crest 4 m, 2 m high) and a triangle
  // with edges at no grid angle, on cells of 0.5 m.
  const std::vector<std::vector<Point2>> shapes{{{1, 0}, {9, 0}, {7, 2}, {3, 2}},
                                                {{0.3, 0.2}, {8.7, 0.4}, {4.1, 3.3}}};
  for (const auto& poly : shapes) {
    const double area = std::abs(hmpm::geometry::signed_area(poly));
    for (int ppc : {1, 2, 4, 8}) {
      hmpm::Problem p = ground(20, 8);
      p.bodies.push_back(polygon_body(poly, ppc));
      ASSERT_TRUE(hmpm::check_problem(p).empty());
      const double s = 0.5 / ppc;
      const double mass = 2000.0 * body_volume(p, 0);
      const double error = std::abs(mass - 2000.0 * area) / (2000.0 * area);
      const double bound = area_bound(poly, s) / area;
      std::printf(
          "polygon of %zu vertices, %d particles per cell: relative mass error %.3e "
          "(bound %.3e)\n",
          poly.size(), ppc, error, bound);
      EXPECT_LE(error, bound) << ppc;
    }
  }
}

TEST(PolygonBody, ErrorShrinksUnderRefinement) {
  // The generic triangle's measured error at 2 and 4 particles per cell
  // (the rule converges at first order; a drop below 0.75 of the coarser
  // error, not the full 0.5, leaves room for the sign changes of a
  // staircase).
  const std::vector<Point2> tri{{0.3, 0.2}, {8.7, 0.4}, {4.1, 3.3}};
  const double area = std::abs(hmpm::geometry::signed_area(tri));
  double err[2];
  int k = 0;
  for (int ppc : {2, 8}) {
    hmpm::Problem p = ground(20, 8);
    p.bodies.push_back(polygon_body(tri, ppc));
    err[k++] = std::abs(body_volume(p, 0) - area);
  }
  EXPECT_LT(err[1], 0.75 * err[0]);
}

/// No two particles within 1e-9 m of each other.
void expect_distinct(const std::vector<hmpm::Vec3>& x) {
  std::vector<hmpm::Vec3> sorted = x;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    const double d = std::hypot(sorted[i][0] - sorted[i - 1][0], sorted[i][1] - sorted[i - 1][1],
                                sorted[i][2] - sorted[i - 1][2]);
    EXPECT_GT(d, 1e-9) << "two particles at (" << sorted[i][0] << ", " << sorted[i][1] << ")";
  }
}

TEST(Overlap, FirstBodyWinsBetweenBoxes) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body a;
  a.box = {{0, 0, 0}, {6, 2, 0}};
  hmpm::Body b = a;
  b.box = {{4, 0, 0}, {10, 2, 0}};
  b.particles_per_cell = 3;  // a different lattice: still no overlap in mass
  p.bodies = {a, b};
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  expect_distinct(hmpm::initial_positions(p));
  // Volume of the union, 10 m x 2 m, to round-off: the later box keeps
  // only its cells outside the first.
  EXPECT_NEAR(body_volume(p, 0) + body_volume(p, 1), 20.0, 1e-12);
  EXPECT_NEAR(body_volume(p, 1), 8.0, 1e-12);
  const auto layouts = hmpm::body_layouts(p);
  ASSERT_EQ(layouts[1].lost.size(), 1u);
  EXPECT_EQ(layouts[1].lost[0].first, 0u);
  EXPECT_EQ(layouts[1].lost[0].second, 4 * 4 * 9);  // 4 x 4 cells, 9 particles each
  const auto warnings = hmpm::problem_warnings(p);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].where.text(), "bodies/1");
  EXPECT_NE(warnings[0].message.find("overlaps body 0: 144 of its particle positions"),
            std::string::npos)
      << warnings[0].message;
}

TEST(Overlap, IdenticalBoxesNoLongerDoubleTheMass) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body a;
  a.box = {{0, 0, 0}, {10, 2, 0}};
  p.bodies = {a, a};
  const auto issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.text(), "bodies/1");
  EXPECT_NE(issues[0].message.find("lies inside an earlier body"), std::string::npos);
}

TEST(Overlap, PolygonsBoxesAndPointsNeverShareAPlace) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body foundation;
  foundation.box = {{0, 0, 0}, {10, 1, 0}};
  // An embankment whose polygon reaches into the foundation, and a second
  // polygon sharing its right slope.
  p.bodies.push_back(foundation);
  p.bodies.push_back(polygon_body({{1, 0}, {9, 0}, {7, 3}, {3, 3}}, 2));
  p.bodies.push_back(polygon_body({{7, 3}, {9, 0}, {10, 0}, {10, 3}}, 2));
  hmpm::Body pts;
  pts.points = hmpm::ParticleList{{{0.125, 0.125, 0}, {9.9, 3.9, 0}}, {0.0625, 0.01}};
  p.bodies.push_back(pts);
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  expect_distinct(hmpm::initial_positions(p));
  const auto layouts = hmpm::body_layouts(p);
  EXPECT_EQ(layouts[3].count, 1);  // (0.125, 0.125) is a foundation particle
  // Foundation 10 m^2 + the embankment above y = 1 + the right wedge above
  // y = 1 (both to the resolution: 2 x the bound of each polygon).
  double total = 0.0;
  for (std::size_t b = 0; b < 3; ++b) total += body_volume(p, b);
  const double embankment_above = 0.5 * (8.0 - 4.0 / 3.0 + 4.0) * 2.0;  // y from 1 to 3
  const double wedge_above = 0.5 * ((1.0 + 2.0 / 3.0) + 3.0) * 2.0;     // x from the slope to 10
  EXPECT_NEAR(total, 10.0 + embankment_above + wedge_above,
              2 * area_bound({{1, 0}, {9, 0}, {7, 3}, {3, 3}}, 0.25));
}

// The checks and estimates lay out the bodies without keeping positions
// (LayoutDetail::counts; a million-particle job calls them a dozen times):
// the counts, filled extents and losses must be those of the full layout,
// with a points body listed first so that later bodies test against it.
TEST(Overlap, CountingLayoutAgreesWithTheFullOne) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body pts;
  pts.points = hmpm::ParticleList{{{0.125, 0.125, 0}, {9.9, 3.9, 0}}, {0.0625, 0.01}};
  p.bodies.push_back(pts);
  hmpm::Body foundation;
  foundation.box = {{0, 0, 0}, {10, 1, 0}};
  p.bodies.push_back(foundation);
  p.bodies.push_back(polygon_body({{1, 0}, {9, 0}, {7, 3}, {3, 3}}, 2));
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  const auto full = hmpm::body_layouts(p);
  const auto counted = hmpm::body_layouts(p, hmpm::LayoutDetail::counts);
  ASSERT_EQ(full.size(), counted.size());
  for (std::size_t b = 0; b < full.size(); ++b) {
    EXPECT_EQ(counted[b].count, full[b].count) << b;
    EXPECT_EQ(full[b].count, static_cast<std::int64_t>(full[b].positions.size())) << b;
    EXPECT_TRUE(counted[b].positions.empty()) << b;
    EXPECT_EQ(counted[b].lost, full[b].lost) << b;
    for (int a = 0; a < 2; ++a) {
      EXPECT_EQ(counted[b].lo[a], full[b].lo[a]) << b;
      EXPECT_EQ(counted[b].hi[a], full[b].hi[a]) << b;
    }
  }
  EXPECT_EQ(full[1].lost.size(), 1u);  // the foundation lost (0.125, 0.125) to the points
  EXPECT_EQ(hmpm::count_particles(p), full[0].count + full[1].count + full[2].count);
}

TEST(PointsBody, ReproducesPositionsAndVolumes) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body b;
  const std::vector<hmpm::Vec3> x{{1.1, 0.3, 0}, {2.05, 0.7, 0}, {1.6, 1.9, 0}};
  b.points = hmpm::ParticleList{x, {0.02, 0.03, 0.04}};
  p.bodies.push_back(b);
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  EXPECT_EQ(hmpm::initial_positions(p), x);
  const auto layouts = hmpm::body_layouts(p);
  EXPECT_EQ(layouts[0].volumes, (std::vector<double>{0.02, 0.03, 0.04}));
  const hmpm::RunResult r = hmpm::run(p);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_EQ(r.particles, 3);
}

TEST(PointsBody, ChecksLengthsVolumesAndTheGrid) {
  hmpm::Problem p = ground(20, 8);
  hmpm::Body b;
  b.points = hmpm::ParticleList{{{1, 1, 0}, {11, 1, 0}}, {0.1, -1, 3}};
  p.bodies.push_back(b);
  std::vector<std::string> where;
  for (const auto& i : hmpm::check_problem(p)) where.push_back(i.where.text());
  EXPECT_EQ(where, (std::vector<std::string>{"bodies/0/points/volumes", "bodies/0/points/volumes/1",
                                             "bodies/0/points/positions/1"}));
}

TEST(PointsBody, GimpRefusesParticlesLargerThanACell) {
  // Cells of 0.5 m x 0.5 m: a particle of 0.25 m^2 fills one exactly (its
  // box's half-length is half a cell, the most GIMP's 3-node stencil holds);
  // 0.3 m^2 would reach a fourth node and lose that share of its mass.
  hmpm::Problem p = ground(20, 8);
  hmpm::Body b;
  b.points = hmpm::ParticleList{{{1, 1, 0}, {3, 1, 0}, {5, 1, 0}}, {0.25, 0.3, 0.1}};
  p.bodies.push_back(b);
  for (auto shape : {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::bspline}) {
    p.shape_function = shape;
    EXPECT_TRUE(hmpm::check_problem(p).empty());
  }
  p.shape_function = hmpm::ShapeFunction::gimp;
  const auto issues = hmpm::check_problem(p);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].where.text(), "bodies/0/points/volumes/1");
  EXPECT_NE(issues[0].message.find("bspline"), std::string::npos) << issues[0].message;
}

TEST(PrismBody, MassIsDensityTimesAreaTimesLength) {
  // A trapezoid extruded along z over [0.5, 2.5] (cell faces, so the length
  // is exact), and the same polygon in the (y, z) plane extruded along x.
  const std::vector<Point2> trap{{0.5, 0}, {3.5, 0}, {2.5, 1.5}, {1.5, 1.5}};
  const double area = std::abs(hmpm::geometry::signed_area(trap));
  for (int axis : {2, 0}) {
    hmpm::Problem p;
    p.dimension = 3;
    p.grid.min = {0, 0, 0};
    p.grid.max = {4, 4, 4};
    p.grid.cells = {8, 8, 8};
    hmpm::Material m;
    m.density = 1800.0;
    m.youngs_modulus = 1e7;
    p.materials.push_back(m);
    hmpm::Body b;
    b.prism = hmpm::Prism{hmpm::Polygon{trap}, axis, 0.5, 2.5};
    b.particles_per_cell = 2;
    p.bodies.push_back(b);
    p.time.end = 1e-3;
    ASSERT_TRUE(hmpm::check_problem(p).empty());
    const double mass = 1800.0 * body_volume(p, 0);
    const double exact = 1800.0 * area * 2.0;
    const double bound = 1800.0 * area_bound(trap, 0.25) * 2.0;
    std::printf("prism along %c: mass %.6g, rho A L %.6g, bound %.3g\n", "xyz"[axis], mass, exact,
                bound);
    EXPECT_LE(std::abs(mass - exact), bound);
    // Sharper: the extrusion of the same polygon's 2D filling (same cells,
    // same particles per cell) times the length, to round-off.
    hmpm::Problem flat = ground(8, 8);
    flat.grid.max = {4, 4, 0};
    flat.bodies.push_back(polygon_body(trap, 2));
    EXPECT_NEAR(mass, 1800.0 * body_volume(flat, 0) * 2.0, 1e-9 * exact);
    // Along the axis, particles lie strictly inside [from, to].
    for (const auto& x : hmpm::initial_positions(p)) {
      EXPECT_GT(x[axis], 0.5);
      EXPECT_LT(x[axis], 2.5);
    }
  }
}

TEST(PolygonSelection, PicksExactlyTheNodesInsideOrOn) {
  hmpm::Problem p = ground(10, 4);  // nodes 1 m apart, 11 x 5
  hmpm::NodeSelection sel;
  sel.polygon = hmpm::Polygon{{{0, 0}, {4, 0}, {0, 4}}};
  int count = 0;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 10; ++i) {
      const bool picked = hmpm::node_selected(p, sel, {double(i), double(j), 0});
      EXPECT_EQ(picked, i + j <= 4) << i << ", " << j;
      count += picked ? 1 : 0;
    }
  EXPECT_EQ(count, 15);  // 5 + 4 + 3 + 2 + 1, the hypotenuse's 5 included
  // Round-off in a vertex (0.1 + 0.2 != 0.3) still keeps the node on the edge.
  sel.polygon = hmpm::Polygon{{{0, 0}, {0.1 + 0.2 - 0.3 + 4, 0}, {0, 4}}};
  EXPECT_TRUE(hmpm::node_selected(p, sel, {2, 2, 0}));
  // Beyond the tolerance (1e-6 of a cell): not selected.
  EXPECT_FALSE(hmpm::node_selected(p, sel, {2 + 1e-4, 2, 0}));
}

TEST(PolygonSelection, TractionLoadsTheParticlesInsideOrOn) {
  hmpm::Problem p = ground(20, 8);
  p.bodies.push_back(polygon_body({{1, 0}, {9, 0}, {7, 2}, {3, 2}}, 2));
  hmpm::Traction t;
  t.polygon = hmpm::Polygon{{{0, 1.75}, {10, 1.75}, {10, 2}, {0, 2}}};
  std::size_t n = 0;
  for (const auto& x : hmpm::initial_positions(p)) n += hmpm::particle_selected(p, t, x) ? 1 : 0;
  // The top row at y = 1.875, x from 2.875 to 7.125 (both ends on the
  // 45-degree slopes, so inside): 18 particles.
  EXPECT_EQ(n, 18u);
}

TEST(PolygonChecks, ReportEachProblemWithItsLocation) {
  struct Case {
    std::vector<Point2> v;
    const char* where;
    const char* part;
  };
  const Case cases[] = {
      {{{0, 0}, {1, 0}}, "bodies/0/polygon", "at least 3"},
      {{{0, 0}, {3, 2}, {3, 0}, {0, 1}}, "bodies/0/polygon", "not a simple polygon"},
      {{{0, 0}, {1, 1}, {2, 2}}, "bodies/0/polygon", "zero area"},
      {{{0, 0}, {2, 0}, {2, 2}, {0, 0}}, "bodies/0/polygon/3", "repeats vertex 0"},
  };
  for (const Case& c : cases) {
    hmpm::Problem p = ground(20, 8);
    p.bodies.push_back(polygon_body(c.v, 2));
    const auto issues = hmpm::check_problem(p);
    ASSERT_EQ(issues.size(), 1u) << c.where;
    EXPECT_EQ(issues[0].where.text(), c.where);
    EXPECT_NE(issues[0].message.find(c.part), std::string::npos) << issues[0].message;
  }
  hmpm::Problem p3 = ground(20, 8);
  p3.dimension = 3;
  p3.grid.max[2] = 1;
  p3.bodies.push_back(polygon_body({{0, 0}, {2, 0}, {2, 2}}, 2));
  const auto issues = hmpm::check_problem(p3);
  ASSERT_FALSE(issues.empty());
  EXPECT_EQ(issues[0].where.text(), "bodies/0/polygon");
  EXPECT_NE(issues[0].message.find("'prism'"), std::string::npos);
}

}  // namespace
