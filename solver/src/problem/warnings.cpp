// problem/warnings.cpp — problem_warnings: what makes a runnable Problem
// doubtful (Darcy-inertia growth, overlapping bodies, a motion that carries
// the soil out of the grid, linear shape functions whose particles cross
// cells), then the plausibility (problem/plausibility.hpp) and geostatic
// warnings.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geostatic.hpp"
#include "hmpm/format.hpp"
#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"
#include "problem/plausibility.hpp"

namespace hmpm {

namespace {

/// The ways out of the Darcy-inertia growth regime that exist for this
/// material (E_oed Q rho_f/(rho - rho_f) <= 0.9): a stiffer fluid only when
/// one no stiffer than water gets there, else a softer skeleton.
std::string darcy_growth_advice(const Material& m, const MaterialConstants& c) {
  constexpr double water_bulk_modulus = 2.2e9;  // Pa, at 20 degrees C
  const Hydraulic& h = *m.hydraulic;
  const double buoyant = c.mixture_density - c.fluid_density;
  // The storage Q at which the ratio is 0.9, and the fluid modulus giving it.
  const double q_target = 0.9 * buoyant / (c.fluid_density * c.constrained_modulus);
  const double solid_term =
      std::isinf(h.solid_bulk_modulus) ? 0.0 : (1 - h.porosity) / h.solid_bulk_modulus;
  std::string out;
  if (q_target > solid_term) {
    const double kf = h.porosity / (q_target - solid_term);
    if (kf <= water_bulk_modulus)
      out = "a stiffer fluid_bulk_modulus (at least " + format_lower_bound(kf) +
            " Pa; water's is 2.2e9), ";
  }
  // The Young's modulus at which E_oed Q gives 0.9 with the fluid as given.
  const double nu = m.poisson_ratio;
  const double e_target =
      0.9 * buoyant / (c.fluid_density * c.storage) * (1 + nu) * (1 - 2 * nu) / (1 - nu);
  if (out.empty())
    out =
        "no fluid_bulk_modulus up to water's 2.2e9 Pa removes it (the skeleton is stiffer "
        "than the fluid's storage allows); a softer skeleton (youngs_modulus at most " +
        format_upper_bound(e_target) + " Pa, if " + format4(m.youngs_modulus) +
        " Pa is a unit slip), ";
  return out + "local_damping for quasi-static runs, or darcy_inertia: false (drops the term)";
}

}  // namespace

namespace {

/// A boundary on a face of the grid whose velocity (prescribed, or the
/// input motion of an absorbing base) carries the soil towards the grid's
/// edge further than the room there: a shaken base moves the whole layer
/// along the shaking, and particles that leave the grid stop the run. The
/// displacement is the velocity's integral over the job's time (2000
/// trapezoids); the room is the gap between the bodies' particles and the
/// grid's edges along that axis. Sideways: the smaller gap of the two
/// sides; along the face normal: the gap behind the face, when the motion
/// moves away from the soil.
void check_room_for_motion(const Problem& problem, const std::vector<BodyLayout>& layouts,
                           std::vector<ProblemIssue>& warnings) {
  const int dim = problem.dimension;
  const double end = job_end_time(problem);
  for (std::size_t i = 0; i < problem.boundaries.size(); ++i) {
    const Boundary& b = problem.boundaries[i];
    if (b.nodes.all || b.nodes.polygon) continue;
    // The grid face the nodes lie on: its normal axis and side (-1: min).
    int normal = -1, side = 0;
    for (int a = 0; a < dim; ++a) {
      if (b.nodes.box.min[a] != b.nodes.box.max[a]) continue;
      if (b.nodes.box.min[a] <= problem.grid.min[a] || b.nodes.box.max[a] >= problem.grid.max[a]) {
        normal = a;
        side = b.nodes.box.min[a] <= problem.grid.min[a] ? -1 : 1;
      }
    }
    if (normal < 0) continue;
    for (int a = 0; a < dim; ++a) {
      if (!b.velocity[a]) continue;
      constexpr int samples = 2000;
      double u = 0.0, lowest = 0.0, highest = 0.0, v_prev = (*b.velocity[a])(0.0);
      for (int k = 1; k <= samples; ++k) {
        const double v = (*b.velocity[a])(end * k / samples);
        u += 0.5 * (v + v_prev) * end / samples;
        v_prev = v;
        lowest = std::min(lowest, u);
        highest = std::max(highest, u);
      }
      if (!std::isfinite(lowest) || !std::isfinite(highest)) continue;
      // Room along a: between the particles (half a spacing inside the
      // filled extent) and the grid's edges.
      double below = std::numeric_limits<double>::infinity(), above = below;
      const double h = cell_size(problem, a);
      for (std::size_t k = 0; k < layouts.size(); ++k) {
        if (layouts[k].count == 0) continue;
        const double half = 0.5 * h / problem.bodies[k].particles_per_cell;
        below = std::min(below, layouts[k].lo[a] + half - problem.grid.min[a]);
        above = std::min(above, problem.grid.max[a] - layouts[k].hi[a] + half);
      }
      double reach = 0.0, room = 0.0;
      std::string where;
      if (a != normal) {
        reach = std::max(-lowest, highest);
        room = std::min(below, above);
        where = "sideways";
      } else {
        reach = side < 0 ? -lowest : highest;
        room = side < 0 ? below : above;
        where = "out of the grid across its face";
      }
      if (!(reach > room)) continue;
      const std::string axis(1, static_cast<char>('x' + a));
      warnings.push_back(
          {Location{"boundaries"} / i / (b.from_acceleration[a] ? "acceleration" : "velocity") /
               static_cast<std::size_t>(a),
           "moves its nodes, and the soil with them, up to " + format4(reach) + " m along " + axis +
               " " + where + " over the run (the integral of the velocity), more than the " +
               format4(room) +
               " m between the outermost particles and the grid's edge: "
               "particles will leave the grid and the run will stop there. What to change: "
               "extend the grid along " +
               axis + " by at least " + format4(reach - room) +
               " m beyond the soil (the added cells stay empty), or check the motion's "
               "baseline (a velocity that does not return to zero drifts)"});
    }
  }
}

/// Linear shape functions in a dynamic run whose loads move the loaded face
/// by more than a quarter cell: particles then cross cell boundaries, where
/// linear gradients jump, and the stresses ring (measured on the column-wave
/// problem of verification §5 at its 2 kPa load, particles moving 1-2
/// cells: 18-24 % RMS of the load with linear, 3.5-4 % with GIMP or
/// B-spline). The estimate: the largest traction over the run times the
/// bodies' extent along its normal over the smallest constrained modulus
/// (the static compression of the loaded soil).
void check_cell_crossing(const Problem& problem, const std::vector<BodyLayout>& layouts,
                         std::vector<ProblemIssue>& warnings) {
  if (problem.shape_function != ShapeFunction::linear ||
      problem.time.scheme == Scheme::quasi_static)
    return;
  double modulus = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < layouts.size(); ++b) {
    const int m = problem.bodies[b].material;
    if (layouts[b].count == 0 || m < 0 || static_cast<std::size_t>(m) >= problem.materials.size())
      continue;
    modulus = std::min(modulus, material_constants(problem.materials[static_cast<std::size_t>(m)],
                                                   problem.gravity_constant)
                                    .constrained_modulus);
  }
  if (!std::isfinite(modulus)) return;
  for (std::size_t i = 0; i < problem.tractions.size(); ++i) {
    const Traction& tr = problem.tractions[i];
    const int a = tr.axis;
    if (a < 0 || a >= problem.dimension) continue;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const BodyLayout& l : layouts)
      if (l.count > 0) {
        lo = std::min(lo, l.lo[a]);
        hi = std::max(hi, l.hi[a]);
      }
    double peak = 0.0;
    constexpr int samples = 200;
    const double end = job_end_time(problem);
    for (int k = 0; k <= samples; ++k) {
      const double t = end * k / samples;
      for (int c = 0; c < problem.dimension; ++c)
        if (tr.traction[c]) peak = std::max(peak, std::abs(tr.traction[c](t)));
    }
    const double move = peak * (hi - lo) / modulus;
    const double h = cell_size(problem, a);
    if (!(move > 0.25 * h)) continue;
    warnings.push_back(
        {Location{"tractions"} / i,
         "moves the loaded soil by about " + format4(move) + " m (the load " + format4(peak) +
             " Pa times the soil's extent " + format4(hi - lo) +
             " m over its constrained modulus " + format4(modulus) +
             " Pa), more than a quarter of the cell size " + format4(h) +
             " m: particles will cross cell boundaries, where linear shape functions' gradients "
             "jump, and the stresses ring (18-24 % of the load in the column-wave test, 3.5-4 % "
             "with the others). What to change: \"shape_function\": \"gimp\" or \"bspline\" "
             "(a finer grid makes the crossings more frequent, not fewer)"});
  }
}

