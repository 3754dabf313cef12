// hmpm/random_field.hpp — spatially correlated random fields of a material
// parameter (contract v3, "Ensembles and random fields").
//
// The field is Y(x) = T(G(x)), G a stationary standard Gaussian field with
// the separable Markov correlation
//     rho_G(d) = prod_a exp(-2 |d_a| / theta_a)
// (theta_a the correlation length along axis a, Vanmarcke's scale of
// fluctuation; theta_a = infinity: G constant along that axis), and T the
// transform that gives Y the target distribution:
//     lognormal(mean m, cov v): Y = exp(mu + s G), s^2 = ln(1 + v^2), mu = ln m - s^2 / 2
//     normal(mean m, std s):    Y = m + s G
//     uniform(min a, max b):    Y = a + (b - a) Phi(G)
// so Y has the target's mean and variance exactly, and the correlation
// length is that of the underlying Gaussian (as Griffiths and Fenton use it
// for ln c_u). Point values, no local averaging.
//
// Generation is exact, not approximate: the exponential correlation along
// one axis is the Ornstein-Uhlenbeck process, whose values at sorted
// coordinates x_0 < x_1 < ... follow the recursion
//     g_0 = w_0,  g_i = a_i g_{i-1} + sqrt(1 - a_i^2) w_i,  a_i = exp(-2 (x_i - x_{i-1}) / theta)
// with independent standard normal w_i; the separable field on the tensor
// lattice of the points' distinct coordinates is that recursion applied
// along each axis in turn (the lattice covariance is the Kronecker product
// of the axes' covariances, and the recursion along each axis is the
// Cholesky factor of its own). O(lattice size), any spacing, reproducible
// from the seed (a 64-bit Mersenne twister and Box-Muller written out, so
// the same seed gives the same field with any standard library), and
// independent of the thread count. Points whose distinct coordinates would
// make a lattice over 8 times the point count (scattered explicit
// particles) take the value at the nearest node of a regular lattice of
// spacing theta_a / 16 per axis instead (coarsened if it would exceed 2^25
// nodes): points closer than that share a value.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace hmpm {

struct RandomField {
  enum class Distribution { lognormal, normal, uniform };
  Distribution distribution = Distribution::normal;
  /// lognormal: (mean, cov); normal: (mean, std); uniform: (min, max).
  double first = 0.0, second = 0.0;
  /// Per axis, m; infinity: perfectly correlated along that axis.
  std::array<double, 3> correlation_length = {std::numeric_limits<double>::infinity(),
                                              std::numeric_limits<double>::infinity(),
                                              std::numeric_limits<double>::infinity()};
  std::uint64_t seed = 0;

  /// The target distribution's mean and standard deviation.
  double mean() const;
  double standard_deviation() const;
};

/// The standard Gaussian field G at each point (dim coordinates used).
std::vector<double> gaussian_field(const RandomField& field, int dim,
                                   const std::vector<std::array<double, 3>>& points);

/// T(g): the target distribution's value for a standard normal g.
double transform_gaussian(const RandomField& field, double g);

/// The field's values Y = T(G) at the points.
std::vector<double> sample_random_field(const RandomField& field, int dim,
                                        const std::vector<std::array<double, 3>>& points);

}  // namespace hmpm
