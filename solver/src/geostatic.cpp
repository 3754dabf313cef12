// geostatic.cpp — the geostatic initial state: checks and the layered
// integral over each particle's column (see geostatic.hpp).
#include "geostatic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "hmpm/format.hpp"
#include "interrupt.hpp"
#include "materials/material.hpp"
#include "particle_layout.hpp"

namespace hmpm {

namespace {

/// The space a body's particles fill (whole cells), and its density.
struct BodyExtent {
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  bool empty = true;
  double density = 0.0;  ///< mixture density, kg/m^3
  bool hydraulic = false;
};

/// Where gravity points: the vertical axis, "up" (+1 when gravity points to
/// -axis) and |g|. axis = -1 when gravity is not along exactly one axis.
struct Vertical {
  int axis = -1;
  double up = 1.0;
  double g = 0.0;
};

Vertical vertical_of(const Problem& problem) {
  Vertical v;
  int nonzero = 0;
  for (int a = 0; a < problem.dimension; ++a)
    if (problem.gravity[a] != 0.0) {
      ++nonzero;
      v.axis = a;
    }
  if (nonzero != 1) return Vertical{};
  v.up = problem.gravity[v.axis] < 0 ? 1.0 : -1.0;
  v.g = std::abs(problem.gravity[v.axis]);
  return v;
}

std::vector<BodyExtent> body_extents(const Problem& problem,
                                     const std::vector<BodyLayout>& layouts) {
  std::vector<BodyExtent> out;
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Body& body = problem.bodies[b];
    BodyExtent e;
    const BodyLayout& layout = layouts[b];
    e.empty = layout.count == 0;
    for (int a = 0; a < problem.dimension && !e.empty; ++a) {
      e.lo[a] = layout.lo[a];
      e.hi[a] = layout.hi[a];
    }
    if (body.material >= 0 && body.material < static_cast<int>(problem.materials.size())) {
      const Material& m = problem.materials[static_cast<std::size_t>(body.material)];
      e.density = material_constants(m, problem.gravity_constant).mixture_density;
      e.hydraulic = m.hydraulic.has_value();
    }
    out.push_back(e);
  }
  return out;
}

/// Elevation interval [bottom, top] of a body along "up".
std::pair<double, double> elevations(const BodyExtent& e, const Vertical& v) {
  const double a = v.up * e.lo[v.axis], b = v.up * e.hi[v.axis];
  return {std::min(a, b), std::max(a, b)};
}

/// Whether the column through x (horizontal coordinates) crosses body e.
bool covers(const BodyExtent& e, const Vec3& x, const Vertical& v, int dim) {
  if (e.empty) return false;
  for (int a = 0; a < dim; ++a)
    if (a != v.axis && (x[a] < e.lo[a] || x[a] > e.hi[a])) return false;
  return true;
}

/// Elevation of the ground surface over the column through x.
double surface_at(const std::vector<BodyExtent>& extents, const Vec3& x, const Vertical& v,
                  int dim) {
  double top = -std::numeric_limits<double>::infinity();
  for (const BodyExtent& e : extents)
    if (covers(e, x, v, dim)) top = std::max(top, elevations(e, v).second);
  return top;
}

std::string fmt(double x) {
  return format_significant(x, 6);
}

}  // namespace

