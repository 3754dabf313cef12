// tractions.cpp — the "tractions", "fluxes" and "surface_pressures"
// sections: surface loads, water flowing across a face, and pore pressures
// prescribed on a face of the particles inside a box or a polygon.
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view traction_allowed[] = {"particles", "face", "traction"};
constexpr std::string_view flux_allowed[] = {"particles", "face", "rate"};
constexpr std::string_view surface_allowed[] = {"particles", "face", "pore_pressure", "seepage"};
constexpr std::string_view surface_required[] = {"particles", "face"};
constexpr std::string_view face_names[] = {"x-", "x+", "y-", "y+", "z-", "z+"};

// "particles" and "face" of a traction or a flux.
template <class Load>
void read_face(ParseContext& c, const json& j, const std::string& path, Load& load) {
  SpecReader& r = c.r;
  if (j.contains("particles")) {
    bool all = false;
    if (auto box = read_selection(c, j["particles"], path + "/particles", all, &load.polygon))
      load.particles = *box;
  }
  if (j.contains("face")) {
    if (auto f = r.one_of(j["face"], path + "/face", face_names)) {
      load.axis = (*f)[0] - 'x';
      load.side = (*f)[1] == '+' ? +1 : -1;
      if (c.dim > 0 && load.axis >= c.dim)
        r.error(path + "/face", "is '" + *f + "', but a " + std::to_string(c.dim) +
                                    "D problem has no " + std::string(axis_names[load.axis]) +
                                    " axis");
    }
  }
}

void read_traction(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, traction_allowed, traction_allowed)) return;
  Traction t;
  read_face(c, j, path, t);
  if (j.contains("traction")) {
    const json& v = j["traction"];
    const std::string vp = path + "/traction";
    if (r.per_axis(v, vp, c.dim, "number or formula in x, y, z, t")) {
      // A number or a formula in x, y, z, t (the particle's initial
      // position): one in t alone is a value of time, evaluated once per step.
      for (std::size_t a = 0; a < v.size() && a < 3; ++a) {
        bool varies = false;
        if (auto f = read_value_of_space_time(c, v[a], child_pointer(vp, a), varies)) {
          t.traction[a] = [f = *f](double time) { return f(Vec3{0.0, 0.0, 0.0}, time); };
          if (varies) t.traction_field[a] = std::move(*f);
        }
      }
    }
  }
  c.traction_paths.push_back(path + "/particles");
  c.p.tractions.push_back(std::move(t));
}

void read_flux(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, flux_allowed, flux_allowed)) return;
  Flux f;
  read_face(c, j, path, f);
  if (j.contains("rate"))
    if (auto rate = read_value_of_space_time(c, j["rate"], path + "/rate", f.rate_varies_in_space))
      f.rate = std::move(*rate);
  c.flux_paths.push_back(path + "/particles");
  c.p.fluxes.push_back(std::move(f));
}

void read_surface_pressure(ParseContext& c, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, surface_allowed, surface_required)) return;
  SurfacePressure s;
  read_face(c, j, path, s);
  if (j.contains("pore_pressure")) {
    bool varies = false;
    if (auto f = read_value_of_space_time(c, j["pore_pressure"], path + "/pore_pressure", varies))
      s.pore_pressure = std::move(*f);
  }
  if (j.contains("seepage"))
    if (const auto v = r.boolean(j["seepage"], path + "/seepage")) s.seepage = *v;
  if (j.contains("seepage") && j.contains("pore_pressure"))
    r.error(path + "/seepage",
            "cannot share an entry with pore_pressure: a seepage face decides its own pressure "
            "(p = 0 while water leaves); give the prescribed pressure its own entry");
  else if (!s.seepage && !j.contains("pore_pressure"))
    r.error(path, "needs 'pore_pressure' (a number or a formula in x, y, z, t) or 'seepage': true");
  c.surface_pressure_paths.push_back(path + "/particles");
  c.p.surface_pressures.push_back(std::move(s));
}

}  // namespace

void surface_pressure_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/surface_pressures/*", surface_allowed));
  out.push_back(keys_entry("/surface_pressures/*/particles", selection_key_names()));
  out.push_back(keys_entry("/surface_pressures/*/particles/box", box_key_names()));
}

void read_surface_pressures(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  for (std::size_t i = 0; i < j.size(); ++i) read_surface_pressure(c, j[i], child_pointer(path, i));
}

void flux_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/fluxes/*", flux_allowed));
  out.push_back(keys_entry("/fluxes/*/particles", selection_key_names()));
  out.push_back(keys_entry("/fluxes/*/particles/box", box_key_names()));
}

void read_fluxes(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  for (std::size_t i = 0; i < j.size(); ++i) read_flux(c, j[i], child_pointer(path, i));
}

void traction_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/tractions/*", traction_allowed));
  out.push_back(keys_entry("/tractions/*/particles", selection_key_names()));
  out.push_back(keys_entry("/tractions/*/particles/box", box_key_names()));
}

std::span<const std::string_view> traction_faces() {
  return face_names;
}

void read_tractions(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.array(j, path)) return;
  for (std::size_t i = 0; i < j.size(); ++i) read_traction(c, j[i], child_pointer(path, i));
}

}  // namespace hmpm::api::parse
