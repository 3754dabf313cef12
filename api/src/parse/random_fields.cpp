// random_fields.cpp — a material parameter given as a random field (contract
// v3, "Ensembles and random fields"):
//   {"random_field": {"distribution": D, "correlation_length": [lx, ly(, lz)], "seed": n}}
// D is {"lognormal": {"mean", "cov"}}, {"normal": {"mean", "std"}} or
// {"uniform": {"min", "max"}}; a correlation length is a number > 0 (m) or
// "infinite" (perfectly correlated along that axis). The solver generates
// the field (solver/include/hmpm/random_field.hpp).
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

constexpr std::string_view parameter_allowed[] = {"random_field"};
constexpr std::string_view field_allowed[] = {"distribution", "correlation_length", "seed"};
constexpr std::string_view distributions[] = {"lognormal", "normal", "uniform"};
constexpr std::string_view lognormal_keys[] = {"mean", "cov"};
constexpr std::string_view normal_keys[] = {"mean", "std"};
constexpr std::string_view uniform_keys[] = {"min", "max"};

/// The largest integer a JSON number holds exactly.
constexpr std::int64_t max_seed = 9007199254740991;  // 2^53 - 1

void read_distribution(SpecReader& r, const json& j, const std::string& path, RandomField& f) {
  if (!j.is_object() || j.size() != 1) {
    r.error(path,
            "expected an object with one key, 'lognormal', 'normal' or 'uniform' (e.g. "
            "{\"lognormal\": {\"mean\": 10e6, \"cov\": 0.3}})");
    return;
  }
  const auto& [name, body] = *j.items().begin();
  if (!r.one_of(json(name), path, distributions)) return;
  const std::string bp = child_pointer(path, name);
  if (name == "lognormal") {
    f.distribution = RandomField::Distribution::lognormal;
    if (!r.object(body, bp, lognormal_keys, lognormal_keys)) return;
    r.number_at(body, bp, "mean", Range::positive(), f.first);
    r.number_at(body, bp, "cov", Range::non_negative(), f.second);
  } else if (name == "normal") {
    f.distribution = RandomField::Distribution::normal;
    if (!r.object(body, bp, normal_keys, normal_keys)) return;
    r.number_at(body, bp, "mean", Range::any(), f.first);
    r.number_at(body, bp, "std", Range::non_negative(), f.second);
  } else {
    f.distribution = RandomField::Distribution::uniform;
    if (!r.object(body, bp, uniform_keys, uniform_keys)) return;
    const bool lo = r.number_at(body, bp, "min", Range::any(), f.first);
    const bool hi = r.number_at(body, bp, "max", Range::any(), f.second);
    if (lo && hi && f.first > f.second)
      r.error(bp + "/max", "is " + format_number(f.second) + "; must not be below min " +
                               format_number(f.first));
  }
}

}  // namespace

std::optional<RandomField> read_random_field(ParseContext& c, const json& j,
                                             const std::string& path) {
  SpecReader& r = c.r;
  if (!r.object(j, path, parameter_allowed, parameter_allowed)) return std::nullopt;
  const std::string fp = path + "/random_field";
  const json& f = j["random_field"];
  if (!r.object(f, fp, field_allowed, field_allowed)) return std::nullopt;
  const std::size_t errors = r.error_count();
  RandomField out;
  read_distribution(r, f["distribution"], fp + "/distribution", out);
  const json& lengths = f["correlation_length"];
  const std::string lp = fp + "/correlation_length";
  if (r.per_axis(lengths, lp, c.dim, "a correlation length (m, > 0, or \"infinite\")")) {
    for (std::size_t a = 0; a < lengths.size() && a < 3; ++a) {
      const json& l = lengths[a];
      const std::string ap = child_pointer(lp, a);
      if (l.is_string()) {
        if (l.get<std::string>() == "infinite")
          out.correlation_length[a] = std::numeric_limits<double>::infinity();
        else
          r.error(ap, "is \"" + l.get<std::string>() +
                          "\"; expected a length in m (> 0) or \"infinite\"");
      } else if (auto v = r.number(l, ap, Range::positive())) {
        out.correlation_length[a] = *v;
      }
    }
  }
  if (auto seed = r.integer(f["seed"], fp + "/seed", 0, max_seed))
    out.seed = static_cast<std::uint64_t>(*seed);
  if (r.error_count() > errors) return std::nullopt;
  return out;
}

}  // namespace hmpm::api::parse
