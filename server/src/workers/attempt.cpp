// workers/attempt.cpp — one attempt at a job: its folder prepared (resumed
// from a checkpoint or started afresh), the run with its progress and
// checkpoint writers, and its end written to the store. See workers/pool.hpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "digest.hpp"
#include "job_log.hpp"
#include "run_log.hpp"
#include "run_tracker.hpp"
#include "workers/pool.hpp"

namespace hmpm::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

double seconds_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double>(SteadyClock::now() - t0).count();
}

void log_transition(const std::string& id, JobStatus to, nlohmann::ordered_json extra = {}) {
  nlohmann::ordered_json line{{"event", "job"}, {"job", id}, {"status", status_name(to)}};
  for (auto& [key, value] : extra.items()) line[key] = value;
  log_line(std::move(line));
}

// The first few spec errors as one line, for a failure reason.
std::string describe(const std::vector<hmpm::api::SpecError>& errors) {
  std::string text;
  for (std::size_t i = 0; i < errors.size() && i < 5; ++i) {
    text += (i ? "; " : "") + (errors[i].path.empty() ? std::string("/") : errors[i].path) + ": " +
            errors[i].message;
  }
  return text;
}

// `x` rounded down to a whole number.
long whole(double x) {
  return static_cast<long>(std::floor(x));
}

// `x` with 4 significant digits ("0.25", "1.234e+04").
std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

// The bytes of the recorded checkpoint `rec` in `dir` when the file is
// there, a regular file of the recorded size and SHA-256 that belongs to
// `job` (spec text `key`); otherwise nullopt, with why in `why`. Whatever
// stands in the file's place (a directory, a FIFO, a device) is refused
// without blocking or reading it (read_checkpoint_file).
std::optional<std::string> read_checkpoint(const std::filesystem::path& dir,
                                           const CheckpointRecord& rec,
                                           const hmpm::api::ParsedJob& job, const std::string& key,
                                           std::string& why) {
  std::string bytes;
  try {
    bytes = read_checkpoint_file(dir / rec.file, rec.size);
  } catch (const std::exception& e) {
    why = "its file " + rec.file + " " + e.what();
    return std::nullopt;
  }
  if (sha256_hex(bytes) != rec.sha256) {
    why = "its file " + rec.file + " does not have the recorded SHA-256";
    return std::nullopt;
  }
  try {
    (void)hmpm::inspect_checkpoint(job.problem, key, bytes);
  } catch (const std::exception& e) {
    why = std::string("the solver refuses it: ") + e.what();
    return std::nullopt;
  }
  return bytes;
}

// What one attempt knows while it runs: its claim and folders, the
// checkpoint it resumed from or last recorded, and the pace of its progress
// writes. Its progress and checkpoint writers are the solver's callbacks.
class Attempt {
 public:
  Attempt(JobStore& store, const WorkerSettings& settings, const JobFiles& files,
          const JobRecord& job, RunningJob& running)
      : store_(store),
        settings_(settings),
        job_(job),
        running_(running),
        claim_(claim_of(job)),
        dir_(files.job_dir(job.id)),
        out_(files.attempt_dir(claim_)),
        out_name_(out_.filename().string()) {}

