// run_watch.hpp — plausibility of the state during a run (internal): pore
// pressure below cavitation, tensile total stress in a material without
// tensile strength, and particles whose volume left a plausible range for
// soil (issue 38). The time loop calls check() every few steps (a few
// hundred times per run at most): one pass over the particles that counts
// and keeps the first and the worst finding, no allocation, no string.
// The messages are built once, at the end (messages()). The run still ends
// as it ends; these become RunResult::run_warnings (docs/job-spec.md,
// "Plausibility warnings").
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "materials/material.hpp"
#include "state/particles.hpp"

namespace hmpm {

/// Gauge pore pressure (hmpm's p is relative to the atmosphere) below which
/// water cavitates: absolute pressure about zero (-101.3 kPa gauge, rounded).
inline constexpr double cavitation_pressure = -100e3;
/// Major principal total stress above which a material without tensile
/// strength counts as in tension (tension positive): 1 kPa, well above the
/// noise of a free surface, far below any stress that matters.
inline constexpr double tension_tolerance = 1e3;
/// The range of a saturated particle's volume ratio to the stage's start
/// that soil can reach (its volume changes only by the water that flows in
/// or out): a soft clay compressed from e = 3 to e = 1 keeps 0.5 of its
/// volume, and drained swelling on unloading (kappa ln(ratio) / (1 + e))
/// or dilation is a few to 20 %. Past it, something other than the soil's
/// behaviour drives the volume (water pushed in by a pressure held where
/// the soil has gone, particles pulled apart). Dry particles are not
/// watched: at a runout's thin front their volumes stretch (1.77 times in
/// examples/column-collapse.json) with no water to account for.
inline constexpr double volume_ratio_low = 0.5, volume_ratio_high = 1.5;
static_assert(cavitation_pressure == -100e3 && tension_tolerance == 1e3 &&
                  volume_ratio_low == 0.5 && volume_ratio_high == 1.5,
              "RunWatch::messages() states the thresholds in words");

template <int Dim>
class RunWatch {
 public:
  /// A finding: how many (particle, check) pairs, the first and the worst.
  struct Finding {
    std::int64_t count = 0;
    double first_time = 0, first_value = 0, worst_time = 0, worst_value = 0;
    std::size_t first_particle = 0, worst_particle = 0;
    Eigen::Matrix<double, Dim, 1> first_x, worst_x;
  };

  /// ps: the particles at the stage's start (their volumes are the
  /// reference of the volume ratio).
  RunWatch(const Problem& problem, const std::vector<MaterialConstants>& constants,
           const ParticleState<Dim>& ps)
      : saturated_(constants.size()), tensionless_(constants.size()), volume0_(ps.volume) {
    for (std::size_t m = 0; m < constants.size(); ++m) {
      saturated_[m] = constants[m].saturated ? 1 : 0;
      tensionless_[m] = no_tensile_strength(problem.materials[m]) ? 1 : 0;
      any_ = any_ || saturated_[m] != 0 || tensionless_[m] != 0;
    }
  }

  /// Whether any material can produce a finding (else check() is not worth calling).
  bool active() const { return any_; }

  /// One pass over the particles at time t.
  void check(const ParticleState<Dim>& ps, double t) {
    const bool fluid = !ps.pressure_out.empty();
    for (std::size_t p = 0; p < ps.size(); ++p) {
      const std::size_t m = ps.material[p];
      if (saturated_[m]) {
        const double j = volume_ratio(ps, p);
        if (j > 0 && (j < volume_ratio_low || j > volume_ratio_high))
          note(volume_, p, ps.x[p], t, j,
               std::abs(std::log(j)) > std::abs(std::log(volume_.worst_value)));
      }
      const double pw = fluid && saturated_[m] ? ps.pressure_out[p] : 0.0;
      if (pw < cavitation_pressure)
        note(cavitation_, p, ps.x[p], t, pw, pw < cavitation_.worst_value);
      if (!tensionless_[m]) continue;
      const Voigt& s = ps.stress[p];
      // Total stress sigma' - p I. Gershgorin's bound first: most particles
      // are in compression and need no eigenvalues.
      const double d0 = s[0] - pw, d1 = s[1] - pw, d2 = s[2] - pw;
      const double a3 = std::abs(s[3]), a4 = std::abs(s[4]), a5 = std::abs(s[5]);
      const double bound = std::max({d0 + a3 + a5, d1 + a3 + a4, d2 + a4 + a5});
      if (bound <= tension_tolerance) continue;
      Eigen::Matrix3d sigma;
      sigma << d0, s[3], s[5], s[3], d1, s[4], s[5], s[4], d2;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(sigma, Eigen::EigenvaluesOnly);
      const double major = eig.eigenvalues().maxCoeff();
      if (major > tension_tolerance)
        note(tension_, p, ps.x[p], t, major, major > tension_.worst_value);
    }
  }

  const Finding& cavitation() const { return cavitation_; }
  const Finding& tension() const { return tension_; }

  /// Particle p's volume over its volume at the stage's start.
  double volume_ratio(const ParticleState<Dim>& ps, std::size_t p) const {
    return p < volume0_.size() && volume0_[p] > 0 ? ps.volume[p] / volume0_[p] : 1.0;
  }