std::vector<ProblemIssue> check_geostatic(const Problem& problem) {
  std::vector<ProblemIssue> issues;
  if (!problem.initial_state.geostatic) return issues;
  const Geostatic& geo = *problem.initial_state.geostatic;
  const Location where{"initial_state", "geostatic"};
  const Vertical v = vertical_of(problem);
  if (v.axis < 0) {
    issues.push_back({{"gravity"},
                      "must have exactly one non-zero component for "
                      "initial_state.geostatic: the ground is layered across gravity"});
    return issues;
  }
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const InitialFields& init = problem.bodies[b].initial;
    const Location w = Location{"bodies"} / b / "initial";
    if (init.pore_pressure)
      issues.push_back({w / "pore_pressure",
                        "conflicts with initial_state.geostatic, which sets "
                        "the initial pore pressure of every body"});
    if (std::any_of(init.effective_stress.begin(), init.effective_stress.end(),
                    [](const FieldOfPosition& f) { return static_cast<bool>(f); }))
      issues.push_back({w / "effective_stress",
                        "conflicts with initial_state.geostatic, which "
                        "sets the initial effective stress of every body"});
  }
  const Material* fluid = nullptr;
  for (const Material& m : problem.materials) {
    if (!m.hydraulic) continue;
    if (fluid && fluid->hydraulic->fluid_density != m.hydraulic->fluid_density)
      issues.push_back({Location{"materials", m.name, "hydraulic", "fluid_density"},
                        "differs from that of material '" + fluid->name +
                            "': a geostatic state needs one pore fluid (one hydrostatic "
                            "pressure)"});
    if (!fluid) fluid = &m;
  }
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  const std::vector<BodyExtent> extents = body_extents(problem, layouts);
  const int dim = problem.dimension;
  const char* axis_name[] = {"x", "y", "z"};
  for (std::size_t b = 0; b < extents.size(); ++b) {
    const BodyExtent& e = extents[b];
    if (e.empty || !e.hydraulic) continue;
    const std::string body = "body " + std::to_string(b);
    if (!geo.water_table) {
      issues.push_back({where, "needs 'water_table': " + body +
                                   " is of a material with 'hydraulic' (saturated)"});
      break;
    }
    const double table = v.up * *geo.water_table;
    const auto [bottom, top] = elevations(e, v);
    const double tol = 1e-9 * (problem.grid.max[v.axis] - problem.grid.min[v.axis]);
    if (top > table + tol)
      issues.push_back(
          {where / "water_table",
           "is " + fmt(*geo.water_table) + " but " + body +
               " (a material with 'hydraulic') reaches " + axis_name[v.axis] + " = " +
               fmt(v.up * top) +
               ": the u-p model is fully saturated, so ground above the water table must be a "
               "material without 'hydraulic' (with the bulk density of the unsaturated soil)"});
    // The table must not lie above the ground surface of any column through
    // this body: free water above the ground is not modelled.
    // Every particle's column (one per distinct horizontal position would
    // do; the first violation is reported).
    for (const Vec3& at : layouts[b].positions) {
      const double surface = surface_at(extents, at, v, dim);
      if (table > surface + tol) {
        issues.push_back({where / "water_table",
                          "is " + fmt(*geo.water_table) + ", above the ground surface " +
                              axis_name[v.axis] + " = " + fmt(v.up * surface) + " over " + body +
                              ": free water above the ground is not modelled; lower the table "
                              "to the surface and load the surface with a traction instead"});
        break;
      }
    }
  }
  return issues;
}

GeostaticState geostatic_state(const Problem& problem, const SetupInterrupt* interrupt) {
  const Geostatic& geo = *problem.initial_state.geostatic;
  const Vertical v = vertical_of(problem);
  const std::vector<BodyLayout> layouts = body_layouts(problem, LayoutDetail::counts);
  const std::vector<BodyExtent> extents = body_extents(problem, layouts);
  const int dim = problem.dimension;
  GeostaticState out;
  out.vertical_axis = v.axis;
  const std::vector<Vec3> positions = initial_positions(problem);
  out.vertical.resize(positions.size());
  out.horizontal.resize(positions.size());
  out.pressure.assign(positions.size(), 0.0);
  const double table = geo.water_table ? v.up * *geo.water_table : 0.0;
  std::size_t p = 0;
  for (std::size_t b = 0; b < problem.bodies.size(); ++b) {
    const Material& m = problem.materials[static_cast<std::size_t>(problem.bodies[b].material)];
    const std::size_t mat = static_cast<std::size_t>(problem.bodies[b].material);
    double k0 = geo.k0.value_or(m.poisson_ratio / (1.0 - m.poisson_ratio));
    if (mat < geo.material_k0.size() && geo.material_k0[mat]) k0 = *geo.material_k0[mat];
    const std::int64_t count = layouts[b].count;
    for (std::int64_t k = 0; k < count; ++k, ++p) {
      if (interrupt) interrupt->poll(p);
      const Vec3& x = positions[p];
      const double elevation = v.up * x[v.axis];
      // Weight of the column above the particle, per unit area.
      double weight = 0.0;
      for (const BodyExtent& e : extents) {
        if (!covers(e, x, v, dim)) continue;
        const auto [bottom, top] = elevations(e, v);
        const double from = std::max(bottom, elevation);
        if (top > from) weight += e.density * v.g * (top - from);
      }
      const double pressure =
          m.hydraulic ? m.hydraulic->fluid_density * v.g * (table - elevation) : 0.0;
      out.pressure[p] = pressure;
      out.vertical[p] = -weight + pressure;
      out.horizontal[p] = k0 * out.vertical[p];
    }
  }
  return out;
}

