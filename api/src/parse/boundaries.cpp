// boundaries.cpp — the "boundaries" section: grid nodes with prescribed
// velocity components (or accelerations), pore pressure, rigid ties, wall
// friction, seepage faces and absorbing (viscous) boundaries.
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

constexpr std::string_view boundary_allowed[] = {"nodes",         "velocity", "acceleration",
                                                 "pore_pressure", "rigid",    "friction",
                                                 "seepage",       "absorbing"};
constexpr std::string_view absorbing_allowed[] = {"normal", "material"};

/// `absorbing`: true or {"normal": axis, "material": name}. The normal
/// defaults to the one axis along which the node box is flat, the material
/// to the job's only one.
void read_absorbing(ParseContext& c, const json& j, const std::string& path, Boundary& b) {
  SpecReader& r = c.r;
  Absorbing ab;
  bool normal_given = false, material_given = false;
  if (j.is_boolean()) {
    if (!j.get<bool>()) return;  // false: no dashpots
  } else if (!j.is_object()) {
    r.error(path, std::string("expected true or an object {\"normal\": \"x\"|\"y\"|\"z\", "
                              "\"material\": name}, got ") +
                      j.type_name());
    return;
  } else {
    if (!r.object(j, path, absorbing_allowed)) return;
    if (j.contains("normal")) {
      const std::span<const std::string_view> axes(axis_names,
                                                   static_cast<std::size_t>(std::max(c.dim, 1)));
      if (auto s = r.one_of(j["normal"], path + "/normal", axes)) {
        ab.normal = static_cast<int>(std::find(axes.begin(), axes.end(), *s) - axes.begin());
        normal_given = true;
      } else {
        return;
      }
    }
    if (j.contains("material")) {
      const std::string mp = path + "/material";
      const auto name = r.string(j["material"], mp, 100);
      if (!name) return;
      const auto it = c.material_index.find(*name);
      if (it == c.material_index.end()) {
        std::vector<std::string> names;
        for (const auto& [n, i] : c.material_index) names.push_back(n);
        r.error(mp, "unknown material '" + *name + "'; defined materials: " +
                        (names.empty() ? std::string("none") : quoted_list(names)));
        return;
      }
      ab.material = static_cast<std::size_t>(it->second);
      material_given = true;
    }
  }
  if (!normal_given) {
    int flat = -1, flats = 0;
    if (!b.nodes.all && !b.nodes.polygon)
      for (int a = 0; a < c.dim; ++a)
        if (b.nodes.box.min[a] == b.nodes.box.max[a]) {
          flat = a;
          ++flats;
        }
    if (c.dim == 1) {
      ab.normal = 0;
    } else if (flats == 1) {
      ab.normal = flat;
    } else {
      r.error(path,
              "needs 'normal' (the axis across the face: \"x\", \"y\" or \"z\"): the "
              "nodes are not a box flat along exactly one axis");
      return;
    }
  }
  if (!material_given && c.p.materials.size() > 1) {
    r.error(path, "needs 'material': the job has " + std::to_string(c.p.materials.size()) +
                      " materials; name the medium beyond the boundary (the soil it "
                      "bounds, or the rock below a compliant base)");
    return;
  }
  b.absorbing = ab;
}
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
  if (j.contains("absorbing")) read_absorbing(c, j["absorbing"], path + "/absorbing", b);
  if (!j.contains("velocity") && !j.contains("acceleration") && !j.contains("pore_pressure") &&
      !j.contains("rigid") && !b.seepage && !b.absorbing)
    r.error(path,
            "needs 'velocity', 'acceleration', 'pore_pressure', 'rigid', 'seepage' and/or "
            "'absorbing'");
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
  if (j.contains("acceleration")) {
    // Integrated from rest at t = 0 to the velocity the solver uses.
    const json& v = j["acceleration"];
    const std::string vp = path + "/acceleration";
    if (r.per_axis(v, vp, c.dim, "number, formula in t, table or null")) {
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        if (v[a].is_null()) continue;
        const std::string ap = child_pointer(vp, a);
        if (b.velocity[a]) {
          r.error(ap, "and velocity/" + std::to_string(a) +
                          " both give this component; give one (the velocity is the "
                          "acceleration's integral from rest at t = 0)");
          continue;
        }
        if (auto f = read_acceleration(c, v[a], ap)) {
          b.velocity[a] = std::move(*f);
          b.has_velocity = true;
          b.from_acceleration[a] = true;
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
    if (!j.contains("velocity") && !j.contains("acceleration"))
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
  out.push_back(keys_entry("/boundaries/*/absorbing", absorbing_allowed));
}

void read_boundaries(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  for (std::size_t i = 0; i < j.size(); ++i) read_boundary(c, j[i], child_pointer(path, i));
}

}  // namespace hmpm::api::parse
