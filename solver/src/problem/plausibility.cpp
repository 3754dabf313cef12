// problem/plausibility.cpp — see plausibility.hpp. The ranges and rules are
// documented in docs/job-spec.md ("Plausibility warnings"); a change here
// changes that table.
#include "problem/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "hmpm/format.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"

namespace hmpm {

namespace {

/// A range of usual values of one parameter, with what a value outside it
/// most likely is and what to give instead.
struct UsualRange {
  const char* key;
  double lo, hi;
  const char* unit;
  const char* range_text;  ///< the range in words, with examples
  const char* below;       ///< the likely mistake when below lo
  const char* above;       ///< the likely mistake when above hi
};

// Young's modulus of the skeleton: from very soft clay and peat (~0.1-1 MPa)
// to intact strong rock (~100 GPa); steel is 200 GPa.
constexpr UsualRange youngs_range{
    "youngs_modulus",
    1e5,
    1e11,
    "Pa",
    "1e5 Pa (very soft clay, 0.1 MPa) to 1e11 Pa (strong intact rock, 100 GPa)",
    "likely a value in kPa or MPa given in Pa (hmpm's stresses and moduli are in Pa: 5 MPa is "
    "5e6)",
    "likely a value in kPa given in Pa twice over, or a modulus in Pa multiplied by 1000 (hmpm's "
    "moduli are in Pa: 50 GPa is 5e10)"};
// Grain density rho_s (materials with hydraulic): organic soils ~1300-2000,
// quartz 2650, most minerals 2600-2900, heavy ores up to ~5000.
constexpr UsualRange grain_density_range{
    "density",
    1300,
    3500,
    "kg/m3",
    "1300 kg/m3 (organic soil grains) to 3500 kg/m3 (heavy minerals); quartz is 2650",
    "likely g/cm3 given for kg/m3 (2.65 g/cm3 is 2650), a unit weight in kN/m3 (18 kN/m3 is "
    "1835 kg/m3), or the mixture's density where the grains' is meant",
    "likely g/m3 or a unit weight in N/m3 given for kg/m3 (2650 kg/m3 is 2.65 g/cm3)"};
// Bulk density of a dry (no hydraulic) material: loose dry sand ~1400,
// compacted fill ~1800-2100, rock 2200-3000 (peat lower still, rare).
constexpr UsualRange bulk_density_range{
    "density",
    1000,
    3500,
    "kg/m3",
    "1000 kg/m3 (loose or organic dry soil) to 3500 kg/m3 (dense rock)",
    "likely g/cm3 given for kg/m3 (1.8 g/cm3 is 1800) or a unit weight in kN/m3 (18 kN/m3 is "
    "1835 kg/m3)",
    "likely g/m3 or a unit weight in N/m3 given for kg/m3"};
// Hydraulic conductivity k (m/s): clean gravel ~1e-2-1, sand 1e-5-1e-3,
// silt 1e-8-1e-5, clay 1e-11-1e-8, intact rock down to ~1e-13.
constexpr UsualRange conductivity_range{
    "hydraulic_conductivity",
    1e-13,
    1.0,
    "m/s",
    "1e-13 m/s (intact rock, unweathered clay) to 1 m/s (open gravel); sand is 1e-5 to 1e-3, "
    "clay 1e-11 to 1e-8",
    "likely an intrinsic permeability in m2 given for the hydraulic conductivity in m/s (for "
    "water k [m/s] ~ 1e7 x kappa [m2]), or an exponent off by orders of magnitude",
    "likely a value in cm/s or mm/s read as m/s, or a wrong exponent sign (1e+5 for 1e-5)"};
// Porosity n: dense rock ~0.01-0.05, sand 0.25-0.5, soft clay 0.4-0.7,
// peat up to ~0.9.
constexpr UsualRange porosity_range{
    "porosity",
    0.05,
    0.9,
    "",
    "0.05 (dense rock) to 0.9 (peat); sand is 0.25 to 0.5, soft clay 0.4 to 0.7",
    "likely a percentage divided twice (30 % is 0.3) or a rock that the u-p model of a soil "
    "hardly suits",
    "likely a void ratio e given for the porosity (n = e/(1+e): e = 1 is n = 0.5)"};

/// The value times 1e3, 1e6, 1e-3 or 1e-6 (the first that lands in the
/// range): the likely fix of a unit slip; "" when none does.
std::string rescaled(double v, const UsualRange& r) {
  static constexpr double factors[] = {1e3, 1e6, 1e-3, 1e-6};
  for (double f : factors)
    if (const double w = v * f; w >= r.lo && w <= r.hi) return format4(w);
  return {};
}

void check_range(double v, const UsualRange& r, const Location& where,
                 std::vector<ProblemIssue>& out) {
  if (!(v < r.lo || v > r.hi)) return;
  const bool low = v < r.lo;
  std::string message =
      "is " + format4(v) + (r.unit[0] ? std::string(" ") + r.unit : "") + ", far " +
      (low ? "below" : "above") + " the usual range of soils and rocks (" + r.range_text +
      "): " + (low ? r.below : r.above) + ". What to change: check the value and its unit";
  const std::string fix = rescaled(v, r);
  if (!fix.empty()) message += " (e.g. " + fix + " " + r.unit + ")";
  message += "; if the value is deliberate (a non-dimensional benchmark), ignore this warning";
  out.push_back({where / r.key, std::move(message)});
}

struct StrengthOf {
  bool plastic = false;
  double phi = 0.0, c = 0.0, tension = 0.0;
};

StrengthOf strength_of(const Material& m) {
  StrengthOf s;
  if (const auto* mc = std::get_if<MohrCoulomb>(&m.plasticity)) {
    s = {true, mc->friction_angle_deg, mc->cohesion, mc->tensile_strength};
  } else if (const auto* dp = std::get_if<DruckerPrager>(&m.plasticity)) {
    s = {true, dp->friction_angle_deg, dp->cohesion, dp->tensile_strength};
  }
  return s;
}

// Friction angles: loose sand ~28-32, dense sand and gravel 35-45, rock
// joints 25-45; above 50 degrees no soil, and few rock masses, reach.
constexpr double max_friction_deg = 50.0;
// Cohesion: a soil's effective cohesion is 0-50 kPa, an undrained strength
// 10-200 kPa, a rock mass's up to tens of MPa. Below 100 Pa (but not 0) a
// value is almost surely kPa given as Pa; above 100 MPa beyond intact rock.
constexpr double min_cohesion = 100.0;
constexpr double max_cohesion = 1e8;
// Poisson's ratio of a drained soil skeleton 0.1-0.4; undrained behaviour
// comes from the pore fluid in the u-p model. A dry material may stand for
// undrained clay in total stress (nu up to ~0.49).
constexpr double max_nu_saturated = 0.45;
constexpr double max_nu_dry = 0.49;

void check_strength(const Material& m, const Location& w, std::vector<ProblemIssue>& out) {
  const StrengthOf s = strength_of(m);
  if (!s.plastic) return;
  if (s.phi > max_friction_deg)
    out.push_back({w / "friction_angle",
                   "is " + format4(s.phi) +
                       " degrees, above the friction angle of soils and rock joints (about 25 to "
                       "45 degrees; 50 at most for dense angular gravel): the material would be "
                       "unrealistically strong, and its dilatancy bound is as high. What to "
                       "change: check the value (degrees, not percent or grade), e.g. 30 to 40 "
                       "for sand"});
  else if (s.phi > 0 && s.phi < 1.6)
    out.push_back(
        {w / "friction_angle",
         "is " + format4(s.phi) + " degrees: likely an angle in radians (" + format4(s.phi) +
             " rad is " + format4(s.phi * 180.0 / std::numbers::pi) +
             " degrees). What to change: give friction_angle in degrees (usually 20 to 45)"});
  if (s.c > 0 && s.c < min_cohesion)
    out.push_back({w / "cohesion",
                   "is " + format4(s.c) +
                       " Pa, far below any soil's cohesion worth modelling (0, or 1 kPa to 200 "
                       "kPa for soils, up to tens of MPa for rock masses): likely kPa given as "
                       "Pa. What to change: give cohesion in Pa (10 kPa is 1e4), or 0 for a "
                       "cohesionless soil"});
  if (s.c > max_cohesion)
    out.push_back({w / "cohesion",
                   "is " + format4(s.c) +
                       " Pa, above the cohesion of intact strong rock (soils 0 to 200 kPa, rock "
                       "masses up to tens of MPa): likely a value in kPa given in Pa twice over. "
                       "What to change: give cohesion in Pa (50 kPa is 5e4)"});
}

void check_poisson(const Material& m, const Location& w, std::vector<ProblemIssue>& out) {
  const double nu = m.poisson_ratio;
  const double max_nu = m.hydraulic ? max_nu_saturated : max_nu_dry;
  if (nu > max_nu) {
    const std::string why =
        m.hydraulic
            ? "for a saturated material nu is the drained skeleton's (soils 0.1 to 0.4); the "
              "pore fluid already makes the undrained response nearly incompressible. What to "
              "change: use the drained Poisson's ratio, e.g. 0.3"
            : "near 0.5 the skeleton is nearly incompressible: the P-wave speed and so the "
              "number of explicit steps grow without bound and linear elements lock. What to "
              "change: 0.45 or less, or model the water with 'hydraulic' and a drained "
              "Poisson's ratio (0.2 to 0.35)";
    out.push_back({w / "poisson_ratio",
                   "is " + format4(nu) + " (at most " + format4(max_nu) + " is usual): " + why});
  } else if (nu < 0) {
    out.push_back({w / "poisson_ratio",
                   "is " + format4(nu) +
                       ": soils and rocks have Poisson's ratios between 0 and 0.5 (0.1 to 0.4 "
                       "drained). What to change: check the sign, e.g. 0.3"});
  }
}

}  // namespace

std::vector<ProblemIssue> material_plausibility(const Problem& problem) {
  std::vector<ProblemIssue> out;
  for (const Material& m : problem.materials) {
    const Location w{"materials", m.name};
    check_range(m.youngs_modulus, youngs_range, w, out);
    check_range(m.density, m.hydraulic ? grain_density_range : bulk_density_range, w, out);
    check_poisson(m, w, out);
    check_strength(m, w, out);
    if (const auto* mc = std::get_if<MohrCoulomb>(&m.plasticity); mc && mc->softening) {
      const MohrCoulomb::Softening& s = *mc->softening;
      // Without the regularisation the plastic strain localises in a band
      // about a cell wide, so the softening (and a runout) follows the grid.
      if (s.reference_cell_size <= 0)
        out.push_back({w / "softening",
                       "has no reference_cell_size: the plastic strain of a shear band "
                       "concentrates in about one cell, so the strength drop, the failure "
                       "load and the runout change with the grid. What to change: set "
                       "reference_cell_size to the cell size the shape_factor was calibrated "
                       "for (e.g. the cell size of this grid, " +
                           format4(softening_cell_size(problem)) +
                           " m): the shape factor then scales with the cell size and the "
                           "softening displacement across a band stays the same"});
      // Softened within a strain the elastic range already spans: a snap
      // back at the point (the return still converges; the run is brittle).
      const double drop = mc->cohesion - s.residual_cohesion;
      if (s.shape_factor > 1e4 && drop >= 0)
        out.push_back({w / "softening" / "shape_factor",
                       "is " + format4(s.shape_factor) +
                           ": the strength drops within a plastic strain of " +
                           format4(3.0 / s.shape_factor) +
                           ", close to a brittle jump; the answer then depends strongly on the "
                           "step and the grid. What to change: a shape factor of 5-100 (95 % "
                           "of the drop at a plastic strain of 3/shape_factor)"});
    }
    if (m.hydraulic) {
      const Hydraulic& h = *m.hydraulic;
      // 0 is a deliberate choice (no flow, undrained); only a positive value is checked.
      if (h.hydraulic_conductivity > 0)
        check_range(h.hydraulic_conductivity, conductivity_range, w / "hydraulic", out);
      check_range(h.porosity, porosity_range, w / "hydraulic", out);
    }
  }
  return out;
}

double strip_bearing_capacity(double c, double phi_deg, double gamma, double b) {
  const double phi = phi_deg * std::numbers::pi / 180.0;
  if (phi <= 1e-9) return c * (std::numbers::pi + 2.0);
  const double t = std::tan(phi);
  const double tp = std::tan(std::numbers::pi / 4 + phi / 2);
  const double nq = std::exp(std::numbers::pi * t) * tp * tp;
  const double nc = (nq - 1.0) / t;
  const double ngamma = 2.0 * (nq + 1.0) * t;
  return c * nc + 0.5 * gamma * b * ngamma;
}

namespace {

double cell_of(const Problem& p, int a) {
  return (p.grid.max[a] - p.grid.min[a]) / p.grid.cells[a];
}

/// Particle positions bucketed by grid cell, for "is there a particle near
/// this point" without a search over all of them.
class NearIndex {
 public:
  explicit NearIndex(const Problem& p) : p_(p) {
    for (const BodyLayout& l : body_layouts(p))
      for (const Vec3& x : l.positions) entries_.push_back({key(x), x});
    std::sort(entries_.begin(), entries_.end(),
              [](const Entry& a, const Entry& b) { return a.key < b.key; });
  }
  /// Whether a particle lies within r (< one cell) of x.
  bool any_within(const Vec3& x, double r) const {
    std::array<std::int64_t, 2> c{cell(x, 0), cell(x, 1)};
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj) {
        const std::int64_t i = c[0] + di, j = c[1] + dj;
        if (i < 0 || j < 0 || i >= p_.grid.cells[0] || j >= p_.grid.cells[1]) continue;
        const std::int64_t k = i + j * p_.grid.cells[0];
        auto it = std::lower_bound(entries_.begin(), entries_.end(), k,
                                   [](const Entry& e, std::int64_t v) { return e.key < v; });
        for (; it != entries_.end() && it->key == k; ++it)
          if (std::hypot(it->x[0] - x[0], it->x[1] - x[1]) <= r) return true;
      }
    return false;
  }

