// workers/pool.cpp — see workers/pool.hpp.
#include "workers/pool.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include "job_log.hpp"

namespace hmpm::server {

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

WorkerPool::WorkerPool(JobStore& store, Metrics& metrics, WorkerSettings settings)
    : store_(store),
      metrics_(metrics),
      settings_(std::move(settings)),
      files_(settings_.data_dir) {}

WorkerPool::~WorkerPool() {
  shutdown();
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
      const RecoveryReport report =
          store_.recover(settings_.max_attempts, settings_.charge_after_s);
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

void WorkerPool::stop_claiming() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [id, running] : running_) running->cancel = true;
  }
  wake_.notify_all();
  heartbeat_wake_.notify_all();
  retry_wake_.notify_all();
}

ClaimState WorkerPool::with_retries(const std::string& id, const char* during,
                                    const std::function<ClaimState()>& write) {
  double wait_s = first_retry_s;
  for (int attempt = 1;; ++attempt) {
    try {
      return write();
    } catch (const StoreFailure& e) {
      std::unique_lock<std::mutex> lock(mutex_);
      log_line({{"event", "store_error"},
                {"job", id},
                {"during", during},
                {"attempt", attempt},
                {"detail", e.what()},
                {"retry_in_s", stopping_ ? 0.0 : wait_s}});
      if (stopping_) throw;  // the job stays running; recovery at the next start requeues it
      retry_wake_.wait_for(lock, std::chrono::duration<double>(wait_s), [&] { return stopping_; });
      wait_s = std::min(2 * wait_s, last_retry_s);
    }
  }
}

void WorkerPool::shutdown() {
  stop_claiming();
  std::vector<std::thread> threads;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    threads.swap(threads_);
    if (heartbeat_.joinable()) threads.push_back(std::move(heartbeat_));
  }
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
    auto running = std::make_shared<RunningJob>();
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

}  // namespace hmpm::server