  // Prepares the job's folder: an earlier attempt's checkpoint is resumed
  // from when it is intact, else the run starts afresh (the folder then
  // loses that attempt's leftovers). Logs the start.
  void prepare(const hmpm::api::ParseResult& parsed) {
    std::optional<CheckpointRecord> recorded;
    try {
      recorded = store_.checkpoint(job_.id);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"job", job_.id}, {"detail", e.what()}});
    }
    if (recorded && parsed.ok() && settings_.checkpoint_interval_s > 0) {
      std::string why;
      resume_ = read_checkpoint(dir_, *recorded, *parsed.job, job_.spec, why);
      if (!resume_) {
        append_run_log(dir_, "checkpoint at step " + std::to_string(recorded->step) +
                                 " not usable (" + why + "): starting from step 0");
        log_line({{"event", "checkpoint"}, {"job", job_.id}, {"unusable", why}});
      }
    }
    if (resume_) {
      // The snapshots so far come along into this attempt's folder; the
      // folder resumed from stays until this attempt records a checkpoint of
      // its own (until then a crash resumes from the same one).
      checkpoint_file_ = recorded->file;
      const std::string from = std::filesystem::path(checkpoint_file_).begin()->string();
      const bool legacy = from == checkpoint_file_;  // an older server's file in `dir` itself
      try {
        if (legacy) {
          carry_over(dir_, out_);
        } else {
          remove_all_but_log(dir_, from);  // folders of attempts before that one
          carry_over(dir_ / from, out_);
        }
      } catch (const std::exception& e) {
        append_run_log(dir_,
                       std::string("the results before the checkpoint could not be copied (") +
                           e.what() + "): starting from step 0");
        resume_.reset();
        checkpoint_file_.clear();
      }
    }
    if (!resume_) remove_all_but_log(dir_);  // leftovers of interrupted attempts
    append_run_log(dir_, "attempt " + std::to_string(job_.attempts) + " started on " +
                             settings_.claimant.instance + ": " +
                             std::to_string(job_.cost.particles) + " particles, " +
                             std::to_string(job_.cost.steps) + " steps, " +
                             std::to_string(settings_.threads_per_job) + " solver threads");
    if (resume_) {
      append_run_log(dir_, "resumed from the checkpoint at step " + std::to_string(recorded->step) +
                               ", t = " + short_number(recorded->time) + " s (" + recorded->file +
                               ", written " + recorded->written + ")");
      log_line({{"event", "checkpoint"}, {"job", job_.id}, {"resumed_step", recorded->step}});
    }
  }

  // The solver's options for this attempt, its callbacks writing to the
  // store and the job's log.
  hmpm::RunOptions options() {
    hmpm::RunOptions options;
    options.threads = settings_.threads_per_job;
    options.cancel = &running_.cancel;
    options.wall_time_limit_s = settings_.wall_time_limit_s;
    options.progress_interval_s = settings_.progress_interval_s;
    options.on_progress = [this](const hmpm::Progress& p) { progress(p); };
    options.checkpoint_key = job_.spec;
    options.checkpoint_interval_s = settings_.checkpoint_interval_s;
    if (resume_) options.resume = &*resume_;
    if (settings_.checkpoint_interval_s > 0)
      options.on_checkpoint = [this](const hmpm::Checkpoint& c) { checkpoint(c); };
    return options;
  }

  double seconds() const { return seconds_since(t0_); }
  const Claim& claim() const { return claim_; }
  /// The job's folder.
  const std::filesystem::path& dir() const { return dir_; }
  /// This attempt's files, fenced.
  const std::filesystem::path& out() const { return out_; }
  const std::string& out_name() const { return out_name_; }
  /// The recorded checkpoint of this job, if any (relative to dir()).
  const std::string& checkpoint_file() const { return checkpoint_file_; }
  RunTracker& tracker() { return tracker_; }

 private:
  // A claimed write was refused: stop, as for a cancel.
  void stop_on(ClaimState state) {
    running_.dismissed = state == ClaimState::dismissed;
    running_.lost = state == ClaimState::lost;
    running_.cancel = true;
  }

  void progress(const hmpm::Progress& p) {
    const RunProgress& reached = tracker_.observe(p);
    const auto now = SteadyClock::now();
    if (pacer_.due(p.fraction, now)) {
      append_run_log(dir_, "progress " + std::to_string(whole(100.0 * p.fraction)) + " %: step " +
                               std::to_string(p.step) + " of " + std::to_string(p.total_steps) +
                               ", t = " + short_number(p.time) + " of " + short_number(p.end_time) +
                               " s, " + short_number(seconds_since(t0_)) + " s wall");
    }
    if (now - last_write_ < std::chrono::duration<double>(0.5 * settings_.progress_interval_s))
      return;
    last_write_ = now;
    try {
      const ClaimState state = store_.record_progress(claim_, reached);
      if (state != ClaimState::held) stop_on(state);  // dismissed elsewhere, or taken over
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"job", job_.id}, {"detail", e.what()}});
    }
  }

  void checkpoint(const hmpm::Checkpoint& c) {
    // The solver's last checkpoint of a cancelled run is kept for a
    // shutdown only (a dismissed job, or one another claim took, is over).
    if (running_.dismissed || running_.lost) return;
    const auto t1 = SteadyClock::now();
    const std::string name = checkpoint_path(claim_, c.step);  // relative to the job's folder
    try {
      write_durably(dir_ / name, c.bytes);
      const CheckpointRecord rec{
          name, c.step, c.time, static_cast<std::int64_t>(c.bytes.size()), sha256_hex(c.bytes), ""};
      const ClaimState state = store_.record_checkpoint(claim_, rec);
      if (state != ClaimState::held) {  // not ours to record: stop, as for progress
        std::error_code ec;
        std::filesystem::remove(dir_ / name, ec);
        stop_on(state);
        return;
      }
      if (!checkpoint_file_.empty() && checkpoint_file_ != name) {
        std::error_code ec;
        std::filesystem::remove(dir_ / checkpoint_file_, ec);
        remove_all_but_log(dir_, out_name_);  // the folder resumed from, if any
      }
      checkpoint_file_ = name;
      append_run_log(dir_, "checkpoint at step " + std::to_string(c.step) + ", t = " +
                               short_number(c.time) + " s: " + std::to_string(c.bytes.size()) +
                               " bytes in " + short_number(seconds_since(t1)) + " s");
    } catch (const std::exception& e) {  // the run goes on; the last checkpoint stays
      std::error_code ec;
      std::filesystem::remove(dir_ / name, ec);
      log_line({{"event", "checkpoint_error"}, {"job", job_.id}, {"detail", e.what()}});
    }
  }

  JobStore& store_;
  const WorkerSettings& settings_;
  const JobRecord& job_;
  RunningJob& running_;
  const SteadyClock::time_point t0_ = SteadyClock::now();
  const Claim claim_;
  const std::filesystem::path dir_;
  const std::filesystem::path out_;
  const std::string out_name_;
  std::optional<std::string> resume_;  ///< the checkpoint's bytes, when resuming
  std::string checkpoint_file_;
  SteadyClock::time_point last_write_ = SteadyClock::now() - std::chrono::hours(1);
  ProgressLogPacer pacer_;
  RunTracker tracker_;  ///< what the run reached, for the store
};

}  // namespace