 private:
  struct Entry {
    std::int64_t key;
    Vec3 x;
  };
  std::int64_t cell(const Vec3& x, int a) const {
    return static_cast<std::int64_t>(std::floor((x[a] - p_.grid.min[a]) / cell_of(p_, a)));
  }
  std::int64_t key(const Vec3& x) const {
    const std::int64_t i = std::clamp<std::int64_t>(cell(x, 0), 0, p_.grid.cells[0] - 1);
    const std::int64_t j = std::clamp<std::int64_t>(cell(x, 1), 0, p_.grid.cells[1] - 1);
    return i + j * p_.grid.cells[0];
  }
  const Problem& p_;
  std::vector<Entry> entries_;
};

bool in_grid_2d(const Problem& p, const Vec3& x) {
  for (int a = 0; a < 2; ++a)
    if (x[a] < p.grid.min[a] || x[a] > p.grid.max[a]) return false;
  return true;
}

/// Whether some boundary prescribes the velocity along `axis` at the node
/// position x.
bool velocity_prescribed(const Problem& p, const Vec3& x, int axis) {
  return std::any_of(p.boundaries.begin(), p.boundaries.end(), [&](const Boundary& b) {
    return b.velocity[axis].has_value() && !b.absorbing && node_selected(p, b.nodes, x);
  });
}

/// Whether an absorbing boundary with normal `axis` holds the node position x.
bool absorbing_on(const Problem& p, const Vec3& x, int axis) {
  return std::any_of(p.boundaries.begin(), p.boundaries.end(), [&](const Boundary& b) {
    return b.absorbing && b.absorbing->normal == axis && node_selected(p, b.nodes, x);
  });
}

/// Whether a traction acts on the face with outward normal along (axis,
/// side) of the particle at x.
bool traction_on(const Problem& p, const Vec3& x, int axis, int side) {
  return std::any_of(p.tractions.begin(), p.tractions.end(), [&](const Traction& t) {
    return t.axis == axis && t.side == side && particle_selected(p, t, x);
  });
}

struct Face {
  std::array<double, 2> a, b;  ///< end points
  std::array<double, 2> n;     ///< outward unit normal
};

/// The faces of a 2D body: a polygon's edges, or the four sides of the
/// region a box body fills.
std::vector<Face> faces_of(const Body& body, const BodyLayout& layout) {
  std::vector<Face> out;
  if (body.polygon) {
    const auto& v = body.polygon->vertices;
    double area2 = 0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const auto& p = v[k];
      const auto& q = v[(k + 1) % v.size()];
      area2 += p[0] * q[1] - q[0] * p[1];
    }
    const double orient = area2 > 0 ? 1.0 : -1.0;  // counter-clockwise: outward is (dy, -dx)
    for (std::size_t k = 0; k < v.size(); ++k) {
      const auto& p = v[k];
      const auto& q = v[(k + 1) % v.size()];
      const double dx = q[0] - p[0], dy = q[1] - p[1], len = std::hypot(dx, dy);
      if (len <= 0) continue;
      out.push_back({p, q, {orient * dy / len, -orient * dx / len}});
    }
    return out;
  }
  if (body.points || body.prism) return out;
  const double x0 = layout.lo[0], x1 = layout.hi[0], y0 = layout.lo[1], y1 = layout.hi[1];
  out.push_back({{x0, y1}, {x1, y1}, {0, 1}});
  out.push_back({{x0, y0}, {x1, y0}, {0, -1}});
  out.push_back({{x0, y0}, {x0, y1}, {-1, 0}});
  out.push_back({{x1, y0}, {x1, y1}, {1, 0}});
  return out;
}

