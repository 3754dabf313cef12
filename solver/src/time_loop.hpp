// time_loop.hpp — the time loop around a time scheme's step: time-step
// control, output sampling, progress, cancellation, the wall-time limit,
// checkpoints and resuming from one (checkpoint.hpp), and failure reports
// (internal). The scheme (schemes/) owns the step and its
// stable-step rule; this loop owns everything between steps.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "checkpoint.hpp"
#include "collapse_watch.hpp"
#include "output.hpp"
#include "run_watch.hpp"
#include "schemes/make_scheme.hpp"
#include "schemes/table.hpp"
#include "schemes/time_scheme.hpp"
#include "simulation.hpp"

namespace hmpm {

/// Adds a stage's iteration counts to the job's (the worst step overall
/// keeps its residual history).
inline void add_iterations(RunResult::Iterations& into, const RunResult::Iterations& from) {
  into.nonlinear += from.nonlinear;
  into.linear += from.linear;
  into.solves += from.solves;
  into.cutbacks += from.cutbacks;
  if (from.max_nonlinear > into.max_nonlinear) {
    into.max_nonlinear = from.max_nonlinear;
    into.worst_residuals = from.worst_residuals;
  }
}

/// A quasi-static run with linear shape functions whose particles crossed
/// cell boundaries (their cell now is not the one they started in): linear
/// gradients jump there, so the settlement comes out too large and the
/// stresses scatter (a Cam-Clay column settling half a cell: 15 % more
/// settlement than the model's oedometric integration, particles' sigma'_v
/// off by up to 40 % of the load; with GIMP 0.5 % and 3 %,
/// docs/verification.md). The run still ends as it ends; this says so.
/// Dynamic runs are left to the spec-time estimate (check_cell_crossing):
/// their particles cross cells by design in runouts.
template <int Dim, class Shape>
void Simulation<Dim, Shape>::report_cell_crossings(RunResult& result) const {
  if (job_.shape_function != ShapeFunction::linear ||
      model_.problem.time.scheme != Scheme::quasi_static)
    return;
  std::size_t crossed = 0;
  double farthest = 0.0;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    bool moved = false;
    for (int a = 0; a < Dim; ++a) {
      const double from = (particles_.x0[p][a] - grid_.origin[a]) * grid_.inv_h[a];
      const double to = (particles_.x[p][a] - grid_.origin[a]) * grid_.inv_h[a];
      moved = moved || std::floor(from) != std::floor(to);
    }
    if (!moved) continue;
    ++crossed;
    farthest = std::max(farthest, (particles_.x[p] - particles_.x0[p]).norm());
  }
  if (crossed == 0) return;
  result.run_warnings.push_back(
      std::to_string(crossed) + " of " + std::to_string(particles_.size()) +
      " particles crossed a cell boundary in this quasi-static run (the farthest moved " +
      number(farthest) +
      " m) with linear shape functions, whose gradients jump there: settlements come out "
      "too large and stresses scatter (a clay settling half a cell: 15 % more settlement, "
      "stresses off by up to 40 % of the load; 0.5 % and 3 % with GIMP). What to change: "
      "\"shape_function\": \"gimp\" or \"bspline\"");
}

