// workers/pool.hpp — the threads that run jobs, one job per worker at a time.
//
// Workers take the oldest accepted job from the store (FIFO), re-parse its
// stored spec (the database stays the only source of truth), run it with
// hmpm::api::run_job into `<data-dir>/<job id>/attempt-<fencing token>/`,
// record the result files with size and SHA-256, and write the outcome.
// Result files are fenced like every other write: each claim writes only
// into its own attempt folder, and the files served are those of the claim
// whose fenced finish() (or keep_results()) was recorded, whose token the
// job row keeps. A paused-then-revived server whose claim was taken over
// can fill its own folder, never the one being served. The job's log
// (`<data-dir>/<job id>/job.log`) spans all attempts. HTTP handlers never run
// solver work; they only nudge the pool (`notify`) or ask it to cancel.
//
// Cancellation is cooperative: each running job has an atomic flag the solver
// checks once per step. A client's cancel or DELETE dismisses the job (the
// store says whether its files stay: keep_results); a shutdown puts it back
// in the queue so the next start resumes it. Each job's log (run_log.hpp) is
// written here.
//
// The pool (workers/pool.cpp) claims jobs, renews leases and runs recovery;
// one attempt at a job, from its folder's preparation to the end written to
// the store, is workers/attempt.cpp; the job's folder is job_files.hpp.
//
// Every job is claimed for this process's instance (`WorkerSettings::claimant`);
// a heartbeat thread renews the leases of the running jobs every
// `lease_renewal_s`, and a worker whose claim was lost stops without touching
// the job's files (another instance owns them now). The same heartbeat runs
// recovery (JobStore::recover), so the jobs of a server that died while
// others share its database are taken over once their lease lapses, not
// only when a server starts.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/server/store.hpp"
#include "job_files.hpp"
#include "metrics.hpp"

namespace hmpm::server {

struct WorkerSettings {
  int workers = 1;
  int threads_per_job = 1;
  double wall_time_limit_s = 0.0;    ///< <= 0: none
  double progress_interval_s = 1.0;  ///< how often progress reaches the store
  std::filesystem::path data_dir;
  hmpm::api::Limits limits;
  Claimant claimant;              ///< this process's instance id and lease length
  double lease_renewal_s = 10.0;  ///< heartbeat period; well under claimant.lease_s
  /// Wall time between checkpoints of a running job (its solver state, from
  /// which a later attempt resumes); <= 0: none.
  double checkpoint_interval_s = 60.0;
  int max_attempts = 3;          ///< recover(): starts of a job before it fails
  double charge_after_s = 30.0;  ///< recover(): see ServiceConfig::charge_after_s
};

/// What a worker and the threads that stop it share about a running job.
struct RunningJob {
  std::atomic<bool> cancel{false};
  std::atomic<bool> dismissed{false};
  std::atomic<bool> lost{false};  ///< another claim replaced ours
};

/// One log line per job that recovery requeued or failed.
void log_recovery(const RecoveryReport& recovery);

class WorkerPool {
 public:
  WorkerPool(JobStore& store, Metrics& metrics, WorkerSettings settings);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  void start();
  /// Wakes an idle worker: a job was queued.
  void notify();
  /// Asks the worker running `id` to stop; its job stays dismissed. Waits up
  /// to `wait_s` for the worker to let go of the job (its files recorded or
  /// removed). Returns whether a worker of this process was running it.
  bool cancel(const std::string& id, double wait_s = 0.0);
  /// Stops taking jobs and asks the running ones to stop; each worker puts
  /// its job back in the queue and ends. Returns at once. Idempotent.
  void stop_claiming();
  /// stop_claiming(), then joins the threads. Idempotent.
  void shutdown();

  /// The job folders the workers write (settings' data_dir).
  const JobFiles& files() const { return files_; }

 private:
  void work();
  void heartbeat();
  // One attempt at `job` (workers/attempt.cpp).
  void run_one(const JobRecord& job, RunningJob& running);
  // A write of `claim` was refused: another claim replaced ours (counted,
  // logged); then discard_if_ended.
  void claim_lost(const Claim& claim, double seconds);
  // Removes the attempt folder of `claim` once its job has ended under
  // another claim (nobody resumes from it or serves it any more).
  void discard_if_ended(const Claim& claim);
  // The end of a dismissed run: keeps the files it `written` if the job was
  // cancelled, removes them if it was deleted (the store decides).
  void end_dismissed(const JobRecord& job, const Claim& claim,
                     const std::vector<std::string>& written, double seconds);
  // A write that ends a job's attempt (finish, requeue, keep_results): a
  // StoreFailure (disk full, I/O error) is logged and the write retried after
  // first_retry_s, doubling up to last_retry_s, until it succeeds or the pool
  // stops (then the failure is rethrown and start-up recovery deals with it).
  ClaimState with_retries(const std::string& id, const char* during,
                          const std::function<ClaimState()>& write);
  static constexpr double first_retry_s = 0.1;
  static constexpr double last_retry_s = 5.0;

  JobStore& store_;
  Metrics& metrics_;
  WorkerSettings settings_;
  JobFiles files_;
  std::mutex mutex_;
  std::condition_variable wake_;            ///< workers: a job was queued, or stop
  std::condition_variable heartbeat_wake_;  ///< the heartbeat thread: stop
  std::condition_variable job_done_;        ///< a worker let go of a job
  std::condition_variable retry_wake_;      ///< a worker retrying a store write: stop
  bool stopping_ = false;
  std::uint64_t generation_ = 0;  ///< bumped by notify()
  std::map<std::string, std::shared_ptr<RunningJob>> running_;
  std::vector<std::thread> threads_;
  std::thread heartbeat_;
};

}  // namespace hmpm::server