/// How many of 5 points along the face are open: nothing beyond them (no
/// particle within a spacing, no boundary holding the face, no traction on it).
int open_points(const Problem& p, const NearIndex& near, const Face& f, double s) {
  int open = 0;
  for (double frac : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    const Vec3 m{f.a[0] + frac * (f.b[0] - f.a[0]), f.a[1] + frac * (f.b[1] - f.a[1]), 0};
    const Vec3 out{m[0] + f.n[0] * s, m[1] + f.n[1] * s, 0};
    const Vec3 in{m[0] - f.n[0] * 0.5 * s, m[1] - f.n[1] * 0.5 * s, 0};
    // The dominant axis of the normal: the boundary or traction that holds the face.
    const int axis = std::abs(f.n[0]) >= std::abs(f.n[1]) ? 0 : 1;
    const int side = f.n[axis] > 0 ? 1 : -1;
    if (traction_on(p, in, axis, side)) continue;
    if (velocity_prescribed(p, m, axis) || absorbing_on(p, m, axis)) continue;
    if (in_grid_2d(p, out) && near.any_within(out, 0.75 * s)) continue;
    ++open;
  }
  return open;
}

void check_slopes(const Problem& p, const std::vector<BodyLayout>& layouts,
                  std::vector<ProblemIssue>& out) {
  const double g = std::hypot(p.gravity[0], p.gravity[1]);
  if (!(g > 0)) return;
  const std::array<double, 2> up{-p.gravity[0] / g, -p.gravity[1] / g};
  std::optional<NearIndex> near;
  for (std::size_t b = 0; b < p.bodies.size(); ++b) {
    const Body& body = p.bodies[b];
    if (layouts[b].count == 0 || body.material < 0 ||
        body.material >= static_cast<int>(p.materials.size()))
      continue;
    const Material& m = p.materials[static_cast<std::size_t>(body.material)];
    const StrengthOf s = strength_of(m);
    if (!s.plastic || s.c > 0 || s.tension > 0) continue;
    const double spacing =
        std::min(cell_of(p, 0), cell_of(p, 1)) / std::max(body.particles_per_cell, 1);
    double steepest = -1;
    std::string where;
    for (const Face& f : faces_of(body, layouts[b])) {
      const double cos_up = f.n[0] * up[0] + f.n[1] * up[1];
      if (cos_up < -1e-9) continue;  // an overhang or a base: not a slope
      const double angle = std::acos(std::min(1.0, cos_up)) * 180.0 / std::numbers::pi;
      if (angle <= s.phi + 1.0 || angle <= steepest) continue;
      if (!near) near.emplace(p);
      if (open_points(p, *near, f, spacing) < 3) continue;
      steepest = angle;
      // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive)
      // on "(" + std::string here.
      where.assign(1, '(');
      where.append(format4(f.a[0])).append(", ").append(format4(f.a[1])).append(") to (");
      where.append(format4(f.b[0])).append(", ").append(format4(f.b[1])).append(")");
    }
    if (steepest < 0) continue;
    out.push_back(
        {Location{"bodies"} / b,
         "has a free face from " + where + " inclined " + format4(steepest) +
             " degrees to the horizontal (across gravity), steeper than the friction angle " +
             format4(s.phi) + " degrees of its cohesionless material '" + m.name +
             "': a cohesionless slope stands at most at its friction angle (infinite-slope "
             "limit tan(beta) = tan(phi), dry), so this face will run out under gravity. What to "
             "change: nothing if the collapse is the point; else flatten the face to at most " +
             format4(s.phi) +
             " degrees, give the material cohesion, or support the face (a boundary or a "
             "traction)"});
  }
}

