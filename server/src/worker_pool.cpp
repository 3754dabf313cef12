// worker_pool.cpp — see worker_pool.hpp.
#include "worker_pool.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <system_error>

#include "digest.hpp"
#include "job_log.hpp"
#include "run_log.hpp"

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

// Removes everything in `dir` but the job's log (it spans every attempt).
void remove_all_but_log(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().filename() != run_log_name) std::filesystem::remove_all(entry.path(), ec);
  }
}

// Size, SHA-256 and media type of each of `names` in `dir`, appended to
// `files`; the name of the first one that cannot be read back, if any.
std::optional<std::string> record_files(const std::filesystem::path& dir,
                                        const std::vector<std::string>& names,
                                        std::vector<ResultFile>& files) {
  std::optional<std::string> unreadable;
  for (const std::string& name : names) {
    const auto path = dir / name;
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    auto sha = sha256_file_hex(path);
    if (ec || !sha) {
      if (!unreadable) unreadable = name;
      continue;
    }
    files.push_back({name, static_cast<std::int64_t>(size), *sha, hmpm::api::media_type_for(name)});
  }
  return unreadable;
}

}  // namespace

void log_recovery(const RecoveryReport& recovery) {
  for (const auto& id : recovery.requeued) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", status_name(JobStatus::accepted)},
              {"recovered", true}});
  }
  for (const auto& id : recovery.failed) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", status_name(JobStatus::failed)},
              {"recovered", true},
              {"reason", "too many interrupted attempts"}});
  }
}

void WorkerPool::claim_lost(const std::string& id, double seconds) {
  ++metrics_.claims_lost;
  log_line({{"event", "job"}, {"job", id}, {"claim", "lost"}, {"seconds", seconds}});
}

void WorkerPool::end_dismissed(const JobRecord& job, const Claim& claim,
                               const std::vector<std::string>& written, double seconds) {
  const std::filesystem::path dir = job_dir(job.id);
  std::vector<ResultFile> files;
  record_files(dir, written, files);
  ClaimState state = ClaimState::lost;
  try {
    state = store_.keep_results(claim, files, seconds);
  } catch (const std::exception& e) {
    log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
  }
  if (state == ClaimState::lost) {  // not ours any more: touch nothing
    claim_lost(job.id, seconds);
    return;
  }
  const bool kept = state == ClaimState::held;
  std::error_code ec;
  if (kept) {
    append_run_log(dir, "cancelled after " + short_number(seconds) + " s wall; " +
                            std::to_string(files.size()) + " result files kept");
  } else {
    std::filesystem::remove_all(dir, ec);  // deleted: the files go with it
  }
  metrics_.observe_job(seconds, JobStatus::dismissed);
  log_transition(job.id, JobStatus::dismissed, {{"seconds", seconds}, {"files_kept", kept}});
}

WorkerPool::WorkerPool(JobStore& store, Metrics& metrics, WorkerSettings settings)
    : store_(store), metrics_(metrics), settings_(std::move(settings)) {}

WorkerPool::~WorkerPool() {
  shutdown();
}

std::filesystem::path WorkerPool::job_dir(const std::string& id) const {
  return settings_.data_dir / id;
}

void WorkerPool::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (int i = 0; i < settings_.workers; ++i) threads_.emplace_back([this] { work(); });
  heartbeat_ = std::thread([this] { heartbeat(); });
}

void WorkerPool::heartbeat() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    heartbeat_wake_.wait_for(lock, std::chrono::duration<double>(settings_.lease_renewal_s),
                             [&] { return stopping_; });
    if (stopping_) return;
    const bool busy = !running_.empty();
    lock.unlock();
    try {
      if (busy) store_.renew_leases(settings_.claimant);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}, {"during", "lease renewal"}});
    }
    try {
      // Takes over the jobs of servers whose lease lapsed (on one SQLite
      // file there are none: the lock voided them at start-up).
      const RecoveryReport report = store_.recover(settings_.max_attempts);
      log_recovery(report);
      metrics_.recovered_jobs += static_cast<int>(report.requeued.size() + report.failed.size());
      for (std::size_t i = 0; i < report.requeued.size(); ++i) notify();
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}, {"during", "recovery"}});
    }
    lock.lock();
  }
}

void WorkerPool::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++generation_;
  }
  wake_.notify_one();
}

bool WorkerPool::cancel(const std::string& id, double wait_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto it = running_.find(id);
  if (it == running_.end()) return false;
  it->second->dismissed = true;
  it->second->cancel = true;
  job_done_.wait_for(lock, std::chrono::duration<double>(wait_s),
                     [&] { return running_.find(id) == running_.end(); });
  return true;
}

void WorkerPool::shutdown() {
  std::vector<std::thread> threads;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [id, running] : running_) running->cancel = true;
    threads.swap(threads_);
    if (heartbeat_.joinable()) threads.push_back(std::move(heartbeat_));
  }
  wake_.notify_all();
  heartbeat_wake_.notify_all();
  for (auto& t : threads) t.join();
}