void WorkerPool::claim_lost(const Claim& claim, double seconds) {
  ++metrics_.claims_lost;
  log_line({{"event", "job"}, {"job", claim.job_id}, {"claim", "lost"}, {"seconds", seconds}});
  discard_if_ended(claim);
}

void WorkerPool::discard_if_ended(const Claim& claim) {
  try {
    const auto job = store_.find(claim.job_id);
    if (job && job->lease_token != claim.token &&
        (job->status == JobStatus::successful || job->status == JobStatus::failed ||
         job->status == JobStatus::dismissed)) {
      std::error_code ec;
      std::filesystem::remove_all(files_.attempt_dir(claim), ec);
    }
  } catch (const std::exception& e) {  // the folder stays until retention removes the job
    log_line({{"event", "store_error"}, {"job", claim.job_id}, {"detail", e.what()}});
  }
}

void WorkerPool::end_dismissed(const JobRecord& job, const Claim& claim,
                               const std::vector<std::string>& written, double seconds) {
  const std::filesystem::path dir = files_.job_dir(job.id);
  const std::filesystem::path out = files_.attempt_dir(claim);
  std::vector<ResultFile> files;
  record_files(out, written, files);
  ClaimState state = ClaimState::lost;
  try {
    state = with_retries(job.id, "keep_results",
                         [&] { return store_.keep_results(claim, files, seconds); });
  } catch (const std::exception& e) {  // shutting down: the next start recovers the job
    log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
  }
  if (state == ClaimState::lost) {  // not ours any more: touch nothing
    claim_lost(claim, seconds);
    return;
  }
  const bool kept = state == ClaimState::held;
  std::error_code ec;
  if (kept) {
    remove_checkpoints_but(out);
    remove_all_but_log(dir, out.filename().string());  // other attempts' folders
    append_run_log(dir, "cancelled after " + short_number(seconds) + " s wall; " +
                            std::to_string(files.size()) + " result files kept");
  } else {
    std::filesystem::remove_all(dir, ec);  // deleted: the files go with it
  }
  metrics_.observe_job(seconds, JobStatus::dismissed);
  log_transition(job.id, JobStatus::dismissed, {{"seconds", seconds}, {"files_kept", kept}});
}