template <int Dim, class Shape>
RunResult Simulation<Dim, Shape>::run(const RunOptions& options) {
  using Clock = std::chrono::steady_clock;
  RunResult result;
  const std::size_t stages = stage_count(job_);
  // Every stage's estimated steps (progress); a stage's scheme says its own.
  std::int64_t total = 0;
  for (std::size_t k = 0; k < stages; ++k) {
    const StableStep step = stable_step(stage_problem(job_, k));
    total += std::max<std::int64_t>(1, step.steps);
    if (k == 0) {  // the first stage's (also when resumed later)
      result.dt = step.chosen;
      const Problem& first = stage_problem(job_, 0);
      result.dt_rule = step.follows_state ? "stable_with_state"
                       : !step.fixed      ? "growing"
                       : first.time.dt    ? "user"
                                          : "stable";
    }
  }
  double dt_min = std::numeric_limits<double>::infinity(), dt_max = 0.0;  // steps taken
  double shortened_dt = 0.0;  // the last step shortened to end a stage
  const double end = stage_problem(job_, stages - 1).time.end;  // the job's end
  result.scheme = scheme_name(job_.time.scheme);
  result.reports_iterations = scheme_row(job_.time.scheme).reports_iterations;
  double min_mass = std::numeric_limits<double>::infinity();
  for (double m : particles_.mass) min_mass = std::min(min_mass, m);
  for (double m : dormant_.mass) min_mass = std::min(min_mass, m);
  model_.mass_tolerance = job_particles_ > 0 ? 1e-12 * min_mass : 0.0;
  // Threads: every core when asked for <= 0, but at least
  // min_particles_per_thread particles each.
  int threads = options.threads > 0
                    ? options.threads
                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::clamp<std::int64_t>(
      job_particles_ / std::max<std::int64_t>(1, options.min_particles_per_thread), 1, threads));
  threads_.start(threads, grid_, model_.fluid);

  result.particles = job_particles_;
  result.nodes = grid_.count;
  result.state_bytes = particles_.bytes() + dormant_.bytes() + grid_.bytes() * threads;
  for (const auto& r : threads_.records)
    result.state_bytes += static_cast<std::int64_t>(r.size() * sizeof(NodeRecord));
  result.threads = threads;
  result.warnings = warnings_;
  failures_.warned = !warnings_.empty();

  // Output set-up.
  const OutputRequest& out = job_.output;
  Series& series = result.series;
  series.dimension = Dim;
  // A series (or a profile) of these particles and fields, empty.
  auto start_series = [&](Series& s, const std::vector<std::int64_t>& particles,
                          const std::vector<Field>& fields) {
    s.dimension = Dim;
    s.particles = particles;
    s.fields = fields;
    s.values.resize(fields.size());
    const std::vector<Vec3> x0 = slot_.empty() ? std::vector<Vec3>{} : initial_positions(job_);
    for (std::int64_t pi : particles) {
      Vec3 at{0, 0, 0};
      if (slot_.empty())
        for (int a = 0; a < Dim; ++a) at[a] = particles_.x[static_cast<std::size_t>(pi)][a];
      else
        at = x0[static_cast<std::size_t>(pi)];
      s.initial_positions.push_back(at);
    }
  };
  const bool want_series = !out.series_particles.empty() && !out.series_fields.empty();
  if (want_series) start_series(series, out.series_particles, out.series_fields);
  // Profiles: sampled together at t = 0, every profile_interval and at
  // each of profile_times (the next one not sampled yet: next_listed).
  std::vector<Series>& profiles = result.profiles;
  const bool want_profiles =
      !out.profiles.empty() && (out.profile_interval > 0 || !out.profile_times.empty());
  if (want_profiles) {
    profiles.resize(out.profiles.size());
    for (std::size_t l = 0; l < profiles.size(); ++l)
      start_series(profiles[l], out.profiles[l].particles, out.profiles[l].fields);
  }
  double next_profile =
      out.profile_interval > 0 ? out.profile_interval : std::numeric_limits<double>::infinity();
  std::size_t next_listed = 0;
  auto listed_time = [&]() {
    return next_listed < out.profile_times.size() ? out.profile_times[next_listed]
                                                  : std::numeric_limits<double>::infinity();
  };
  // Consolidation: the excess of the counted particles (job indices; none
  // listed: every particle in the run) at `from`, then every interval after it.
  const ConsolidationRequest& cr = out.consolidation;
  RunResult::Consolidation& consolidation = result.consolidation;
  const bool want_consolidation = cr.interval > 0;
  std::vector<std::int64_t> counted;
  if (want_consolidation && !cr.all) {
    const std::vector<Vec3> x0 = initial_positions(job_);
    for (std::size_t pi = 0; pi < x0.size(); ++pi)
      if (particle_selected(job_, cr, x0[pi])) counted.push_back(static_cast<std::int64_t>(pi));
  }
  double next_consolidation = cr.from > 0 ? cr.from : cr.interval;
  // Reactions: one vector per boundary (the most any stage has) per sample,
  // the first at t = interval (a step's reaction needs the step). A boundary
  // a stage does not have exerts no force.
  Reactions& reactions = result.reactions;
  reactions.dimension = Dim;
  const bool want_reactions = out.reactions_interval > 0;
  if (want_reactions) {
    std::size_t most = job_.boundaries.size();
    for (const Stage& st : job_.stages)
      if (st.boundaries) most = std::max(most, st.boundaries->size());
    reactions.force.resize(most);
  }
  double next_reaction = out.reactions_interval;
  std::vector<Field> snapshot_fields = out.snapshot_fields;
  if (snapshot_fields.empty()) snapshot_fields = default_snapshot_fields(job_);
  const bool want_snapshots = out.snapshot_interval > 0 && options.on_snapshot;
  Snapshot snap;
  std::vector<double> snapshot_times;  // of the snapshots taken, for checkpoints
  auto take_snapshot = [&](double t) {
    snap.time = t;
    fill_snapshot(snap, snapshot_fields);
    options.on_snapshot(snap);
    ++snap.index;
    snapshot_times.push_back(t);
  };
  double next_series = out.series_interval > 0 ? out.series_interval : 0.0;
  double next_snapshot = out.snapshot_interval;
  std::int64_t n = 0;
  double t = 0.0;
  double seconds_before = 0.0;  // loop wall time of the runs before a resume
  std::size_t first_stage = 0;
  RunResult::Iterations done_iterations;  // of the stages before the one in force
  std::optional<checkpoint::Reader> resume;
  if (options.resume) {
    // Everything the loop carries, as the checkpoint left it after step n
    // (the initial positions of the series come from the set-up above).
    checkpoint::Reader& r = resume.emplace(*options.resume, checkpoint::body_end(*options.resume));
    const checkpoint::Header h =
        checkpoint::read_header(r, *options.resume, job_, options.checkpoint_key);
    n = h.step;
    t = h.time;
    total = h.total;
    next_series = h.next_series;
    next_snapshot = h.next_snapshot;
    next_reaction = h.next_reaction;
    seconds_before = h.seconds;
    snapshot_times = h.snapshot_times;
    snap.index = static_cast<int>(snapshot_times.size());
    r.array(series.time, -1, "series times");
    const auto fields = r.pod<std::uint64_t>();
    if (fields != series.values.size())
      throw std::invalid_argument("the checkpoint's series has " + std::to_string(fields) +
                                  " fields where this run has " +
                                  std::to_string(series.values.size()));
    for (std::vector<double>& v : series.values) r.array(v, -1, "series values");
    r.array(reactions.time, -1, "reaction times");
    const auto boundaries = r.pod<std::uint64_t>();
    if (boundaries != reactions.force.size())
      throw std::invalid_argument("the checkpoint has reactions of " + std::to_string(boundaries) +
                                  " boundaries where this run has " +
                                  std::to_string(reactions.force.size()));
    for (std::vector<double>& v : reactions.force) r.array(v, -1, "reactions");
    next_profile = r.pod<double>();
    const auto lines = r.pod<std::uint64_t>();
    if (lines != profiles.size())
      throw std::invalid_argument("the checkpoint has " + std::to_string(lines) +
                                  " profiles where this run has " +
                                  std::to_string(profiles.size()));
    for (Series& s : profiles) {
      r.array(s.time, -1, "profile times");
      for (std::vector<double>& v : s.values) r.array(v, -1, "profile values");
    }
    // The listed times sampled already: those up to t, and those within the
    // tolerance of the step that ended at t (1e-9 of its length, at most
    // 1e-9 t) when it took a sample.
    const bool sampled_at_t =
        !profiles.empty() && !profiles[0].time.empty() && profiles[0].time.back() == t;
    while (listed_time() <= (sampled_at_t ? t + 1e-9 * t : t)) ++next_listed;
    next_consolidation = r.pod<double>();
    r.array(consolidation.time, -1, "consolidation times");
    r.array(consolidation.excess, static_cast<std::int64_t>(consolidation.time.size()),
            "consolidation excess");
    r.array(consolidation.volume, static_cast<std::int64_t>(consolidation.time.size()),
            "consolidation volume");
    first_stage = static_cast<std::size_t>(r.pod<std::uint64_t>());
    if (first_stage >= stages)
      throw std::invalid_argument("the checkpoint is in stage " + std::to_string(first_stage) +
                                  " of a job with " + std::to_string(stages));
    done_iterations.nonlinear = r.pod<std::int64_t>();
    done_iterations.linear = r.pod<std::int64_t>();
    done_iterations.solves = r.pod<std::int64_t>();
    done_iterations.cutbacks = r.pod<std::int64_t>();
    done_iterations.max_nonlinear = r.pod<int>();
    r.array(done_iterations.worst_residuals, -1, "residuals");
    dt_min = r.pod<double>();
    dt_max = r.pod<double>();
    // The particles of the stage it was in, then their state.
    if (first_stage != stage_) enter_stage(first_stage);
    particles_.for_each_array(
        [&](auto& a) { r.array(a, static_cast<std::int64_t>(a.size()), "particle array"); });
    const auto absorbing = r.pod<std::uint64_t>();
    if (absorbing != model_.constraints.absorbing.size())
      throw std::invalid_argument("the checkpoint has " + std::to_string(absorbing) +
                                  " absorbing boundaries where this run has " +
                                  std::to_string(model_.constraints.absorbing.size()));
    for (AbsorbingConstraint& ab : model_.constraints.absorbing) {
      ab.held = r.pod<std::uint8_t>() != 0;
      r.array(ab.hold, static_cast<std::int64_t>(ab.hold.size()), "absorbing boundary's forces");
      r.array(ab.coefficient, static_cast<std::int64_t>(ab.coefficient.size()),
              "absorbing boundary's dashpots");
    }
  } else {
    if (want_series) sample_series(series, 0.0);
    for (Series& s : profiles) sample_series(s, 0.0);
    while (listed_time() <= 0.0) ++next_listed;  // t = 0 is sampled anyway
    if (want_consolidation && !(cr.from > 0)) sample_consolidation(consolidation, counted, 0.0);
    if (want_snapshots) take_snapshot(0.0);
  }

  const auto start = Clock::now();
  auto last_progress = start;
  auto last_checkpoint = start;
  const bool want_checkpoints = options.on_checkpoint && options.checkpoint_interval_s > 0;
  Checkpoint ckpt;
  std::int64_t checkpointed = n;  // steps done at the last checkpoint (or the resume)
  // The state after `done` steps (t the time reached), in the stage in
  // force, whose scheme is `scheme`.
  auto write_checkpoint = [&](std::int64_t done, Clock::time_point now, const TimeScheme& scheme) {
    checkpointed = done;
    ckpt.step = done;
    ckpt.time = t;
    ckpt.bytes.clear();
    checkpoint::Writer w(ckpt.bytes);
    checkpoint::Header h;
    h.dimension = Dim;
    h.shape = static_cast<std::uint32_t>(job_.shape_function);
    h.scheme = static_cast<std::uint32_t>(job_.time.scheme);
    h.particles = job_particles_;
    h.fingerprint = checkpoint::fingerprint(job_, options.checkpoint_key);
    h.threads = threads;
    h.step = done;
    h.time = t;
    h.total = total;
    h.next_series = next_series;
    h.next_snapshot = next_snapshot;
    h.next_reaction = next_reaction;
    h.seconds = seconds_before + std::chrono::duration<double>(now - start).count();
    h.snapshot_times = snapshot_times;
    checkpoint::write_header(w, h);
    w.array(series.time);
    w.pod(static_cast<std::uint64_t>(series.values.size()));
    for (const std::vector<double>& v : series.values) w.array(v);
    w.array(reactions.time);
    w.pod(static_cast<std::uint64_t>(reactions.force.size()));
    for (const std::vector<double>& v : reactions.force) w.array(v);
    w.pod(next_profile);
    w.pod(static_cast<std::uint64_t>(profiles.size()));
    for (const Series& s : profiles) {
      w.array(s.time);
      for (const std::vector<double>& v : s.values) w.array(v);
    }
    w.pod(next_consolidation);
    w.array(consolidation.time);
    w.array(consolidation.excess);
    w.array(consolidation.volume);
    w.pod(static_cast<std::uint64_t>(stage_));
    w.pod(done_iterations.nonlinear);
    w.pod(done_iterations.linear);
    w.pod(done_iterations.solves);
    w.pod(done_iterations.cutbacks);
    w.pod(done_iterations.max_nonlinear);
    w.array(done_iterations.worst_residuals);
    w.pod(dt_min);
    w.pod(dt_max);
    particles_.for_each_array([&](const auto& a) { w.array(a); });
    w.pod(static_cast<std::uint64_t>(model_.constraints.absorbing.size()));
    for (const AbsorbingConstraint& ab : model_.constraints.absorbing) {
      w.pod(static_cast<std::uint8_t>(ab.held ? 1 : 0));
      w.array(ab.hold);
      w.array(ab.coefficient);  // from the particles where the stage began
    }
    scheme.save(w);
    checkpoint::finish(w);
    options.on_checkpoint(ckpt);
  };
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
  // "stage 'excavation' (2 of 3), " in messages of staged jobs.
  auto stage_text = [&]() -> std::string {
    if (stages == 1) return "";
    std::string name = stage_ == 0 ? job_.first_stage_name : job_.stages[stage_ - 1].name;
    if (name.empty()) name = std::to_string(stage_ + 1);
    return "stage '" + name + "' (" + std::to_string(stage_ + 1) + " of " + std::to_string(stages) +
           "), ";
  };

  result.status = RunStatus::successful;
  for (std::size_t k = first_stage; k < stages && result.status == RunStatus::successful; ++k) {
    if (k != stage_) enter_stage(k);
    const std::unique_ptr<TimeScheme> scheme = make_scheme(context(), model_.problem.time.scheme);
    TimeScheme& time_scheme = *scheme;  // the loop sees the interface only
    model_.stable = time_scheme.stable_step(model_.problem);
    failures_.stable_limit = model_.stable.limit;
    if (resume) {
      time_scheme.load(*resume);
      if (resume->position() != checkpoint::body_end(*options.resume))
        throw std::invalid_argument(
            "the checkpoint has " +
            std::to_string(checkpoint::body_end(*options.resume) - resume->position()) +
            " bytes more than this run's state");
      resume.reset();
    }
    // Fixed steps: step j of the stage ends at start + (j + 1) dt, the last
    // at the stage's end exactly. Varying steps (quasi_static growth): the
    // scheme says each length.
    const bool fixed = model_.stable.fixed;
    const double dt = model_.stable.chosen;
    const double t0 = model_.problem.time.start, stage_end = model_.problem.time.end;
    const std::int64_t steps = std::max<std::int64_t>(1, model_.stable.steps);
    const double eps_t = 1e-9 * dt;
    std::int64_t j = fixed ? std::llround((t - t0) / dt) : 0;  // steps done in this stage

    // Plausibility of the state (run_watch.hpp): about 500 checks per stage.
    RunWatch<Dim> watch(model_.problem, model_.constants, particles_);
    const std::int64_t watch_stride = std::max<std::int64_t>(1, steps / 500);
    std::int64_t watched = -1;  // the step count at the last check
    // A collapse the explicit and semi-implicit schemes follow
    // (collapse_watch.hpp), checked as often.
    CollapseWatch<Dim> collapse_watch(model_.problem, particles_);

    for (; fixed ? j < steps : t < stage_end; ++n, ++j) {
      if (options.cancel && options.cancel->load(std::memory_order_relaxed)) {
        // A last checkpoint, so that a run stopped on purpose (a server
        // shutting down) resumes where it stopped.
        if (want_checkpoints && n > checkpointed) write_checkpoint(n, Clock::now(), time_scheme);
        result.status = RunStatus::cancelled;
        result.message = "cancelled " + stage_text() + "at step " + std::to_string(n) +
                         " (t = " + number(t) + " s)";
        break;
      }
      double t_new;
      double chosen_dt;  // the step's length before it is fitted to the stage's end
      if (fixed) {
        chosen_dt = dt;
        t_new = (j + 1 == steps) ? stage_end : t0 + static_cast<double>(j + 1) * dt;
      } else {
        // A step that would leave less than a hundredth of itself before
        // the stage's end is stretched to end there.
        const double h = time_scheme.next_dt(t);
        chosen_dt = h;
        t_new = t + h >= stage_end - 0.01 * h ? stage_end : t + h;
        if (n + 1 >= total) total = n + 2;
      }
      if (t_new - t >= chosen_dt * (1.0 - 1e-9) || t_new < stage_end) {
        dt_min = std::min(dt_min, chosen_dt);  // the step as chosen, not its rounding
        dt_max = std::max(dt_max, chosen_dt);
      } else {
        shortened_dt = t_new - t;
      }
      // Load and boundary formulas are checked at the step's end time before
      // the step uses them (the start's was checked by the step before, or
      // below at a stage's start): a NaN there is reported as the formula's,
      // not as the divergence it would cause.
      reactions_.due = want_reactions && t_new >= next_reaction - eps_t;
      if ((j > 0 || loads_finite_at<Dim>(model_.problem, model_.fluid, failures_, t)) &&
          loads_finite_at<Dim>(model_.problem, model_.fluid, failures_, t_new))
        time_scheme.step(t, t_new - t);
      if (failures_.failed) {
        std::ostringstream where;
        if (failures_.particle >= 0) {  // -1: a failure of the run, not of a particle
          const auto p = static_cast<std::size_t>(failures_.particle);
          // A particle that swelled (or shrank) past what soil does before it
          // failed: that, not the grid or the step, is the likely cause.
          failures_.hint += watch.volume_advice(particles_, p);
          where << ", particle " << (particles_.id.empty() ? failures_.particle : particles_.id[p])
                << " at (";
          for (int a = 0; a < Dim; ++a) where << (a ? ", " : "") << number(particles_.x[p][a]);
          where << ")";
        }
        result.status = RunStatus::failed;
        result.message = stage_text() + "step " + std::to_string(n + 1) + " (t = " + number(t_new) +
                         " s)" + where.str() + ": " + failures_.what +
                         ". What to change: " + failures_.hint + ".";
        t = t_new;
        ++n;
        break;
      }
      t = t_new;
      if (watch.active() && (j + 1) % watch_stride == 0) {
        watch.check(particles_, t);
        watched = j + 1;
      }
      if (collapse_watch.active() && (j + 1) % watch_stride == 0 && !failures_.collapse.found &&
          report_dynamic_collapse(collapse_watch, t)) {
        result.status = RunStatus::failed;
        result.message = stage_text() + "step " + std::to_string(n + 1) + " (t = " + number(t) +
                         " s): " + failures_.what + ". What to change: " + failures_.hint + ".";
        ++n;
        break;
      }
      if (want_series && (out.series_interval <= 0 || t >= next_series - eps_t)) {
        sample_series(series, t);
        if (out.series_interval > 0)
          while (next_series <= t + eps_t) next_series += out.series_interval;
      }
      if (reactions_.due) {
        reactions.time.push_back(t);
        for (std::size_t b = 0; b < reactions.force.size(); ++b)
          for (int a = 0; a < Dim; ++a)
            reactions.force[b].push_back(b < reactions_.force.size() ? reactions_.force[b][a]
                                                                     : 0.0);
        while (next_reaction <= t + eps_t) next_reaction += out.reactions_interval;
      }
      if (want_profiles && t >= std::min(next_profile, listed_time()) - eps_t) {
        for (Series& s : profiles) sample_series(s, t);
        while (next_profile <= t + eps_t) next_profile += out.profile_interval;
        while (listed_time() <= t + eps_t) ++next_listed;
      }
      if (want_consolidation && t >= next_consolidation - eps_t) {
        sample_consolidation(consolidation, counted, t);
        while (next_consolidation <= t + eps_t) next_consolidation += cr.interval;
      }
      if (want_snapshots && t >= next_snapshot - eps_t) {
        take_snapshot(t);
        while (next_snapshot <= t + eps_t) next_snapshot += out.snapshot_interval;
      }
      const auto now = Clock::now();
      if (std::chrono::duration<double>(now - last_progress).count() >=
          options.progress_interval_s) {
        last_progress = now;
        report(n + 1, t);
        if (options.wall_time_limit_s > 0 &&
            seconds_before + std::chrono::duration<double>(now - interrupt_.start()).count() >
                options.wall_time_limit_s) {  // set-up counts too
          result.status = RunStatus::failed;
          result.message = "wall-time limit of " + number(options.wall_time_limit_s) +
                           " s reached " + stage_text() + "at step " + std::to_string(n + 1) +
                           " of " + std::to_string(total) + " (t = " + number(t) +
                           " s). What to change: shorten time.end, coarsen the grid, use fewer "
                           "particles per cell, or ask for a longer limit.";
          ++n;
          break;
        }
      }
      if (want_checkpoints && std::chrono::duration<double>(now - last_checkpoint).count() >=
                                  options.checkpoint_interval_s) {
        write_checkpoint(n + 1, now, time_scheme);
        last_checkpoint = Clock::now();  // the interval runs from the end of the write
      }
    }
    if (watch.active() && result.status == RunStatus::successful && watched != j)
      watch.check(particles_, t);  // the stage's end state
    const std::vector<std::string> found = watch.messages();
    result.run_warnings.insert(result.run_warnings.end(), found.begin(), found.end());
    RunResult part;
    time_scheme.report(part);
    add_iterations(done_iterations, part.iterations);
  }
  if (want_consolidation && !finish_consolidation(consolidation))
    result.run_warnings.push_back(
        "output.consolidation: the excess pore pressure at t = " +
        number(consolidation.time.empty() ? cr.from : consolidation.time.front()) +
        " s is about zero, so the degree of consolidation is undefined (null). What to change: "
        "set output.consolidation.from to the end of the loading (a load applied at t = 0 "
        "builds its excess in the first step), and steady_pore_pressure to the pore pressure "
        "the ground drains to (hydrostatic under gravity)");
  result.iterations = done_iterations;
  report_cell_crossings(result);
  // The factor of safety, from the state the stages reached
  // (strength_reduction.hpp), and the mechanism as the last snapshot.
  if (result.status == RunStatus::successful && job_.strength_reduction) {
    reduce_strength(result, t, options);
    if (failures_.failed) {
      result.status = RunStatus::failed;
      result.message = "strength reduction after t = " + number(t) + " s: " + failures_.what +
                       ". What to change: " + failures_.hint + ".";
    } else if (result.status == RunStatus::successful && options.on_snapshot) {
      snap.time = t;
      snap.mechanism = true;
      fill_snapshot(snap, snapshot_fields);
      options.on_snapshot(snap);
    }
  }
  result.collapse = failures_.collapse;
  if (result.collapse.found && !result.collapse.stopped)
    result.run_warnings.push_back(result.collapse.message +
                                  "; the run went on (time.on_collapse 'continue')");
  const double seconds =
      seconds_before + std::chrono::duration<double>(Clock::now() - start).count();
  result.warnings.insert(result.warnings.end(), result.run_warnings.begin(),
                         result.run_warnings.end());
  result.steps = n;
  result.end_time = t;
  if (!(dt_max > 0)) dt_min = dt_max = shortened_dt;  // only shortened steps (or none)
  result.dt_min = dt_min;
  result.dt_max = dt_max;
  result.solve_seconds = seconds;
  result.particle_steps_per_second =
      seconds > 0 ? static_cast<double>(n) * static_cast<double>(particles_.size()) / seconds : 0.0;
  if (result.status == RunStatus::successful) {
    result.message = "completed " + std::to_string(n) + " steps to t = " + number(t) + " s";
    if (stages > 1) result.message.append(" in ").append(std::to_string(stages)).append(" stages");
    if (result.strength_reduction.done)
      result.message.append("; ").append(result.strength_reduction.message);
    if (result.collapse.found)
      result.message.append("; the soil collapsed at t = ")
          .append(number(result.collapse.time))
          .append(" s (")
          .append(result.collapse.criterion)
          .append(", see the warnings)");
  }
  report(n, t);
  return result;
}

