// collapse_watch.hpp — a collapse in the schemes that follow the soil's
// motion (explicit, semi_implicit; internal). docs/job-spec.md "Collapse".
//
// These schemes have no equilibrium to lose: past a limit load the soil
// accelerates and runs out, and the run follows it. What shows a collapse
// there is displacement on the scale of the ground itself: criterion
// `large_displacement`, a particle that has yielded and has moved more than
// `collapse_fraction` (10 %) of the soil's height from its initial position
// (x0: the job's start, or the last stage that reset the displacements).
// Elastic ground under its own weight moves rho g H^2 / (2 E)
// (0.1 % of H for a stiff soil, 1 % for a very soft one), consolidation
// settles a few per cent slowly and mostly without yielding: neither gets
// near 10 % of the height while yielding. A mechanism (a slope sliding, a
// footing punching, a column spreading) gets there within about
// sqrt(2 * 0.1 H / g) of free fall at the fastest, and the test
// (tests/solver/test_dynamic_collapse.cpp) checks both sides.
//
// The soil's height: the extent of the particles' initial positions (x0)
// along gravity; without gravity, the smallest non-zero extent of their
// bounding box. Both come from the checkpointed state (x, x0, plastic
// strain), so a run resumed from a checkpoint finds a collapse it had not
// found before at the same check as the uninterrupted run (a collapse found
// before the checkpoint is not in it: the resumed run finds it again at its
// first check). The time loop calls check() every few steps (about
// 500 times per stage, with the run watch): one pass over the particles,
// no allocation after construction, no string until found.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "state/particles.hpp"

namespace hmpm {

/// A yielding particle's displacement from x0, as a fraction of the
/// soil's height, beyond which a dynamic run reports a collapse.
inline constexpr double collapse_fraction = 0.1;

/// The soil's height (the file comment): the extent of the particles'
/// initial positions along `stage`'s gravity; without gravity, the
/// smallest non-zero extent of their bounding box; +inf without particles.
template <int Dim>
double soil_height(const Problem& stage, const ParticleState<Dim>& ps) {
  using Vec = VecD<Dim>;
  double height = 0.0;
  if (ps.size() == 0) return std::numeric_limits<double>::infinity();
  Vec lo = ps.x0[0], hi = ps.x0[0];
  for (const Vec& x : ps.x0) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  Vec g;
  for (int a = 0; a < Dim; ++a) g[a] = stage.gravity[static_cast<std::size_t>(a)];
  if (g.norm() > 0.0) {
    const Vec down = g / g.norm();
    double top = std::numeric_limits<double>::infinity(), bottom = -top;
    for (const Vec& x : ps.x0) {
      top = std::min(top, x.dot(down));
      bottom = std::max(bottom, x.dot(down));
    }
    height = bottom - top;
  }
  if (!(height > 0.0)) {
    height = std::numeric_limits<double>::infinity();
    for (int a = 0; a < Dim; ++a)
      if (hi[a] > lo[a]) height = std::min(height, hi[a] - lo[a]);
  }
  return height;
}

template <int Dim>
class CollapseWatch {
 public:
  using Vec = VecD<Dim>;

  /// For the particles in the run at the stage's start. Inactive (check()
  /// never finds anything) in the quasi-static scheme, which has its own
  /// criteria, and in runs without plastic particles.
  CollapseWatch(const Problem& stage, const ParticleState<Dim>& ps)
      : active_(stage.time.scheme != Scheme::quasi_static && !ps.plastic_strain.empty() &&
                ps.size() > 0) {
    if (!active_) return;
    plastic_ = ps.plastic_strain;
    height_ = soil_height(stage, ps);
    active_ = std::isfinite(height_) && height_ > 0.0;
  }

  bool active() const { return active_; }
  double height() const { return height_; }

  /// One pass at time t: true the first time a yielding particle has moved
  /// more than collapse_fraction of the height; `k` then holds the finding
  /// (everything but the load and the message, which the caller adds).
  bool check(const ParticleState<Dim>& ps, double t, RunResult::Collapse& k) {
    if (!active_ || found_) return false;
    const double limit = collapse_fraction * height_;
    double worst = 0.0, moved = 0.0;
    std::int64_t yielding = 0;
    Vec lo = Vec::Zero(), hi = Vec::Zero();
    for (std::size_t p = 0; p < ps.size(); ++p) {
      const double d = (ps.x[p] - ps.x0[p]).norm();
      moved = std::max(moved, d);
      // Yielding in the last check window: the mechanism as it is now.
      if (ps.plastic_strain[p] > plastic_[p]) {
        lo = yielding ? lo.cwiseMin(ps.x[p]) : ps.x[p];
        hi = yielding ? hi.cwiseMax(ps.x[p]) : ps.x[p];
        ++yielding;
      }
      if (ps.plastic_strain[p] > 0.0) worst = std::max(worst, d);
      plastic_[p] = ps.plastic_strain[p];
    }
    if (!(worst > limit)) return false;
    found_ = true;
    k.found = true;
    k.time = t;
    k.criterion = "large_displacement";
    k.max_displacement = moved;
    k.yielding = yielding;
    k.yield_min = {0.0, 0.0, 0.0};
    k.yield_max = {0.0, 0.0, 0.0};
    for (int a = 0; a < Dim; ++a) {
      k.yield_min[static_cast<std::size_t>(a)] = lo[a];
      k.yield_max[static_cast<std::size_t>(a)] = hi[a];
    }
    worst_ = worst;
    return true;
  }

  /// The largest displacement of a particle that has yielded, when found.
  double worst() const { return worst_; }

 private:
  bool active_ = false;
  bool found_ = false;
  double height_ = 0.0;
  double worst_ = 0.0;
  std::vector<double> plastic_;  ///< plastic strain at the last check
};

}  // namespace hmpm