void WorkerPool::run_one(const JobRecord& job, RunningJob& running) {
  Attempt attempt(store_, settings_, files_, job, running);
  const Claim& claim = attempt.claim();
  const std::filesystem::path& dir = attempt.dir();
  const std::filesystem::path& out = attempt.out();
  log_transition(job.id, JobStatus::running, {{"attempt", job.attempts}});
  const auto parsed = hmpm::api::parse_job(job.spec, settings_.limits);
  attempt.prepare(parsed);

  JobStatus outcome = JobStatus::failed;
  std::string reason;
  hmpm::api::JobOutcome result;
  if (!parsed.ok()) {
    reason = "the stored spec is no longer valid: " + describe(parsed.errors);
  } else {
    for (const auto& w : parsed.job->warnings) {
      append_run_log(dir,
                     "warning: " + (w.path.empty() ? std::string("/") : w.path) + ": " + w.message);
    }
    try {
      std::filesystem::create_directories(out);
      result = hmpm::api::run_job(*parsed.job, out, attempt.options());
      for (const std::string& w : result.run.run_warnings) append_run_log(dir, "warning: " + w);
      if (result.run.status == hmpm::RunStatus::successful) {
        outcome = JobStatus::successful;
      } else {
        reason = result.run.message.empty()
                     ? std::string("the run ended as ") + hmpm::status_name(result.run.status)
                     : result.run.message;
      }
    } catch (const std::exception& e) {
      reason = std::string("could not write the result files: ") + e.what();
    }
  }
  const double seconds = attempt.seconds();

  if (running.lost) {  // another instance owns the job now
    claim_lost(claim, seconds);
    return;
  }
  if (running.dismissed) {
    end_dismissed(job, claim, result.files, seconds);
    return;
  }
  if (running.cancel && outcome != JobStatus::successful) {  // shutdown: run it again next start
    const ClaimState state = with_retries(job.id, "requeue", [&] { return store_.requeue(claim); });
    if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
    if (state == ClaimState::lost) {
      claim_lost(claim, seconds);
      return;
    }
    if (attempt.checkpoint_file().empty()) {
      remove_all_but_log(dir);
      append_run_log(dir, "stopped after " + short_number(seconds) +
                              " s: the server is shutting down; queued again");
    } else {  // the next attempt resumes from the checkpoint and the snapshots before it
      append_run_log(dir, "stopped after " + short_number(seconds) +
                              " s: the server is shutting down; queued again, to resume from " +
                              attempt.checkpoint_file());
    }
    log_transition(job.id, JobStatus::accepted, {{"requeued", true}, {"seconds", seconds}});
    return;
  }

  std::vector<ResultFile> files;
  if (const auto unreadable = record_files(out, result.files, files)) {
    outcome = JobStatus::failed;
    reason = "result file " + *unreadable + " could not be read back";
  }
  remove_unlisted(out, files);
  const std::string message = outcome == JobStatus::successful ? "finished" : reason;
  // The end of a job must reach the store, or it would stay running until a
  // restart: a failing write (disk full) is retried with backoff.
  const ClaimState state = with_retries(job.id, "finish", [&] {
    return store_.finish(claim,
                         JobEnd{outcome, message, reason, files, seconds,
                                attempt.tracker().finish(result.run.steps, result.run.end_time)});
  });
  if (state == ClaimState::lost) {  // taken over while finishing: not served, never will be
    claim_lost(claim, seconds);
    return;
  }
  if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
  // The job has ended: its checkpoints and other attempts' folders are of no use now.
  remove_checkpoints_but(out);
  remove_all_but_log(dir, attempt.out_name());
  append_run_log(dir, std::string(status_name(outcome)) + " after " + short_number(seconds) +
                          " s wall, " + std::to_string(files.size()) + " result files" +
                          (reason.empty() ? "" : ": " + reason));
  metrics_.observe_job(seconds, outcome);
  nlohmann::ordered_json extra{{"seconds", seconds}, {"files", files.size()}};
  if (!reason.empty()) extra["reason"] = reason;
  log_transition(job.id, outcome, std::move(extra));
}

}  // namespace hmpm::server
