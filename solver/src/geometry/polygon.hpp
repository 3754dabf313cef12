// geometry/polygon.hpp — plane polygons (internal, header only): where a
// point lies (inside, outside, on the boundary), area, perimeter and the
// checks that make a polygon simple. Used by the particle layout of polygon
// and prism bodies and by polygon selections (problem/layout.cpp), so filling and
// selecting agree on every point.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

namespace hmpm::geometry {

using Point2 = std::array<double, 2>;

enum class Where { outside, inside, boundary };

/// Distance from p to the segment [a, b].
inline double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double len2 = dx * dx + dy * dy;
  double t = 0.0;
  if (len2 > 0.0) t = std::clamp(((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2, 0.0, 1.0);
  const double ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
  return std::sqrt(ex * ex + ey * ey);
}

/// Where p lies with respect to the polygon (vertices in order, closed
/// implicitly, either orientation): on the boundary when within `tol` of an
/// edge, else inside or outside by the even-odd rule. The crossing test
/// counts an edge when it straddles the horizontal line through p with the
/// half-open rule (one endpoint strictly above, the other on or below), so
/// a ray through a vertex is counted once and horizontal edges never.
inline Where locate(const std::vector<Point2>& poly, const Point2& p, double tol) {
  const std::size_t n = poly.size();
  bool inside = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point2& a = poly[j];
    const Point2& b = poly[i];
    if (segment_distance(p, a, b) <= tol) return Where::boundary;
    if ((a[1] > p[1]) != (b[1] > p[1])) {
      const double x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
      if (p[0] < x) inside = !inside;
    }
  }
  return inside ? Where::inside : Where::outside;
}

/// Inside the polygon or within `tol` of its boundary.
inline bool inside_or_on(const std::vector<Point2>& poly, const Point2& p, double tol) {
  return locate(poly, p, tol) != Where::outside;
}

/// Signed area (shoelace): positive for counter-clockwise vertices.
inline double signed_area(const std::vector<Point2>& poly) {
  double twice = 0.0;
  const std::size_t n = poly.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
    twice += poly[j][0] * poly[i][1] - poly[i][0] * poly[j][1];
  return 0.5 * twice;
}

inline double perimeter(const std::vector<Point2>& poly) {
  double sum = 0.0;
  const std::size_t n = poly.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
    sum += std::hypot(poly[i][0] - poly[j][0], poly[i][1] - poly[j][1]);
  return sum;
}

/// Bounding box: {min x, min y}, {max x, max y}.
inline std::pair<Point2, Point2> bounds(const std::vector<Point2>& poly) {
  Point2 lo = poly.front(), hi = poly.front();
  for (const Point2& v : poly)
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], v[a]);
      hi[a] = std::max(hi[a], v[a]);
    }
  return {lo, hi};
}

namespace detail {

/// Orientation of c relative to the line a->b: +1 left, -1 right, 0 when
/// within `tol` (an area tolerance) of collinear.
inline int orientation(const Point2& a, const Point2& b, const Point2& c, double tol) {
  const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  if (std::abs(cross) <= tol) return 0;
  return cross > 0 ? 1 : -1;
}

/// c, collinear with [a, b], lies within its bounding box.
inline bool on_segment(const Point2& a, const Point2& b, const Point2& c) {
  return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= c[1] && c[1] <= std::max(a[1], b[1]);
}

}  // namespace detail

/// Whether the closed segments [a, b] and [c, d] share a point (crossing,
/// touching or overlapping). `tol` is an area tolerance for collinearity.
inline bool segments_intersect(const Point2& a, const Point2& b, const Point2& c, const Point2& d,
                               double tol) {
  using detail::on_segment;
  using detail::orientation;
  const int o1 = orientation(a, b, c, tol), o2 = orientation(a, b, d, tol);
  const int o3 = orientation(c, d, a, tol), o4 = orientation(c, d, b, tol);
  if (o1 != o2 && o3 != o4 && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
         (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

/// The first two edges (edge i runs from vertex i to vertex i + 1, the last
/// back to vertex 0) that make the polygon not simple: non-adjacent edges
/// sharing a point, or adjacent edges folding back onto each other.
/// std::nullopt for a simple polygon. O(n^2): for the few vertices of a
/// spec's polygon.
inline std::optional<std::pair<std::size_t, std::size_t>> self_intersection(
    const std::vector<Point2>& poly) {
  const std::size_t n = poly.size();
  if (n < 3) return std::nullopt;
  const auto [lo, hi] = bounds(poly);
  const double extent = std::max(hi[0] - lo[0], hi[1] - lo[1]);
  const double tol = 1e-12 * extent * extent;
  auto vertex = [&](std::size_t k) -> const Point2& { return poly[k % n]; };
  for (std::size_t i = 0; i < n; ++i) {
    const Point2& a = vertex(i);
    const Point2& b = vertex(i + 1);
    // Adjacent edge i+1 folds back onto edge i when its far end is
    // collinear and lies on edge i (or edge i's start lies on it).
    const Point2& c = vertex(i + 2);
    if (detail::orientation(a, b, c, tol) == 0 &&
        (detail::on_segment(a, b, c) || detail::on_segment(b, c, a)))
      return std::make_pair(i, (i + 1) % n);
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through vertex 0
      if (segments_intersect(a, b, vertex(j), vertex(j + 1), tol)) return std::make_pair(i, j);
    }
  }
  return std::nullopt;
}

}  // namespace hmpm::geometry
