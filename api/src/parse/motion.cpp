// motion.cpp — values of time given as tables, and boundary accelerations
// integrated to the velocities the solver prescribes (or, on an absorbing
// boundary, feeds in as the outcrop motion).
//
//   {"table": [[t0, v0], [t1, v1], ...]}   piecewise linear in t, times
//                                          increasing; the end values hold
//                                          outside [t0, tn]
//   acceleration a(t) -> velocity v(t) = integral of a from 0 to t:
//     a number       v = a t
//     a table        exactly (piecewise quadratic)
//     a formula      Simpson's rule on 2^16 panels over [0, the job's end]
//                    (built once the job's end is known, see
//                    integrate_accelerations), quadratic in between; past
//                    the end the last acceleration holds
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

/// A piecewise-linear function of time and its exact integral from 0.
struct Table {
  std::vector<double> t, v;
  std::vector<double> integral;  ///< from 0 to t[k]

  double at(double x) const {
    if (x <= t.front()) return v.front();
    if (x >= t.back()) return v.back();
    const auto k =
        static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    const double s = (x - t[k]) / (t[k + 1] - t[k]);
    return v[k] + s * (v[k + 1] - v[k]);
  }

  /// integral_0^x of at(): before t0 the first value holds, after tn the last.
  double integral_to(double x) const {
    auto part = [&](double a, double b) {  // integral over [a, b] inside one piece
      return 0.5 * (at(a) + at(b)) * (b - a);
    };
    if (x <= t.front()) return v.front() * x;
    if (x >= t.back()) return integral.back() + v.back() * (x - t.back());
    const auto k =
        static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    return integral[k] + part(t[k], x);
  }

  void integrate() {
    integral.assign(t.size(), 0.0);
    integral[0] = v[0] * t[0];  // the first value held from 0 (negative t0: back to it)
    for (std::size_t k = 1; k < t.size(); ++k)
      integral[k] = integral[k - 1] + 0.5 * (v[k - 1] + v[k]) * (t[k] - t[k - 1]);
  }
};

}  // namespace

/// An acceleration formula's velocity, tabulated by integrate_accelerations.
struct IntegratedFormula {
  FieldOfTime a;
  double panel = 0.0;            ///< panel length, s
  std::vector<double> samples;   ///< a at 0, panel/2, panel, ... (2 per panel + 1)
  std::vector<double> integral;  ///< from 0 to each panel's start (one per panel + 1)

  double velocity(double t) const {
    if (integral.empty()) return 0.0;  // not built: the spec had errors
    const auto panels = integral.size() - 1;
    if (!(t > 0.0)) return samples.front() * t;
    const double end = panel * static_cast<double>(panels);
    if (t >= end) return integral.back() + samples.back() * (t - end);
    const auto k = std::min(static_cast<std::size_t>(t / panel), panels - 1);
    // The quadratic through a(k), a(k + 1/2), a(k + 1), integrated to s.
    const double s = (t - panel * static_cast<double>(k)) / panel;
    const double a0 = samples[2 * k], am = samples[2 * k + 1], a1 = samples[2 * k + 2];
    const double c1 = -3 * a0 + 4 * am - a1, c2 = 2 * a0 - 4 * am + 2 * a1;
    return integral[k] + panel * (a0 * s + c1 * s * s / 2 + c2 * s * s * s / 3);
  }

  void build(double end) {
    constexpr std::size_t panels = 1u << 16;
    panel = end / static_cast<double>(panels);
    samples.resize(2 * panels + 1);
    for (std::size_t j = 0; j < samples.size(); ++j)
      samples[j] = a(0.5 * panel * static_cast<double>(j));
    integral.assign(panels + 1, 0.0);
    for (std::size_t k = 0; k < panels; ++k)
      integral[k + 1] =
          integral[k] + panel / 6 * (samples[2 * k] + 4 * samples[2 * k + 1] + samples[2 * k + 2]);
  }
};

namespace {

constexpr std::string_view table_allowed[] = {"table"};

std::optional<Table> read_table(ParseContext& c, const json& j, const std::string& path) {
  if (!c.r.object(j, path, table_allowed, table_allowed)) return std::nullopt;
  const json& rows = j["table"];
  const std::string tp = path + "/table";
  if (!c.r.array(rows, tp, 1)) return std::nullopt;
  constexpr std::size_t max_rows = 1'000'000;
  if (rows.size() > max_rows) {
    c.r.error(tp, "has " + std::to_string(rows.size()) + " rows; at most " +
                      std::to_string(max_rows) + " (resample the record)");
    return std::nullopt;
  }
  Table table;
  bool ok = true;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const std::string rp = child_pointer(tp, k);
    const json& row = rows[k];
    if (!row.is_array() || row.size() != 2) {
      c.r.error(rp, "expected a row [t, value] (two numbers)");
      ok = false;
      continue;
    }
    const auto t = c.r.number(row[0], child_pointer(rp, 0));
    const auto v = c.r.number(row[1], child_pointer(rp, 1));
    if (!t || !v) {
      ok = false;
      continue;
    }
    if (!table.t.empty() && !(*t > table.t.back())) {
      c.r.error(child_pointer(rp, 0),
                "is " + format_number(*t) + " s, not after the previous row's " +
                    format_number(table.t.back()) + " s; times must increase down the table");
      ok = false;
    }
    table.t.push_back(*t);
    table.v.push_back(*v);
  }
  if (!ok) return std::nullopt;
  table.integrate();
  return table;
}

}  // namespace

std::optional<FieldOfTime> read_table_of_time(ParseContext& c, const json& j,
                                              const std::string& path) {
  auto table = read_table(c, j, path);
  if (!table) return std::nullopt;
  auto shared = std::make_shared<const Table>(std::move(*table));
  FieldOfTime f = [shared](double t) { return shared->at(t); };
  c.time_formulas.push_back({path, f, 1});
  return f;
}

std::optional<FieldOfTime> read_acceleration(ParseContext& c, const json& j,
                                             const std::string& path) {
  if (j.is_object()) {
    auto table = read_table(c, j, path);
    if (!table) return std::nullopt;
    auto shared = std::make_shared<const Table>(std::move(*table));
    return FieldOfTime{[shared](double t) { return shared->integral_to(t); }};
  }
  if (j.is_number()) {
    const auto a = c.r.number(j, path);
    if (!a) return std::nullopt;
    return FieldOfTime{[a = *a](double t) { return a * t; }};
  }
  auto a = read_value_of_time(c, j, path);  // a formula (checked finite with the others)
  if (!a) return std::nullopt;
  auto integrated = std::make_shared<IntegratedFormula>();
  integrated->a = std::move(*a);
  c.accelerations.push_back(integrated);
  return FieldOfTime{[integrated](double t) { return integrated->velocity(t); }};
}

void integrate_accelerations(ParseContext& c) {
  const double end = job_end_time(c.p);
  if (!(end > 0)) return;
  for (const auto& a : c.accelerations) a->build(end);
}

}  // namespace hmpm::api::parse