std::vector<ProblemIssue> geostatic_warnings(const Problem& problem) {
  std::vector<ProblemIssue> out;
  if (!problem.initial_state.geostatic || problem.dimension < 2) return out;
  const Vertical v = vertical_of(problem);
  if (v.axis < 0) return out;  // check_geostatic refuses it
  // The ground surface over each column of particles: the highest particle
  // plus half its spacing along the vertical.
  const std::vector<BodyLayout> layouts = body_layouts(problem);
  const double hv =
      (problem.grid.max[v.axis] - problem.grid.min[v.axis]) / problem.grid.cells[v.axis];
  double quantum = std::numeric_limits<double>::infinity();
  for (int a = 0; a < problem.dimension; ++a)
    if (a != v.axis)
      quantum = std::min(
          quantum, 1e-6 * (problem.grid.max[a] - problem.grid.min[a]) / problem.grid.cells[a]);
  struct Column {
    double surface;
    Vec3 at;
  };
  std::map<std::array<std::int64_t, 2>, Column> columns;
  double tolerance = 0;
  for (std::size_t b = 0; b < layouts.size(); ++b) {
    const double half = 0.5 * hv / std::max(problem.bodies[b].particles_per_cell, 1);
    tolerance = std::max(tolerance, 2 * half);
    for (const Vec3& x : layouts[b].positions) {
      std::array<std::int64_t, 2> key{0, 0};
      int k = 0;
      for (int a = 0; a < problem.dimension; ++a)
        if (a != v.axis) key[k++] = static_cast<std::int64_t>(std::llround(x[a] / quantum));
      const double top = v.up * x[v.axis] + half;
      auto [it, fresh] = columns.try_emplace(key, Column{top, x});
      if (!fresh && top > it->second.surface) it->second = {top, x};
    }
  }
  if (columns.empty()) return out;
  auto [low, high] = std::minmax_element(
      columns.begin(), columns.end(),
      [](const auto& a, const auto& b) { return a.second.surface < b.second.surface; });
  if (high->second.surface - low->second.surface <= tolerance * (1 + 1e-9)) return out;
  const char* axis_name[] = {"x", "y", "z"};
  auto column_text = [&](const Column& c) {
    std::string s;
    for (int a = 0; a < problem.dimension; ++a)
      if (a != v.axis)
        s += std::string(s.empty() ? "" : ", ") + axis_name[a] + " = " + fmt(c.at[a]);
    return std::string(axis_name[v.axis]) + " = " + fmt(v.up * c.surface) + " (over " + s + ")";
  };
  out.push_back(
      {{"initial_state", "geostatic"},
       "is for level, horizontally layered ground, but the ground surface here is not level: "
       "it lies between " +
           column_text(low->second) + " and " + column_text(high->second) +
           ". The geostatic state is the weight of the column above each particle with no shear "
           "stress (and the columns of polygon or prism bodies are taken up to the top of their "
           "bounding box), which is not in equilibrium under a slope, an embankment or a step: "
           "as the run starts the stress redistributes and the pore pressure changes with it "
           "before any load acts. What to change: for non-level ground, build the initial state "
           "by gravity loading instead (omit initial_state.geostatic and settle the bodies under "
           "gravity with local_damping over a first part of the run, loads starting after it); "
           "for ground meant to be level, make the bodies' tops meet at one height"});
  return out;
}

}  // namespace hmpm
