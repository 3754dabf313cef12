// random_fields/random_field.cpp — the separable Markov field by the
// Ornstein-Uhlenbeck recursion along each axis (hmpm/random_field.hpp says
// why it is exact).
#include "hmpm/random_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>

namespace hmpm {

double RandomField::mean() const {
  return distribution == Distribution::uniform ? 0.5 * (first + second) : first;
}

double RandomField::standard_deviation() const {
  switch (distribution) {
    case Distribution::lognormal:
      return first * second;
    case Distribution::normal:
      return second;
    case Distribution::uniform:
      return (second - first) / std::sqrt(12.0);
  }
  return 0.0;
}

double transform_gaussian(const RandomField& field, double g) {
  switch (field.distribution) {
    case RandomField::Distribution::lognormal: {
      const double s2 = std::log1p(field.second * field.second);
      return std::exp(std::log(field.first) - 0.5 * s2 + std::sqrt(s2) * g);
    }
    case RandomField::Distribution::normal:
      return field.first + field.second * g;
    case RandomField::Distribution::uniform:
      return field.first + (field.second - field.first) * 0.5 * std::erfc(-g / std::sqrt(2.0));
  }
  return 0.0;
}

namespace {

/// Standard normal deviates from a 64-bit Mersenne twister (its sequence is
/// fixed by the C++ standard) by Box-Muller, both of each pair used.
class Normals {
 public:
  explicit Normals(std::uint64_t seed) : engine_(seed) {}
  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    constexpr double two_pi = 6.283185307179586476925;
    const double u1 = uniform_open(), u2 = uniform_open();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(two_pi * u2);
    has_spare_ = true;
    return r * std::cos(two_pi * u2);
  }

 private:
  double uniform_open() {  // in (0, 1]
    return (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
  }
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// One axis of the lattice: its node coordinates (sorted) and each point's
/// node on it.
struct Axis {
  std::vector<double> nodes;
  std::vector<std::size_t> of_point;
};

/// The points' distinct coordinates along axis a (within 1e-9 of the
/// extent): exact lattice.
Axis distinct_axis(const std::vector<std::array<double, 3>>& points, int a) {
  Axis axis;
  std::vector<double> x(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) x[p] = points[p][static_cast<std::size_t>(a)];
  std::vector<double> sorted = x;
  std::sort(sorted.begin(), sorted.end());
  const double tol = 1e-9 * std::max(1.0, sorted.empty() ? 0.0 : sorted.back() - sorted.front());
  for (double v : sorted)
    if (axis.nodes.empty() || v - axis.nodes.back() > tol) axis.nodes.push_back(v);
  axis.of_point.resize(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    auto it = std::lower_bound(axis.nodes.begin(), axis.nodes.end(), x[p] - tol);
    axis.of_point[p] = static_cast<std::size_t>(it - axis.nodes.begin());
  }
  return axis;
}

/// A regular lattice along axis a covering the points, spacing
/// coarsen * theta / 16; one node where theta is infinite or the points
/// have no extent.
Axis regular_axis(const std::vector<std::array<double, 3>>& points, int a, double theta,
                  double coarsen) {
  Axis axis;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : points) {
    lo = std::min(lo, p[static_cast<std::size_t>(a)]);
    hi = std::max(hi, p[static_cast<std::size_t>(a)]);
  }
  const double extent = hi - lo;
  std::size_t n = 1;
  double spacing = 1.0;
  if (extent > 0 && std::isfinite(theta)) {
    spacing = coarsen * theta / 16.0;
    n = static_cast<std::size_t>(std::ceil(extent / spacing)) + 1;
  }
  for (std::size_t i = 0; i < n; ++i) axis.nodes.push_back(lo + static_cast<double>(i) * spacing);
  axis.of_point.resize(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    const double s = n > 1 ? (points[p][static_cast<std::size_t>(a)] - lo) / spacing : 0.0;
    axis.of_point[p] = std::min(n - 1, static_cast<std::size_t>(std::lround(s)));
  }
  return axis;
}

}  // namespace

std::vector<double> gaussian_field(const RandomField& field, int dim,
                                   const std::vector<std::array<double, 3>>& points) {
  if (points.empty()) return {};
  std::vector<Axis> axes;
  std::size_t size = 1;
  for (int a = 0; a < dim; ++a) {
    axes.push_back(distinct_axis(points, a));
    size *= axes.back().nodes.size();
  }
  // Scattered points: a regular lattice, coarsened until it holds at most
  // 2^25 nodes (256 MiB of deviates).
  for (double coarsen = 1.0; size > 8 * points.size(); coarsen *= 1.5) {
    axes.clear();
    size = 1;
    for (int a = 0; a < dim; ++a) {
      axes.push_back(
          regular_axis(points, a, field.correlation_length[static_cast<std::size_t>(a)], coarsen));
      size *= axes.back().nodes.size();
    }
    if (size <= (std::size_t{1} << 25)) break;
  }
  // Independent deviates at every lattice node (axis 0 fastest), then the
  // recursion along each axis in turn, in place.
  std::vector<double> g(size);
  Normals normals(field.seed);
  for (double& v : g) v = normals.next();
  std::size_t stride = 1;
  std::vector<double> rho, innovation;  // the recursion's coefficients along one axis
  for (int a = 0; a < dim; ++a) {
    const Axis& axis = axes[static_cast<std::size_t>(a)];
    const std::size_t n = axis.nodes.size();
    const double theta = field.correlation_length[static_cast<std::size_t>(a)];
    rho.assign(n, 0.0);
    innovation.assign(n, 1.0);
    for (std::size_t i = 1; i < n; ++i) {
      rho[i] =
          std::isfinite(theta) ? std::exp(-2.0 * (axis.nodes[i] - axis.nodes[i - 1]) / theta) : 1.0;
      innovation[i] = std::sqrt(std::max(0.0, 1.0 - rho[i] * rho[i]));
    }
    const std::size_t block = stride * n;
    for (std::size_t start = 0; start < size; start += block)
      for (std::size_t offset = 0; offset < stride; ++offset) {
        double* line = g.data() + start + offset;
        for (std::size_t i = 1; i < n; ++i)
          line[i * stride] = rho[i] * line[(i - 1) * stride] + innovation[i] * line[i * stride];
      }
    stride = block;
  }
  std::vector<double> out(points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    std::size_t index = 0, scale = 1;
    for (int a = 0; a < dim; ++a) {
      index += axes[static_cast<std::size_t>(a)].of_point[p] * scale;
      scale *= axes[static_cast<std::size_t>(a)].nodes.size();
    }
    out[p] = g[index];
  }
  return out;
}

std::vector<double> sample_random_field(const RandomField& field, int dim,
                                        const std::vector<std::array<double, 3>>& points) {
  std::vector<double> y = gaussian_field(field, dim, points);
  for (double& v : y) v = transform_gaussian(field, v);
  return y;
}

}  // namespace hmpm
