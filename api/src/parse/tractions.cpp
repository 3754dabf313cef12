// tractions.cpp — the "tractions" and "fluxes" sections: surface loads and
// water flowing across a face of the particles inside a box or a polygon.
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view traction_allowed[] = {"particles", "face", "traction"};
constexpr std::string_view flux_allowed[] = {"particles", "face", "rate"};
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

}  // namespace

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
