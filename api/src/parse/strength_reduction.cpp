// strength_reduction.cpp — the "strength_reduction" section: the factor of
// safety by strength reduction after the last stage (quasi-static scheme;
// docs/job-spec.md "Strength reduction").
#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view allowed[] = {"increment", "resolution", "max_factor", "max_iterations",
                                        "displacement_limit"};

}  // namespace

void strength_reduction_keys(std::vector<SpecObjectKeys>& out) {
  out.push_back(keys_entry("/strength_reduction", allowed));
}

void read_strength_reduction(ParseContext& c, const json& j, const std::string& path) {
  // true: every default; an object: its keys.
  if (j.is_boolean()) {
    if (j.get<bool>()) c.p.strength_reduction = StrengthReduction{};
    return;
  }
  if (!c.r.object(j, path, allowed)) return;
  StrengthReduction sr;
  c.r.number_at(j, path, "increment", {0.0, 10.0, true, false}, sr.increment);
  c.r.number_at(j, path, "resolution", {0.0, 1.0, true, false}, sr.resolution);
  c.r.number_at(j, path, "max_factor", {1.0, 100.0, true, false}, sr.max_factor);
  if (j.contains("max_iterations"))
    if (auto v = c.r.integer(j["max_iterations"], path + "/max_iterations", 1, 1000))
      sr.max_iterations = static_cast<int>(*v);
  double limit = 0.0;
  if (c.r.number_at(j, path, "displacement_limit", Range::positive(), limit))
    sr.displacement_limit = limit;
  if (sr.resolution > sr.increment) {
    c.r.error(path + "/resolution", "is " + format_number(sr.resolution) +
                                        ", above the increment " + format_number(sr.increment) +
                                        "; the resolution must be at most the increment");
    return;
  }
  c.p.strength_reduction = sr;
}

}  // namespace hmpm::api::parse