/// A box body fills the whole grid cells inside it only (problem/layout.cpp):
/// a face that is not on a cell boundary loses the partial cell row, and
/// with it mass, silently (issue 38: a box to y = 1.95 with 0.06 m cells
/// filled to 1.92). Says how much of the box gets no particles and where
/// the faces could go. Boxes with no whole cell are an error (check.cpp).
void check_partial_cells(const Problem& problem, std::vector<ProblemIssue>& warnings) {
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    if (body.polygon || body.prism || body.points) continue;
    double volume = 1.0, filled = 1.0;
    std::string faces;
    for (int a = 0; a < problem.dimension; ++a) {
      const auto i = static_cast<std::size_t>(a);
      const double h = cell_size(problem, a), o = problem.grid.min[i];
      const double lo = std::max(body.box.min[i], o);
      const double hi = std::min(body.box.max[i], problem.grid.max[i]);
      const double cell_lo = o + std::ceil((lo - o) / h - 1e-9) * h;
      const double cell_hi = o + std::floor((hi - o) / h + 1e-9) * h;
      volume *= std::max(0.0, hi - lo);
      filled *= std::max(0.0, cell_hi - cell_lo);
      const char* axis = a == 0 ? "x" : (a == 1 ? "y" : "z");
      auto face = [&](const char* side, double at, double down, double up) {
        if (!faces.empty()) faces += "; ";
        faces += std::string(side) + " " + axis + " = " + format4(at) + " is not on a cell " +
                 "boundary: the nearest are " + format4(down) + " and " + format4(up);
      };
      if (cell_lo - lo > 1e-9 * h) face("min", lo, cell_lo - h, cell_lo);
      if (hi - cell_hi > 1e-9 * h) face("max", hi, cell_hi, cell_hi + h);
    }
    if (!(filled > 0.0) || !(volume > filled * (1.0 + 1e-9))) continue;
    warnings.push_back(
        {Location{"bodies"} / b / "box",
         "fills only the whole grid cells inside it, so " +
             format4(100.0 * (volume - filled) / volume) +
             " % of the box's volume gets no particles (and the body that much less mass): " +
             faces +
             ". What to change: put the box's faces on cell boundaries (or the grid's cells "
             "on the box's faces)" +
             (problem.dimension == 2   ? std::string(", or give the body as a polygon, which "
                                                       "fills sub-cells")
              : problem.dimension == 3 ? std::string(", or give the body as a prism, which "
                                                     "fills sub-cells")
                                       : std::string())});
  }
}

}  // namespace

