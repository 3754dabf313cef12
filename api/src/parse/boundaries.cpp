// boundaries.cpp — the "boundaries" section: grid nodes with prescribed
// velocity components, pore pressure, rigid ties, wall friction and seepage
// faces.
#include <algorithm>
#include <cmath>
#include <limits>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

/// Nodes of the selection among those inside `bounds` (a 2D polygon's
/// bounding box).
std::int64_t count_selected_nodes(const Problem& p, const NodeSelection& nodes, const Box& bounds) {
  std::array<std::int64_t, 2> first{0, 0}, last{0, 0};
  std::array<double, 2> h{0.0, 0.0};
  for (int a = 0; a < 2; ++a) {
    h[a] = (p.grid.max[a] - p.grid.min[a]) / p.grid.cells[a];
    first[a] = std::max<std::int64_t>(
        0, static_cast<std::int64_t>(std::floor((bounds.min[a] - p.grid.min[a]) / h[a])));
    last[a] = std::min<std::int64_t>(
        p.grid.cells[a],
        static_cast<std::int64_t>(std::ceil((bounds.max[a] - p.grid.min[a]) / h[a])));
  }
  std::int64_t n = 0;
  for (std::int64_t j = first[1]; j <= last[1]; ++j)
    for (std::int64_t i = first[0]; i <= last[0]; ++i)
      n += node_selected(p, nodes,
                         {p.grid.min[0] + static_cast<double>(i) * h[0],
                          p.grid.min[1] + static_cast<double>(j) * h[1], 0.0})
               ? 1
               : 0;
  return n;
}

constexpr std::string_view boundary_allowed[] = {"nodes", "velocity", "pore_pressure",
                                                 "rigid", "friction", "seepage"};
constexpr std::string_view boundary_required[] = {"nodes"};

void read_boundary(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, boundary_allowed, boundary_required)) return;
  Boundary b;
  if (j.contains("nodes")) {
    bool all = false;
    const std::string np = path + "/nodes";
    if (auto box = read_selection(c, j["nodes"], np, all, &b.nodes.polygon)) {
      b.nodes.all = all;
      b.nodes.box = *box;
      if (b.nodes.polygon) {
        if (c.grid_ok && count_selected_nodes(c.p, b.nodes, *box) == 0)
          r.error(np + "/polygon",
                  "selects no grid node (inside or on its boundary); nodes lie at min + i * "
                  "cell size");
      } else if (!all && c.grid_ok) {
        double count = 1;
        for (int a = 0; a < c.dim; ++a)
          count *= static_cast<double>(nodes_inside(c.p.grid, a, box->min[a], box->max[a]));
        if (count == 0)
          r.error(np + "/box", "selects no grid node; nodes lie at min + i * cell size");
      }
    }
  }
  if (j.contains("seepage"))
    if (const auto s = r.boolean(j["seepage"], path + "/seepage")) b.seepage = *s;
  if (!j.contains("velocity") && !j.contains("pore_pressure") && !j.contains("rigid") && !b.seepage)
    r.error(path, "needs 'velocity', 'pore_pressure', 'rigid' and/or 'seepage'");
  if (j.contains("velocity")) {
    const json& v = j["velocity"];
    const std::string vp = path + "/velocity";
    if (r.per_axis(v, vp, c.dim, "number, formula in t or null")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        if (v[a].is_null()) continue;
        if (auto f = read_value_of_time(c, v[a], child_pointer(vp, a))) {
          b.velocity[a] = std::move(*f);
          b.has_velocity = true;
        }
      }
    }
  }
  if (j.contains("rigid")) {
    const json& v = j["rigid"];
    const std::string vp = path + "/rigid";
    if (r.per_axis(v, vp, c.dim, "true or false")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        const std::string ap = child_pointer(vp, a);
        const auto tied = r.boolean(v[a], ap);
        if (!tied) continue;
        b.rigid[a] = *tied;
        if (b.rigid[a] && b.velocity[a])
          r.error(ap, "is true but velocity/" + std::to_string(a) +
                          " prescribes that component; a rigid tie needs it free");
      }
    }
  }
  if (j.contains("friction")) {
    // A Coulomb coefficient, or "rough" for no slip; which component is the
    // wall normal (exactly one prescribed) is checked by check_problem.
    const json& f = j["friction"];
    const std::string fp = path + "/friction";
    if (f.is_string()) {
      if (f.get<std::string>() == "rough")
        b.friction = std::numeric_limits<double>::infinity();
      else
        r.error(fp, "expected a number >= 0 (Coulomb coefficient) or \"rough\" (no slip), got \"" +
                        f.get<std::string>() + "\"");
    } else if (auto mu = r.number(f, fp, Range::non_negative())) {
      b.friction = *mu;
    }
    if (!j.contains("velocity"))
      r.error(fp, "needs 'velocity' with the wall-normal component prescribed and the others null");
  }
  if (j.contains("pore_pressure")) {
    // A number or a formula in x, y, z, t: one in t alone is a value of time.
    bool varies = false;
    if (auto f = read_value_of_space_time(c, j["pore_pressure"], path + "/pore_pressure", varies)) {
      b.pore_pressure = [f = *f](double t) { return f(Vec3{0.0, 0.0, 0.0}, t); };
      if (varies) b.pore_pressure_field = std::move(*f);
    }
    if (!c.any_pore_pressure_bc) c.first_pore_pressure_bc = path + "/pore_pressure";
    c.any_pore_pressure_bc = true;
  }
  c.p.boundaries.push_back(std::move(b));
}

}  // namespace

void boundary_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/boundaries/*", boundary_allowed));
  out.push_back(keys_entry("/boundaries/*/nodes", selection_key_names()));
  out.push_back(keys_entry("/boundaries/*/nodes/box", box_key_names()));
}

void read_boundaries(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  for (std::size_t i = 0; i < j.size(); ++i) read_boundary(c, j[i], child_pointer(path, i));
}

}  // namespace hmpm::api::parse
