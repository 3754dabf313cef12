// ensembles/ensemble.cpp — reading an ensemble request, its samples, and
// the statistics of their series (ensemble.hpp).
#include "ensembles/ensemble.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

namespace hmpm::server::ensembles {

namespace {

void error(std::vector<api::SpecError>& errors, std::string path, std::string message) {
  errors.push_back({std::move(path), std::move(message)});
}

bool is_finite_number(const json& v) {
  return v.is_number() && std::isfinite(v.get<double>());
}

/// A number > 0 (or >= 0) at key `k` of `o`, or an error.
std::optional<double> read_number(const json& o, std::string_view k, const std::string& path,
                                  bool positive, std::vector<api::SpecError>& errors) {
  const std::string at = path + "/" + std::string(k);
  if (!o.contains(k)) {
    error(errors, at, "missing: a number");
    return std::nullopt;
  }
  const json& v = o.at(std::string(k));
  if (!is_finite_number(v)) {
    error(errors, at, "must be a finite number");
    return std::nullopt;
  }
  const double x = v.get<double>();
  if (positive && !(x > 0)) {
    error(errors, at, "must be > 0");
    return std::nullopt;
  }
  return x;
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// The standard normal draw of varied parameter j in sample k: the first
/// deviate of the random-field generator seeded by (seed, j, k).
double standard_normal(std::uint64_t seed, std::size_t j, int k) {
  RandomField one;
  one.seed = mix(mix(seed ^ mix(j + 1)) + static_cast<std::uint64_t>(k));
  return gaussian_field(one, 1, {{0.0, 0.0, 0.0}})[0];
}

}  // namespace

std::optional<RandomField> read_distribution(const json& d, const std::string& path,
                                             std::vector<api::SpecError>& errors) {
  const char* expected =
      R"(must be {"lognormal": {"mean", "cov"}}, {"normal": {"mean", "std"}} or {"uniform": {"min", "max"}})";
  if (!d.is_object() || d.size() != 1) {
    error(errors, path, expected);
    return std::nullopt;
  }
  const std::string kind = d.begin().key();
  const json& p = d.begin().value();
  const std::string at = path + "/" + kind;
  if (!p.is_object()) {
    error(errors, at, "must be an object");
    return std::nullopt;
  }
  RandomField f;
  const std::size_t before = errors.size();
  if (kind == "lognormal") {
    f.distribution = RandomField::Distribution::lognormal;
    f.first = read_number(p, "mean", at, true, errors).value_or(0);
    f.second = read_number(p, "cov", at, true, errors).value_or(0);
  } else if (kind == "normal") {
    f.distribution = RandomField::Distribution::normal;
    f.first = read_number(p, "mean", at, false, errors).value_or(0);
    f.second = read_number(p, "std", at, false, errors).value_or(0);
    if (errors.size() == before && f.second < 0) error(errors, at + "/std", "must be >= 0");
  } else if (kind == "uniform") {
    f.distribution = RandomField::Distribution::uniform;
    f.first = read_number(p, "min", at, false, errors).value_or(0);
    f.second = read_number(p, "max", at, false, errors).value_or(0);
    if (errors.size() == before && !(f.second > f.first))
      error(errors, at + "/max", "must be > min");
  } else {
    error(errors, path, expected);
    return std::nullopt;
  }
  for (const auto& [key, value] : p.items()) {
    static const std::vector<std::string> known = {"mean", "cov", "std", "min", "max"};
    if (std::find(known.begin(), known.end(), key) == known.end())
      error(errors, at + "/" + key, "unknown key");
  }
  if (errors.size() != before) return std::nullopt;
  return f;
}

std::optional<Request> read_request(const json& body, std::vector<api::SpecError>& errors) {
  const std::size_t before = errors.size();
  if (!body.is_object()) {
    error(errors, "", R"(must be an object {"spec", "samples", "seed", "vary"})");
    return std::nullopt;
  }
  for (const auto& [key, value] : body.items())
    if (key != "spec" && key != "samples" && key != "seed" && key != "vary")
      error(errors, "/" + key, "unknown key (spec, samples, seed, vary)");
  Request r;
  if (!body.contains("spec") || !body["spec"].is_object())
    error(errors, "/spec", "must be a job spec (an object)");
  else
    r.spec = body["spec"];
  if (body.contains("seed")) {
    const json& s = body["seed"];
    if (!s.is_number_integer() || s.get<std::int64_t>() < 0)
      error(errors, "/seed", "must be an integer >= 0");
    else
      r.seed = s.get<std::uint64_t>();
  }
  int samples = -1;
  if (body.contains("samples")) {
    const json& s = body["samples"];
    if (!s.is_number_integer() || s.get<std::int64_t>() < 1 || s.get<std::int64_t>() > max_samples)
      error(errors, "/samples", "must be an integer from 1 to " + std::to_string(max_samples));
    else
      samples = s.get<int>();
  }
  if (!body.contains("vary") || !body["vary"].is_array() || body["vary"].empty()) {
    error(errors, "/vary",
          R"(must be a non-empty array of {"path": JSON pointer, "distribution" or "values"})");
  } else {
    const json& vary = body["vary"];
    for (std::size_t j = 0; j < vary.size(); ++j) {
      const std::string at = "/vary/" + std::to_string(j);
      const json& v = vary[j];
      if (!v.is_object()) {
        error(errors, at, "must be an object");
        continue;
      }
      for (const auto& [key, value] : v.items())
        if (key != "path" && key != "distribution" && key != "values")
          error(errors, at + "/" + key, "unknown key (path, distribution, values)");
      Vary out;
      if (!v.contains("path") || !v["path"].is_string()) {
        error(errors, at + "/path",
              "must be a JSON pointer into the spec, e.g. "
              "\"/materials/clay/cohesion\"");
      } else {
        out.path = v["path"].get<std::string>();
        try {
          const json::json_pointer ptr(out.path);
          if (!r.spec.is_null() && (!r.spec.contains(ptr) || !is_finite_number(r.spec.at(ptr))))
            error(errors, at + "/path",
                  "must name a number in the spec (" + out.path + " is " +
                      (r.spec.contains(ptr) ? std::string("not a number") : "not there") + ")");
        } catch (const json::exception&) {
          error(errors, at + "/path", "is not a JSON pointer (RFC 6901): \"" + out.path + "\"");
        }
        for (std::size_t i = 0; i < j; ++i)
          if (r.vary.size() > i && r.vary[i].path == out.path)
            error(errors, at + "/path", "is varied twice (also /vary/" + std::to_string(i) + ")");
      }
      const bool has_d = v.contains("distribution"), has_v = v.contains("values");
      if (has_d == has_v) {
        error(errors, at, "needs exactly one of distribution and values");
      } else if (has_d) {
        out.distribution = read_distribution(v["distribution"], at + "/distribution", errors);
      } else if (!v["values"].is_array() || v["values"].empty()) {
        error(errors, at + "/values", "must be a non-empty array of numbers");
      } else {
        for (std::size_t k = 0; k < v["values"].size(); ++k)
          if (!is_finite_number(v["values"][k]))
            error(errors, at + "/values/" + std::to_string(k), "must be a finite number");
        out.values = v["values"].get<std::vector<json>>();
        if (samples < 0 && !body.contains("samples"))
          samples = static_cast<int>(std::min<std::size_t>(out.values.size(), max_samples + 1));
        if (samples > 0 && out.values.size() != static_cast<std::size_t>(samples))
          error(errors, at + "/values",
                "has " + std::to_string(out.values.size()) + " values for " +
                    std::to_string(samples) + " samples: give one per sample");
      }
      r.vary.push_back(std::move(out));
    }
  }
  if (samples < 0 && !body.contains("samples"))
    error(errors, "/samples", "missing: the number of samples (an integer)");
  if (samples > max_samples)
    error(errors, "/samples", "must be at most " + std::to_string(max_samples));
  r.samples = samples;
  if (errors.size() != before) return std::nullopt;
  return r;
}

std::vector<json> sample_values(const Request& request, int k) {
  std::vector<json> out;
  for (std::size_t j = 0; j < request.vary.size(); ++j) {
    const Vary& v = request.vary[j];
    if (v.distribution)
      out.emplace_back(transform_gaussian(*v.distribution, standard_normal(request.seed, j, k)));
    else
      out.push_back(v.values[static_cast<std::size_t>(k)]);
  }
  return out;
}

json sample_spec(const Request& request, int k) {
  json spec = request.spec;
  const std::vector<json> values = sample_values(request, k);
  for (std::size_t j = 0; j < values.size(); ++j)
    spec[json::json_pointer(request.vary[j].path)] = values[j];
  const std::string base = request.spec.contains("name") && request.spec["name"].is_string()
                               ? request.spec["name"].get<std::string>()
                               : std::string("ensemble");
  spec["name"] = base + "-" + std::to_string(k);
  return spec;
}

double quantile(std::vector<double>& values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double h = q * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (h - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

Summary summarise(const std::vector<SampleState>& samples) {
  Summary out;
  std::vector<int> count(job_statuses.size(), 0);
  double total = 0;
  for (const SampleState& s : samples) {
    ++count[static_cast<std::size_t>(s.status)];
    total += is_terminal(s.status) ? 100.0 : std::clamp(s.progress, 0.0, 100.0);
  }
  out.progress = samples.empty() ? 100.0 : total / static_cast<double>(samples.size());
  out.counts = json::object();
  for (const JobStatusInfo& row : job_statuses)
    out.counts[std::string(row.name)] = count[static_cast<std::size_t>(row.status)];
  const auto n = [&](JobStatus s) { return count[static_cast<std::size_t>(s)]; };
  const int waiting = n(JobStatus::accepted);
  const int unfinished = waiting + n(JobStatus::running);
  if (unfinished > 0)
    out.status = unfinished == waiting && static_cast<std::size_t>(waiting) == samples.size()
                     ? JobStatus::accepted
                     : JobStatus::running;
  else if (n(JobStatus::dismissed) > 0)
    out.status = JobStatus::dismissed;
  else if (n(JobStatus::failed) > 0)
    out.status = JobStatus::failed;
  else
    out.status = JobStatus::successful;
  return out;
}

namespace {

/// The five figures of one scalar over the samples.
json figures(std::vector<double> v) {
  json out = json::object();
  if (v.empty()) {
    for (const char* k : {"mean", "std", "p05", "p50", "p95"}) out[k] = nullptr;
    return out;
  }
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double var = 0;
  for (double x : v) var += (x - mean) * (x - mean);
  var = v.size() > 1 ? var / static_cast<double>(v.size() - 1) : 0.0;
  out["mean"] = mean;
  out["std"] = std::sqrt(var);
  out["p05"] = quantile(v, 0.05);
  out["p50"] = quantile(v, 0.50);
  out["p95"] = quantile(v, 0.95);
  return out;
}

}  // namespace

json statistics(const std::vector<json>& series) {
  json out = json::object();
  out["samples"] = series.size();
  if (series.empty()) {
    out["time"] = json::array();
    out["particles"] = json::array();
    return out;
  }
  const json& first = series.front();
  const std::vector<double> times = first.value("time", std::vector<double>{});
  out["time"] = times;
  // Each sample's row for each time (or none).
  std::vector<std::vector<long>> row(series.size(), std::vector<long>(times.size(), -1));
  for (std::size_t s = 0; s < series.size(); ++s) {
    const std::vector<double> ts = series[s].value("time", std::vector<double>{});
    std::size_t r = 0;
    for (std::size_t t = 0; t < times.size(); ++t) {
      while (r < ts.size() && ts[r] < times[t] - 1e-9) ++r;
      if (r < ts.size() && std::abs(ts[r] - times[t]) <= 1e-9) row[s][t] = static_cast<long>(r);
    }
  }
  json particles = json::array();
  const json& ps = first.value("particles", json::array());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    json p = json::object();
    p["index"] = ps[i].value("index", json(i));
    if (ps[i].contains("initial_position")) p["initial_position"] = ps[i]["initial_position"];
    for (const auto& [field, history] : ps[i].items()) {
      if (field == "index" || field == "initial_position" || !history.is_array()) continue;
      // Per time: a scalar, or a vector of components.
      json by_time = json::array();
      for (std::size_t t = 0; t < times.size(); ++t) {
        const json& shape = t < history.size() ? history[t] : json();
        const std::size_t components = shape.is_array() ? shape.size() : 1;
        std::vector<json> per_component(components);
        for (std::size_t c = 0; c < components; ++c) {
          std::vector<double> v;
          for (std::size_t s = 0; s < series.size(); ++s) {
            if (row[s][t] < 0) continue;
            const json& sp = series[s]["particles"];
            if (i >= sp.size() || !sp[i].contains(field)) continue;
            const json& cell = sp[i][field][static_cast<std::size_t>(row[s][t])];
            const json& x =
                shape.is_array() ? (cell.is_array() && c < cell.size() ? cell[c] : json()) : cell;
            if (x.is_number()) v.push_back(x.get<double>());
          }
          per_component[c] = figures(std::move(v));
        }
        by_time.push_back(std::move(per_component));
      }
      // Re-shape: field -> figure -> [time][component] (or [time]).
      json f = json::object();
      for (const char* k : {"mean", "std", "p05", "p50", "p95"}) {
        json column = json::array();
        for (std::size_t t = 0; t < times.size(); ++t) {
          const bool vector = t < history.size() && history[t].is_array();
          if (vector) {
            json comps = json::array();
            for (const json& c : by_time[t]) comps.push_back(c[k]);
            column.push_back(std::move(comps));
          } else {
            column.push_back(by_time[t][0][k]);
          }
        }
        f[k] = std::move(column);
      }
      p[field] = std::move(f);
    }
    particles.push_back(std::move(p));
  }
  out["particles"] = std::move(particles);
  return out;
}

}  // namespace hmpm::server::ensembles