std::vector<ProblemIssue> problem_warnings(const Problem& problem) {
  std::vector<ProblemIssue> warnings;
  for (const Material& m : problem.materials) {
    const MaterialConstants c = material_constants(m, problem.gravity_constant);
    // From 0.9 of the equations' limit (the scheme's limit is the same):
    // near it, waves hardly decay.
    const double growth = darcy_inertia_growth_ratio(c);
    if (growth <= 0.9) continue;
    const std::string what =
        std::isinf(growth)
            ? "the grains are not denser than the fluid (density " + format4(m.density) +
                  " kg/m3, fluid " + format4(c.fluid_density) +
                  "), so the u-p equations with the rho_f a term of Darcy's law have growing "
                  "solutions for any stiffness: oscillations can grow and the run can diverge. "
                  "What to change: check density (the grain density, not the mixture's), or "
                  "set darcy_inertia: false (drops the term)"
            : "constrained modulus x storage (E_oed Q = " +
                  format4(c.constrained_modulus * c.storage) + ") is " + format4(growth) +
                  " times (rho - rho_f)/rho_f, above which the u-p equations with the rho_f a "
                  "term of Darcy's law have growing solutions (near it, waves hardly decay): "
                  "oscillations can grow and the run can diverge. What to change: " +
                  darcy_growth_advice(m, c);
    warnings.push_back({Location{"materials", m.name, "hydraulic"}, what});
  }
  const std::vector<BodyLayout> layouts = body_layouts(problem, LayoutDetail::counts);
  for (std::size_t b = 0; b < layouts.size(); ++b)
    for (const auto& [earlier, n] : layouts[b].lost)
      warnings.push_back(
          {Location{"bodies"} / b,
           "overlaps body " + std::to_string(earlier) + ": " + std::to_string(n) +
               " of its particle positions lie inside body " + std::to_string(earlier) +
               ", which is listed first, so they belong to body " + std::to_string(earlier) +
               " (a place inside several bodies gets one particle, of the first). What to "
               "change: nothing if intended; else shrink body " +
               std::to_string(b) + " (or body " + std::to_string(earlier) +
               ") so that they do not overlap, or list body " + std::to_string(b) +
               " first if the shared place should be its (body " + std::to_string(earlier) +
               " then loses it)"});
  check_partial_cells(problem, warnings);
  check_room_for_motion(problem, layouts, warnings);
  check_cell_crossing(problem, layouts, warnings);
  for (ProblemIssue& w : material_plausibility(problem)) warnings.push_back(std::move(w));
  for (ProblemIssue& w : stability_plausibility(problem)) warnings.push_back(std::move(w));
  for (ProblemIssue& w : geostatic_warnings(problem)) warnings.push_back(std::move(w));
  return warnings;
}

}  // namespace hmpm
