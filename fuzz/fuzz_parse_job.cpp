// fuzz_parse_job.cpp — libFuzzer target for the job-spec parser and validator.
//
// Feeds arbitrary bytes to hmpm::api::parse_job and checks its promises: it
// never crashes or throws, every error has a JSON-pointer path ("" or
// starting with "/") and a message, and a spec it accepts yields a Problem
// whose compiled expressions can be evaluated and whose cost is consistent.
// Limits are lower than the defaults so one input stays cheap to process.
// Build and run: see fuzz/README.md.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "hmpm/api/job.hpp"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hmpm::api::Limits limits;
  limits.max_particles = 20'000;
  limits.max_cells = 20'000;
  limits.max_steps = 1'000'000;
  limits.max_series_particles = 200;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const hmpm::api::ParseResult r = hmpm::api::parse_job(text, limits);
  check(r.ok() == r.job.has_value());
  for (const hmpm::api::SpecError& e : r.errors) {
    check(e.path.empty() || e.path[0] == '/');
    check(!e.message.empty());
  }
  if (!r.job) return 0;
  const hmpm::Problem& p = r.job->problem;
  const hmpm::api::CostEstimate& c = r.job->cost;
  check(c.particles > 0 && c.particles <= limits.max_particles);
  check(c.steps <= limits.max_steps);
  check(c.dt > 0 && std::isfinite(c.dt));
  const hmpm::Vec3 x{0.5, 0.25, 0.125};
  volatile double sink = 0;
  for (const hmpm::Body& b : p.bodies) {
    for (const auto& f : b.initial.velocity)
      if (f) sink = sink + f(x);
    if (b.initial.pore_pressure) sink = sink + b.initial.pore_pressure(x);
    for (const auto& f : b.initial.effective_stress)
      if (f) sink = sink + f(x);
  }
  for (const hmpm::Boundary& b : p.boundaries) {
    for (const auto& f : b.velocity)
      if (f && *f) sink = sink + (*f)(0.5);
    if (b.pore_pressure && *b.pore_pressure) sink = sink + (*b.pore_pressure)(0.5);
  }
  for (const hmpm::Traction& t : p.tractions)
    for (const auto& f : t.traction)
      if (f) sink = sink + f(0.5);
  for (std::int64_t i : p.output.series_particles) check(i >= 0 && i < c.particles);
  return 0;
}