/// A dynamic collapse found by `w` at time t (collapse_watch.hpp): its
/// load and message into failures_.collapse; true when the run stops there
/// (time.on_collapse 'stop', fail_run), false when it goes on (a warning).
template <int Dim, class Shape>
bool Simulation<Dim, Shape>::report_dynamic_collapse(CollapseWatch<Dim>& w, double t) {
  RunResult::Collapse& k = failures_.collapse;
  if (!w.check(particles_, t, k)) return false;
  k.load = traction_resultant(model_.tractions, particles_, t);
  auto text = [](const Vec3& v) {
    std::string s = "(";
    for (int a = 0; a < Dim; ++a) s += (a ? ", " : "") + number(v[static_cast<std::size_t>(a)]);
    return s + ")";
  };
  std::ostringstream what;
  what << "the soil collapses: at t = " << number(t) << " s a particle that yielded has moved "
       << number(w.worst()) << " m, more than " << static_cast<int>(collapse_fraction * 100)
       << " % of the soil's height (" << number(w.height()) << " m): a mechanism; surface loads "
       << text(k.load) << " N";
  if (Dim < 3) what << (Dim == 2 ? "/m" : "/m^2");
  what << ", largest displacement " << number(k.max_displacement) << " m, " << k.yielding
       << " particles yielding";
  if (k.yielding > 0) what << " in " << text(k.yield_min) << " .. " << text(k.yield_max);
  k.message = what.str();
  k.stopped = collapse_action(model_.problem.time) == CollapseAction::stop;
  if (k.stopped)
    failures_.fail_run(k.message,
                       "strengthen the soil or lower the loads if it should stand; to follow the "
                       "run-out, set time.on_collapse to 'continue' (the default of the explicit "
                       "and semi-implicit schemes)");
  return k.stopped;
}

}  // namespace hmpm