void WorkerPool::work() {
  for (;;) {
    std::uint64_t seen = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;
      seen = generation_;
    }
    std::optional<JobRecord> job;
    try {
      job = store_.claim_next(settings_.claimant);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}});
    }
    if (!job) {
      // Nothing queued: sleep until a submission (or at most a second, which
      // also picks up jobs queued by another process on the same database).
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait_for(lock, std::chrono::seconds(1),
                     [&] { return stopping_ || generation_ != seen; });
      continue;
    }
    auto running = std::make_shared<Running>();
    bool registered = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!stopping_) running_[job->id] = running;
      registered = !stopping_;
    }
    if (!registered) {  // shutdown began between claim and here
      try {
        store_.requeue(claim_of(*job));
      } catch (const std::exception& e) {  // recovery at the next start requeues it
        log_line({{"event", "store_error"}, {"job", job->id}, {"detail", e.what()}});
      }
      return;
    }
    ++metrics_.busy_workers;
    try {
      run_one(*job, *running);
    } catch (const std::exception& e) {
      // Only the store can throw here; the job stays running and start-up
      // recovery will deal with it.
      log_line({{"event", "worker_error"}, {"job", job->id}, {"detail", e.what()}});
    }
    --metrics_.busy_workers;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_.erase(job->id);
    }
    job_done_.notify_all();
  }
}

void WorkerPool::run_one(const JobRecord& job, Running& running) {
  const auto t0 = SteadyClock::now();
  const Claim claim = claim_of(job);
  log_transition(job.id, JobStatus::running, {{"attempt", job.attempts}});
  const std::filesystem::path dir = job_dir(job.id);
  remove_all_but_log(dir);  // leftovers of an interrupted attempt
  append_run_log(dir, "attempt " + std::to_string(job.attempts) + " started on " +
                          settings_.claimant.instance + ": " + std::to_string(job.cost.particles) +
                          " particles, " + std::to_string(job.cost.steps) + " steps, " +
                          std::to_string(settings_.threads_per_job) + " solver threads");

  JobStatus outcome = JobStatus::failed;
  std::string reason;
  hmpm::api::JobOutcome result;
  auto parsed = hmpm::api::parse_job(job.spec, settings_.limits);
  if (!parsed.ok()) {
    reason = "the stored spec is no longer valid: " + describe(parsed.errors);
  } else {
    for (const auto& w : parsed.job->warnings) {
      append_run_log(dir,
                     "warning: " + (w.path.empty() ? std::string("/") : w.path) + ": " + w.message);
    }
    hmpm::RunOptions options;
    options.threads = settings_.threads_per_job;
    options.cancel = &running.cancel;
    options.wall_time_limit_s = settings_.wall_time_limit_s;
    options.progress_interval_s = settings_.progress_interval_s;
    auto last_write = SteadyClock::now() - std::chrono::hours(1);
    ProgressLogPacer pacer;
    options.on_progress = [&](const hmpm::Progress& p) {
      const auto now = SteadyClock::now();
      if (pacer.due(p.fraction, now)) {
        append_run_log(dir, "progress " + std::to_string(whole(100.0 * p.fraction)) + " %: step " +
                                std::to_string(p.step) + " of " + std::to_string(p.total_steps) +
                                ", t = " + short_number(p.time) + " of " +
                                short_number(p.end_time) + " s, " +
                                short_number(seconds_since(t0)) + " s wall");
      }
      if (now - last_write < std::chrono::duration<double>(0.5 * settings_.progress_interval_s))
        return;
      last_write = now;
      try {
        const ClaimState state =
            store_.update_progress(claim, std::clamp(100.0 * p.fraction, 0.0, 100.0));
        if (state != ClaimState::held) {  // dismissed through another path, or taken over: stop
          running.dismissed = state == ClaimState::dismissed;
          running.lost = state == ClaimState::lost;
          running.cancel = true;
        }
      } catch (const std::exception& e) {
        log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
      }
    };
    try {
      std::filesystem::create_directories(dir);
      result = hmpm::api::run_job(*parsed.job, dir, options);
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
  const double seconds = seconds_since(t0);

  if (running.lost) {  // another instance owns the job and its folder now
    claim_lost(job.id, seconds);
    return;
  }
  if (running.dismissed) {
    end_dismissed(job, claim, result.files, seconds);
    return;
  }
  if (running.cancel && outcome != JobStatus::successful) {  // shutdown: run it again next start
    const ClaimState state = store_.requeue(claim);
    if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
    if (state == ClaimState::lost) {
      claim_lost(job.id, seconds);
      return;
    }
    remove_all_but_log(dir);
    append_run_log(dir, "stopped after " + short_number(seconds) +
                            " s: the server is shutting down; queued again");
    log_transition(job.id, JobStatus::accepted, {{"requeued", true}, {"seconds", seconds}});
    return;
  }

  std::vector<ResultFile> files;
  if (const auto unreadable = record_files(dir, result.files, files)) {
    outcome = JobStatus::failed;
    reason = "result file " + *unreadable + " could not be read back";
  }
  const std::string message = outcome == JobStatus::successful ? "finished" : reason;
  const ClaimState state = store_.finish(claim, JobEnd{outcome, message, reason, files, seconds});
  if (state == ClaimState::lost) {  // taken over while finishing: the files are not ours
    claim_lost(job.id, seconds);
    return;
  }
  if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
  append_run_log(dir, std::string(status_name(outcome)) + " after " + short_number(seconds) +
                          " s wall, " + std::to_string(files.size()) + " result files" +
                          (reason.empty() ? "" : ": " + reason));
  metrics_.observe_job(seconds, outcome);
  nlohmann::ordered_json extra{{"seconds", seconds}, {"files", files.size()}};
  if (!reason.empty()) extra["reason"] = reason;
  log_transition(job.id, outcome, std::move(extra));
}

}  // namespace hmpm::server
