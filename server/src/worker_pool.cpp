// worker_pool.cpp — see worker_pool.hpp.
#include "worker_pool.hpp"

#include <algorithm>
#include <chrono>
#include <system_error>

#include "digest.hpp"
#include "job_log.hpp"

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

}  // namespace

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
    if (running_.empty()) continue;
    lock.unlock();
    try {
      store_.renew_leases(settings_.claimant);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}, {"during", "lease renewal"}});
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

bool WorkerPool::cancel(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = running_.find(id);
  if (it == running_.end()) return false;
  it->second->dismissed = true;
  it->second->cancel = true;
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
    std::lock_guard<std::mutex> lock(mutex_);
    running_.erase(job->id);
  }
}

void WorkerPool::run_one(const JobRecord& job, Running& running) {
  const auto t0 = SteadyClock::now();
  const Claim claim = claim_of(job);
  log_transition(job.id, JobStatus::running, {{"attempt", job.attempts}});
  const std::filesystem::path dir = job_dir(job.id);
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);  // leftovers of an interrupted attempt

  JobStatus outcome = JobStatus::failed;
  std::string reason;
  hmpm::api::JobOutcome result;
  auto parsed = hmpm::api::parse_job(job.spec, settings_.limits);
  if (!parsed.ok()) {
    reason = "the stored spec is no longer valid: " + describe(parsed.errors);
  } else {
    hmpm::RunOptions options;
    options.threads = settings_.threads_per_job;
    options.cancel = &running.cancel;
    options.wall_time_limit_s = settings_.wall_time_limit_s;
    options.progress_interval_s = settings_.progress_interval_s;
    auto last_write = SteadyClock::now() - std::chrono::hours(1);
    options.on_progress = [&](const hmpm::Progress& p) {
      const auto now = SteadyClock::now();
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
    log_line({{"event", "job"}, {"job", job.id}, {"claim", "lost"}, {"seconds", seconds}});
    return;
  }
  if (running.dismissed) {
    std::filesystem::remove_all(dir, ec);
    metrics_.observe_job(seconds, JobStatus::dismissed);
    log_transition(job.id, JobStatus::dismissed, {{"seconds", seconds}});
    return;
  }
  if (running.cancel && outcome != JobStatus::successful) {  // shutdown: run it again next start
    std::filesystem::remove_all(dir, ec);
    store_.requeue(claim);
    log_transition(job.id, JobStatus::accepted, {{"requeued", true}, {"seconds", seconds}});
    return;
  }

  std::vector<ResultFile> files;
  for (const std::string& name : result.files) {
    const auto path = dir / name;
    const auto size = std::filesystem::file_size(path, ec);
    auto sha = sha256_file_hex(path);
    if (ec || !sha) {
      outcome = JobStatus::failed;
      reason = "result file " + name + " could not be read back";
      continue;
    }
    files.push_back({name, static_cast<std::int64_t>(size), *sha, hmpm::api::media_type_for(name)});
  }
  const std::string message = outcome == JobStatus::successful ? "finished" : reason;
  const ClaimState state = store_.finish(claim, JobEnd{outcome, message, reason, files, seconds});
  if (state == ClaimState::lost) {  // taken over while finishing: the files are not ours
    log_line({{"event", "job"}, {"job", job.id}, {"claim", "lost"}, {"seconds", seconds}});
    return;
  }
  if (state == ClaimState::dismissed) {
    std::filesystem::remove_all(dir, ec);  // dismissed while finishing
    log_transition(job.id, JobStatus::dismissed, {{"seconds", seconds}});
    return;
  }
  metrics_.observe_job(seconds, outcome);
  nlohmann::ordered_json extra{{"seconds", seconds}, {"files", files.size()}};
  if (!reason.empty()) extra["reason"] = reason;
  log_transition(job.id, outcome, std::move(extra));
}

}  // namespace hmpm::server
