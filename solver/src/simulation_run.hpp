// simulation_run.hpp — the time loop around Simulation::step: time-step
// control, output sampling, progress, cancellation and failure reports
// (internal; included by simulation.hpp).
#pragma once

namespace hmpm {

template <int Dim, class Shape>
void Simulation<Dim, Shape>::fill_snapshot(Snapshot& snap, const std::vector<Field>& fields) const {
  const std::size_t n = particles_.size();
  snap.dimension = Dim;
  snap.particles = static_cast<std::int64_t>(n);
  snap.fields = fields;
  auto vec3 = [&](std::vector<double>& out, const std::vector<Vec>& in) {
    out.assign(3 * n, 0.0);
    if (in.empty()) return;
    for (std::size_t p = 0; p < n; ++p)
      for (int a = 0; a < Dim; ++a) out[3 * p + a] = in[p][a];
  };
  auto voigt = [&](std::vector<double>& out, const std::vector<Voigt>& in) {
    out.resize(6 * n);
    for (std::size_t p = 0; p < n; ++p)
      for (int c = 0; c < 6; ++c) out[6 * p + c] = in[p][c];
  };
  auto scalar = [&](std::vector<double>& out, const std::vector<double>& in) {
    if (in.empty()) out.assign(n, 0.0);
    else out.assign(in.begin(), in.end());
  };
  for (Field f : fields) {
    switch (f) {
      case Field::position: vec3(snap.position, particles_.x); break;
      case Field::displacement: {
        snap.displacement.assign(3 * n, 0.0);
        for (std::size_t p = 0; p < n; ++p)
          for (int a = 0; a < Dim; ++a) snap.displacement[3 * p + a] = particles_.x[p][a] - particles_.x0[p][a];
        break;
      }
      case Field::velocity: vec3(snap.velocity, particles_.v); break;
      case Field::darcy_velocity: vec3(snap.darcy_velocity, particles_.darcy); break;
      case Field::pore_pressure: scalar(snap.pore_pressure, particles_.pressure_out); break;
      case Field::porosity: scalar(snap.porosity, particles_.porosity); break;
      case Field::effective_stress: voigt(snap.effective_stress, particles_.stress); break;
      case Field::strain: voigt(snap.strain, particles_.strain); break;
      case Field::total_stress: {
        voigt(snap.total_stress, particles_.stress);
        if (!particles_.pressure_out.empty())
          for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 3; ++c) snap.total_stress[6 * p + c] -= particles_.pressure_out[p];
        break;
      }
    }
  }
  snap.volume.assign(particles_.volume.begin(), particles_.volume.end());
  snap.mass.assign(particles_.mass.begin(), particles_.mass.end());
  snap.material.assign(particles_.material.begin(), particles_.material.end());
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::sample_series(Series& series, double t) const {
  series.time.push_back(t);
  for (std::size_t f = 0; f < series.fields.size(); ++f) {
    std::vector<double>& out = series.values[f];
    for (std::int64_t pi : series.particles) {
      const auto p = static_cast<std::size_t>(pi);
      switch (series.fields[f]) {
        case Field::position: for (int a = 0; a < Dim; ++a) out.push_back(particles_.x[p][a]); break;
        case Field::displacement:
          for (int a = 0; a < Dim; ++a) out.push_back(particles_.x[p][a] - particles_.x0[p][a]);
          break;
        case Field::velocity: for (int a = 0; a < Dim; ++a) out.push_back(particles_.v[p][a]); break;
        case Field::darcy_velocity:
          for (int a = 0; a < Dim; ++a) out.push_back(particles_.darcy.empty() ? 0.0 : particles_.darcy[p][a]);
          break;
        case Field::pore_pressure:
          out.push_back(particles_.pressure_out.empty() ? 0.0 : particles_.pressure_out[p]);
          break;
        case Field::porosity:
          out.push_back(particles_.porosity.empty() ? 0.0 : particles_.porosity[p]);
          break;
        case Field::effective_stress: for (int c = 0; c < 6; ++c) out.push_back(particles_.stress[p][c]); break;
        case Field::strain: for (int c = 0; c < 6; ++c) out.push_back(particles_.strain[p][c]); break;
        case Field::total_stress: {
          const double pw = particles_.pressure_out.empty() ? 0.0 : particles_.pressure_out[p];
          for (int c = 0; c < 6; ++c) out.push_back(particles_.stress[p][c] - (c < 3 ? pw : 0.0));
          break;
        }
      }
    }
  }
}

template <int Dim, class Shape>
RunResult Simulation<Dim, Shape>::run(const RunOptions& options) {
  using clock = std::chrono::steady_clock;
  RunResult result;
  stable_ = stable_step(problem_);
  const double dt = stable_.chosen;
  const double end = problem_.time.end;
  const auto total = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(end / dt - 1e-9)));
  double min_mass = std::numeric_limits<double>::infinity();
  for (double m : particles_.mass) min_mass = std::min(min_mass, m);
  mass_tolerance_ = particles_.size() ? 1e-12 * min_mass : 0.0;
  // Threads: every core when asked for <= 0, but at least
  // min_particles_per_thread particles each.
  int threads = options.threads > 0 ? options.threads
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::clamp<std::int64_t>(
      static_cast<std::int64_t>(particles_.size()) / std::max<std::int64_t>(1, options.min_particles_per_thread),
      1, threads));
  setup_threads(threads);

  result.dt = dt;
  result.particles = static_cast<std::int64_t>(particles_.size());
  result.nodes = grid_.count;
  result.state_bytes = particles_.bytes() + grid_.bytes() * threads;
  result.threads = threads;
  result.warnings = warnings_;

  // Output set-up.
  const OutputRequest& out = problem_.output;
  Series& series = result.series;
  series.dimension = Dim;
  const bool want_series = !out.series_particles.empty() && !out.series_fields.empty();
  if (want_series) {
    series.particles = out.series_particles;
    series.fields = out.series_fields;
    series.values.resize(series.fields.size());
    for (std::int64_t pi : series.particles) {
      Vec3 x0{0, 0, 0};
      for (int a = 0; a < Dim; ++a) x0[a] = particles_.x[static_cast<std::size_t>(pi)][a];
      series.initial_positions.push_back(x0);
    }
    sample_series(series, 0.0);
  }
  std::vector<Field> snapshot_fields = out.snapshot_fields;
  if (snapshot_fields.empty())
    for (int f = 0; f < field_count; ++f) snapshot_fields.push_back(static_cast<Field>(f));
  const bool want_snapshots = out.snapshot_interval > 0 && options.on_snapshot;
  Snapshot snap;
  auto take_snapshot = [&](double t) {
    snap.time = t;
    fill_snapshot(snap, snapshot_fields);
    options.on_snapshot(snap);
    ++snap.index;
  };
  if (want_snapshots) take_snapshot(0.0);
  double next_series = out.series_interval > 0 ? out.series_interval : 0.0;
  double next_snapshot = out.snapshot_interval;
  const double eps_t = 1e-9 * dt;

  const auto start = clock::now();
  auto last_progress = start;
  auto report = [&](std::int64_t n, double t) {
    if (!options.on_progress) return;
    Progress pr;
    pr.step = n;
    pr.total_steps = total;
    pr.time = t;
    pr.end_time = end;
    pr.fraction = std::clamp(t / end, 0.0, 1.0);
    options.on_progress(pr);
  };

  result.status = RunStatus::successful;
  std::int64_t n = 0;
  double t = 0.0;
  for (; n < total; ++n) {
    if (options.cancel && options.cancel->load(std::memory_order_relaxed)) {
      result.status = RunStatus::cancelled;
      result.message = "cancelled at step " + std::to_string(n) + " (t = " + number(t) + " s)";
      break;
    }
    const double t_new = (n + 1 == total) ? end : static_cast<double>(n + 1) * dt;
    step(t, t_new - t);
    if (failed_) {
      std::ostringstream where;
      if (failure_particle_ >= 0) {  // -1: a failure of the run, not of a particle
        const auto p = static_cast<std::size_t>(failure_particle_);
        where << ", particle " << failure_particle_ << " at (";
        for (int a = 0; a < Dim; ++a) where << (a ? ", " : "") << number(particles_.x[p][a]);
        where << ")";
      }
      result.status = RunStatus::failed;
      result.message = "step " + std::to_string(n + 1) + " (t = " + number(t_new) + " s)" +
                       where.str() + ": " + failure_ + ". What to change: " + failure_hint_ + ".";
      t = t_new;
      ++n;
      break;
    }
    t = t_new;
    if (want_series && (out.series_interval <= 0 || t >= next_series - eps_t)) {
      sample_series(series, t);
      if (out.series_interval > 0)
        while (next_series <= t + eps_t) next_series += out.series_interval;
    }
    if (want_snapshots && t >= next_snapshot - eps_t) {
      take_snapshot(t);
      while (next_snapshot <= t + eps_t) next_snapshot += out.snapshot_interval;
    }
    const auto now = clock::now();
    if (std::chrono::duration<double>(now - last_progress).count() >= options.progress_interval_s) {
      last_progress = now;
      report(n + 1, t);
      if (options.wall_time_limit_s > 0 &&
          std::chrono::duration<double>(now - start).count() > options.wall_time_limit_s) {
        result.status = RunStatus::failed;
        result.message = "wall-time limit of " + number(options.wall_time_limit_s) +
                         " s reached at step " + std::to_string(n + 1) + " of " +
                         std::to_string(total) + " (t = " + number(t) +
                         " s). What to change: shorten time.end, coarsen the grid, use fewer "
                         "particles per cell, or ask for a longer limit.";
        ++n;
        break;
      }
    }
  }
  const double seconds = std::chrono::duration<double>(clock::now() - start).count();
  result.steps = n;
  result.end_time = t;
  result.solve_seconds = seconds;
  result.particle_steps_per_second =
      seconds > 0 ? static_cast<double>(n) * static_cast<double>(particles_.size()) / seconds : 0.0;
  if (result.status == RunStatus::successful)
    result.message = "completed " + std::to_string(n) + " steps to t = " + number(t) + " s";
  report(n, t);
  return result;
}

}  // namespace hmpm
