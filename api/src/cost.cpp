// cost.cpp — what a job will cost, computed before it runs: particles,
// nodes, steps from the chosen dt, memory and result-file estimates. The
// parser checks the limits against it; the server shows and stores it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "hmpm/api/job.hpp"

namespace hmpm::api {
namespace {

std::int64_t to_count(double v) {
  if (!(v > 0)) return 0;
  if (v >= 9.2e18) return std::numeric_limits<std::int64_t>::max();
  return static_cast<std::int64_t>(v);
}

}  // namespace

CostEstimate estimate_cost(const Problem& p) {
  CostEstimate c;
  const int dim = std::clamp(p.dimension, 1, 3);
  c.particles = count_particles(p);
  double cells = 1, nodes = 1;
  for (int a = 0; a < dim; ++a) {
    cells *= p.grid.cells[a];
    nodes *= p.grid.cells[a] + 1.0;
  }
  c.cells = to_count(cells);
  c.nodes = to_count(nodes);
  c.dt = stable_step(p).chosen;
  const double steps = c.dt > 0 ? std::ceil(p.time.end / c.dt - 1e-9) : 0.0;
  c.steps = to_count(steps);
  c.particle_steps = to_count(static_cast<double>(c.particles) * steps);
  c.memory_bytes = to_count(400.0 * static_cast<double>(c.particles) + 100.0 * nodes);
  const OutputRequest& o = p.output;
  double rows = 0;
  if (!o.series_particles.empty() && !o.series_fields.empty())
    rows = o.series_interval <= c.dt ? steps + 1
                                     : std::floor(p.time.end / o.series_interval + 1e-9) + 1;
  c.series_rows = to_count(rows);
  const double snaps =
      o.snapshot_interval > 0 ? std::floor(p.time.end / o.snapshot_interval + 1e-9) + 1 : 0;
  c.snapshots = to_count(snaps);
  double series_values = 0;
  for (Field f : o.series_fields) series_values += field_components(f, dim);
  series_values *= static_cast<double>(o.series_particles.size());
  // Snapshot arrays have 3 components per vector in every dimension; no
  // fields listed means every field.
  double snapshot_values = 2;  // volume, material
  if (o.snapshot_fields.empty())
    for (const FieldInfo& f : field_table) snapshot_values += field_components(f.field, 3);
  else
    for (Field f : o.snapshot_fields) snapshot_values += field_components(f, 3);
  // ~22 characters per number in series.json and again in series.csv;
  // base64 float64 in the VTU files is 8 * 4/3 bytes per number.
  const double bytes =
      4096 + rows * (1 + series_values) * 2 * 22 +
      snaps * (static_cast<double>(c.particles) * (snapshot_values * 32.0 / 3.0 + 16) + 4096);
  c.output_bytes = to_count(bytes);
  return c;
}

}  // namespace hmpm::api
