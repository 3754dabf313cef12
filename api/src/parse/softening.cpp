// softening.cpp — a Mohr-Coulomb material's "softening" object: the
// residual strength its peak (the material's own c, phi, psi) softens to,
// the shape factor of the exponential law and the optional regularisation
// (MohrCoulomb::Softening, docs/job-spec.md "Strain softening").
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view softening_allowed[] = {"residual_cohesion", "residual_friction_angle",
                                                  "residual_dilatancy_angle", "shape_factor",
                                                  "reference_cell_size"};
constexpr std::string_view softening_required[] = {"residual_cohesion", "residual_friction_angle",
                                                   "shape_factor"};

}  // namespace

void softening_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/materials/*/softening", softening_allowed));
}

void read_softening(ParseContext& c, Material& m, const json& j, const std::string& path) {
  SpecReader& r = c.r;
  auto* mc = std::get_if<MohrCoulomb>(&m.plasticity);
  if (mc == nullptr) {
    r.error(path,
            "applies only to model 'mohr_coulomb' (its strength softens from the peak c, phi, "
            "psi to residual values); remove it, or use model 'mohr_coulomb'");
    return;
  }
  if (!r.object(j, path, softening_allowed, softening_required)) return;
  MohrCoulomb::Softening s;
  const Range angle{0.0, 90.0, false, true};
  r.number_at(j, path, "residual_cohesion", Range::non_negative(), s.residual_cohesion);
  r.number_at(j, path, "residual_friction_angle", angle, s.residual_friction_angle_deg);
  r.number_at(j, path, "residual_dilatancy_angle", angle, s.residual_dilatancy_angle_deg);
  // eta <= 0 would be no softening, or hardening without bound.
  if (j.contains("shape_factor")) {
    const json& v = j["shape_factor"];
    const std::string vp = path + "/shape_factor";
    if (v.is_number() && v.get<double>() <= 0)
      r.error(vp, "is " + format_number(v.get<double>()) +
                      "; must be > 0: the strength falls as exp(-shape_factor x plastic "
                      "strain), so 95 % of the drop is reached at a plastic strain of "
                      "3/shape_factor (e.g. 30 for a drop by 10 % plastic strain); without "
                      "softening remove the object");
    else
      r.number_at(j, path, "shape_factor", Range::positive(), s.shape_factor);
  }
  r.number_at(j, path, "reference_cell_size", Range::positive(), s.reference_cell_size);
  // The residual must not exceed the peak: the law would harden instead.
  const auto above = [&](std::string_view key, double residual, double peak,
                         std::string_view peak_key, std::string_view unit) {
    if (!j.contains(key) || !(residual > peak)) return;
    r.error(child_pointer(path, key),
            "is " + format_number(residual) + std::string(unit) + ", above the peak " +
                std::string(peak_key) + " " + format_number(peak) + std::string(unit) +
                ": softening goes from the peak (the material's own value) down to the "
                "residual; give a residual at most the peak (e.g. a residual cohesion of 0-20 % "
                "and a residual friction angle 2-10 degrees below the peak for brittle clays)");
  };
  above("residual_cohesion", s.residual_cohesion, mc->cohesion, "cohesion", " Pa");
  above("residual_friction_angle", s.residual_friction_angle_deg, mc->friction_angle_deg,
        "friction_angle", " degrees");
  above("residual_dilatancy_angle", s.residual_dilatancy_angle_deg, mc->dilatancy_angle_deg,
        "dilatancy_angle", " degrees");
  if (j.contains("residual_dilatancy_angle") &&
      s.residual_dilatancy_angle_deg > s.residual_friction_angle_deg)
    r.error(path + "/residual_dilatancy_angle",
            "is " + format_number(s.residual_dilatancy_angle_deg) +
                " degrees; must not exceed residual_friction_angle " +
                format_number(s.residual_friction_angle_deg));
  if (s.residual_cohesion == 0 && s.residual_friction_angle_deg == 0 && j.contains("shape_factor"))
    r.error(child_pointer(path, "residual_cohesion"),
            "is 0 with residual_friction_angle 0: the softened soil would have no strength "
            "at all; give a residual cohesion or friction angle");
  mc->softening = s;
}

}  // namespace hmpm::api::parse