void check_bearing(const Problem& p, const std::vector<BodyLayout>& layouts,
                   std::vector<ProblemIssue>& out) {
  // Gravity along one axis only: the vertical of the strip formula.
  int v = -1, nonzero = 0;
  for (int a = 0; a < 2; ++a)
    if (p.gravity[a] != 0) {
      v = a;
      ++nonzero;
    }
  if (nonzero != 1) return;
  const int h = 1 - v;
  const int up_side = p.gravity[v] < 0 ? 1 : -1;
  const double g = std::abs(p.gravity[v]);
  for (std::size_t k = 0; k < p.tractions.size(); ++k) {
    const Traction& t = p.tractions[k];
    if (t.axis != v || t.side != up_side || !t.traction[v]) continue;
    int body = -1;
    bool one_body = true;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, low_row = lo;
    std::vector<Vec3> loaded;  // initial positions of the loaded particles
    for (std::size_t b = 0; b < layouts.size(); ++b)
      for (const Vec3& x : layouts[b].positions) {
        if (!particle_selected(p, t, x)) continue;
        if (body >= 0 && body != static_cast<int>(b)) one_body = false;
        body = static_cast<int>(b);
        lo = std::min(lo, x[h]);
        hi = std::max(hi, x[h]);
        low_row = std::min(low_row, up_side * x[v]);
        loaded.push_back(x);
      }
    if (body < 0 || !one_body) continue;
    // The peak pressure over the run (compression: the traction against the
    // outward normal); a load that varies along the strip by its mean over
    // the loaded particles, the average pressure the bearing capacity is
    // compared with.
    const FieldOfSpaceTime& varying = t.traction_field[v];
    double peak = 0;
    for (int i = 0; i <= 200; ++i) {
      const double time = p.time.end * i / 200.0;
      double value = 0;
      if (varying) {
        for (const Vec3& x : loaded) value += varying(x, time);
        value /= static_cast<double>(loaded.size());
      } else {
        value = t.traction[v](time);
      }
      if (std::isfinite(value)) peak = std::max(peak, -value * t.side);
    }
    if (!(peak > 0)) continue;
    const Body& bd = p.bodies[static_cast<std::size_t>(body)];
    if (bd.polygon || bd.prism || bd.points) continue;  // a box layer only
    const Material& m = p.materials[static_cast<std::size_t>(bd.material)];
    const StrengthOf s = strength_of(m);
    if (!s.plastic) continue;
    const BodyLayout& l = layouts[static_cast<std::size_t>(body)];
    const double sh = cell_of(p, h) / bd.particles_per_cell;
    const double sv = cell_of(p, v) / bd.particles_per_cell;
    const double top = up_side > 0 ? l.hi[v] : -l.lo[v];
    if (low_row < top - sv) continue;  // not (only) the top row: not a surface load
    const double strip_lo = lo - 0.5 * sh, strip_hi = hi + 0.5 * sh;
    const double gap_lo = strip_lo - l.lo[h], gap_hi = l.hi[h] - strip_hi;
    const double tol = 0.5 * sh;
    const double depth = l.hi[v] - l.lo[v];
    Vec3 side_node{0, 0, 0};
    side_node[v] = 0.5 * (l.lo[v] + l.hi[v]);
    double width = strip_hi - strip_lo, free_gap = 0;
    std::string symmetry;
    if (gap_lo < tol && gap_hi < tol) continue;  // the whole top: no strip
    if (gap_lo < tol || gap_hi < tol) {
      // At a side of the layer: a half footing on a symmetry plane, or an edge load (skipped).
      side_node[h] = gap_lo < tol ? l.lo[h] : l.hi[h];
      if (!velocity_prescribed(p, side_node, h)) continue;
      width *= 2;
      free_gap = gap_lo < tol ? gap_hi : gap_lo;
      symmetry = " (twice the loaded " + format4(width / 2) +
                 " m: a half footing on the symmetry plane " + std::string(h == 0 ? "x" : "y") +
                 " = " + format4(side_node[h]) + ")";
    } else {
      free_gap = std::min(gap_lo, gap_hi);
    }
    // The Prandtl mechanism reaches about a width down and beside the strip
    // (more for high friction): a shallower or narrower layer is stronger
    // than the formula says, so the estimate would not apply.
    if (depth < width || free_gap < width) continue;
    const MaterialConstants mc = material_constants(m, p.gravity_constant);
    const double gamma =
        (mc.mixture_density - (m.hydraulic ? m.hydraulic->fluid_density : 0.0)) * g;
    const double q_ult = strip_bearing_capacity(s.c, s.phi, gamma, width);
    if (!(peak > q_ult)) continue;
    out.push_back(
        {Location{"tractions"} / k,
         "presses with up to " + format4(peak) + " Pa" + (varying ? " on average" : "") +
             " on a strip of width " + format4(width) + " m" + symmetry + " on top of body " +
             std::to_string(body) + " ('" + m.name +
             "'), above its drained strip bearing capacity q_ult = c Nc + gamma' B N_gamma / 2 = " +
             format4(q_ult) + " Pa (Prandtl/Terzaghi surface footing, Vesic's N_gamma; c = " +
             format4(s.c) + " Pa, phi = " + format4(s.phi) + " degrees, " +
             (m.hydraulic ? "buoyant " : "") + "unit weight " + format4(gamma) +
             " N/m3): the ground under the load will fail and a load-controlled footing will "
             "punch in until the run fails or runs out (a fast load on saturated soil may stand "
             "for a while on negative pore pressure). What to change: a load below " +
             format4(q_ult) +
             " Pa, a wider strip or a stronger material; or prescribe the footing's velocity "
             "(displacement control) to find the failure load"});
  }
}

}  // namespace

std::vector<ProblemIssue> stability_plausibility(const Problem& problem) {
  std::vector<ProblemIssue> out;
  if (problem.dimension != 2) return out;
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  check_bearing(problem, layouts, out);
  check_slopes(problem, layouts, out);
  return out;
}

}  // namespace hmpm