  /// The advice a failure of particle p adds when its volume has left the
  /// plausible range (a particle that swelled and then left the grid: the
  /// grid's size is not the cause); empty otherwise.
  std::string volume_advice(const ParticleState<Dim>& ps, std::size_t p) const {
    if (!saturated_[ps.material[p]]) return {};
    const double j = volume_ratio(ps, p);
    // (j <= 0: the volume failure itself, which says what to change.)
    if (!(j > 0) || !(j > volume_ratio_high || j < volume_ratio_low)) return {};
    return "; but first: the particle's volume is " + number(j) +
           " times its volume at the stage's start, past what soil does (0.5-1.5), so the "
           "cause is more likely what drove that volume than the grid's size: " +
           volume_causes(j > 1.0);
  }

  /// The warnings, one per kind found (built here, once per run).
  std::vector<std::string> messages() const {
    std::vector<std::string> out;
    if (cavitation_.count > 0)
      out.push_back(
          "during the run: pore pressure below cavitation (-100 kPa gauge, i.e. absolute "
          "pressure below zero; hmpm's pore pressure is relative to the atmosphere) at " +
          where(cavitation_) +
          ". Water cannot sustain that suction: it cavitates (which the u-p model does not "
          "model), so the result is not physical there. Likely causes: a load applied faster "
          "than the water can flow (too fast for the hydraulic_conductivity: the soil is "
          "pulled or sheared undrained), or a dilating soil (dilatancy_angle > 0) sucking water "
          "in. What to change: apply the load more slowly (a longer ramp), check the "
          "hydraulic_conductivity and the load's sign, or use dilatancy_angle 0");
    if (volume_.count > 0)
      out.push_back(
          "during the run: particle volumes outside 0.5-1.5 times their volume at "
          "the stage's start, past what soil does, at " +
          where(volume_, " times its volume at the stage's start") + ". " +
          volume_causes(volume_.worst_value > 1.0));
    if (tension_.count > 0)
      out.push_back(
          "during the run: tensile total stress (major principal total stress above 1 kPa, "
          "tension positive) in a material without tensile strength (Mohr-Coulomb or "
          "Drucker-Prager with cohesion 0 and tensile_strength 0) at " +
          where(tension_) +
          ". Such a soil can carry tension only through suction of its pore water (which "
          "cavitates at about -100 kPa), so the soil is being pulled apart. Likely causes: a "
          "load pulling the soil (a traction's sign: compression is a negative traction on a "
          "'+' face), a boundary moving away from the soil, or a fast load with negative pore "
          "pressure. What to change: check the loads' signs and boundaries; if the soil "
          "has some strength, give it cohesion or a tensile_strength (a tension cut-off)");
    return out;
  }

  /// Whether the material has no tensile strength: Mohr-Coulomb or
  /// Drucker-Prager with cohesion 0 and tensile_strength 0.
  static bool no_tensile_strength(const Material& m) {
    if (const auto* mc = std::get_if<MohrCoulomb>(&m.plasticity))
      return mc->cohesion == 0 && mc->tensile_strength == 0;
    if (const auto* dp = std::get_if<DruckerPrager>(&m.plasticity))
      return dp->cohesion == 0 && dp->tensile_strength == 0;
    return false;
  }

 private:
  template <class X>
  static void note(Finding& f, std::size_t p, const X& x, double t, double value, bool worse) {
    if (f.count == 0) {
      f.first_time = f.worst_time = t;
      f.first_value = f.worst_value = value;
      f.first_particle = f.worst_particle = p;
      f.first_x = f.worst_x = x;
    } else if (worse) {
      f.worst_time = t;
      f.worst_value = value;
      f.worst_particle = p;
      f.worst_x = x;
    }
    ++f.count;
  }

  static std::string number(double v) { return format_significant(v, 4); }

  /// What swells (or shrinks) soil particles that far, and what to change.
  static std::string volume_causes(bool swelling) {
    if (swelling)
      return "Likely causes: water pushed into the soil by a pore pressure held where the "
             "soil no longer is (a node condition fixed in space, e.g. on \"nodes\": \"all\" "
             "or a region, after the soil has moved: it keeps its pressure where the soil used "
             "to be), or soil pulled apart (a load's sign, a boundary moving away). What to "
             "change: pose pore pressures on the soil itself with surface_pressures, which move "
             "with it (docs/job-spec.md, where to put drained boundaries), end a node "
             "condition with a stage when the soil leaves it, and check the loads' signs";
    return "Likely causes: a load far above the soil's strength or stiffness, or a "
           "volumetric locking of linear shape functions under a large deformation. What to "
           "change: check the load and the moduli, or use \"gimp\" or \"bspline\"";
  }

  static std::string at(double t, std::size_t p, const Eigen::Matrix<double, Dim, 1>& x, double v,
                        const char* unit) {
    std::string s = "t = " + number(t) + " s, particle " + std::to_string(p) + " at (";
    for (int a = 0; a < Dim; ++a) s += (a ? ", " : "") + number(x[a]);
    return s + "), " + number(v) + unit;
  }

  std::string where(const Finding& f, const char* unit = " Pa") const {
    return "first " + at(f.first_time, f.first_particle, f.first_x, f.first_value, unit) +
           "; the extreme " + at(f.worst_time, f.worst_particle, f.worst_x, f.worst_value, unit) +
           " (" + std::to_string(f.count) +
           " findings over the particles and the checks, one check every few steps)";
  }

  std::vector<char> saturated_, tensionless_;
  std::vector<double> volume0_;  ///< the particles' volumes at the stage's start
  bool any_ = false;
  Finding cavitation_, tension_, volume_;
};

}  // namespace hmpm
