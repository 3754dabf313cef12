// sqlite_store.hpp — the JobStore on one SQLite file, for one process.
//
// The embedded default: WAL, synchronous=FULL (a 201 means the row is on
// disk), writes in BEGIN IMMEDIATE transactions with a busy timeout so
// concurrent writers queue instead of failing with SQLITE_BUSY. The file is
// locked for the store's lifetime (`<db>.lock`, see process_lock.hpp): a
// second process on the same file is refused on open, so the leases of every
// earlier process are void and end as soon as the lock is ours.
#pragma once

#include <chrono>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>

#include "connection.hpp"
#include "hmpm/server/store.hpp"
#include "process_lock.hpp"

namespace hmpm::server::sqlite {

class SqliteStore final : public JobStore {
 public:
  /// See open_sqlite_store in store.hpp.
  SqliteStore(const std::filesystem::path& db_path, WallClock clock);

  void probe() override;
  SubmitResult submit(const NewJob& job, std::int64_t max_queue) override;
  std::optional<JobRecord> find(const std::string& id) override;
  std::vector<JobRecord> list(const std::vector<JobStatus>& statuses, const std::string& name,
                              int limit) override;
  std::vector<std::string> ids_with_prefix(const std::string& prefix, int limit) override;
  std::optional<JobRecord> claim_next(const Claimant& who) override;
  std::int64_t renew_leases(const Claimant& who) override;
  ClaimState record_progress(const Claim& claim, const RunProgress& run) override;
  ClaimState finish(const Claim& claim, const JobEnd& end) override;
  ClaimState requeue(const Claim& claim) override;
  std::optional<JobRecord> cancel(const std::string& id) override;
  std::optional<JobRecord> dismiss(const std::string& id) override;
  ClaimState keep_results(const Claim& claim, const std::vector<ResultFile>& files,
                          double run_seconds) override;
  std::vector<ResultFile> results(const std::string& id) override;
  RecoveryReport recover(int max_attempts, double charge_after_s) override;
  StatusCounts count_by_status() override;
  std::vector<std::string> purge_ended(std::chrono::system_clock::time_point ended_before) override;
  ClaimState record_checkpoint(const Claim& claim, const CheckpointRecord& checkpoint) override;
  std::optional<CheckpointRecord> checkpoint(const std::string& id) override;
  EnsembleSubmitResult submit_ensemble(const NewEnsemble& ensemble,
                                       std::int64_t max_queue) override;
  std::optional<EnsembleRecord> find_ensemble(const std::string& id) override;
  std::vector<EnsembleRecord> list_ensembles(int limit) override;
  std::optional<EnsembleRecord> set_ensemble_state(const std::string& id,
                                                   EnsembleState state) override;

 private:
  std::chrono::system_clock::time_point now() const;
  std::string now_text() const;  ///< now() as RFC 3339
  std::int64_t now_ms() const;   ///< now() as Unix ms
  std::int64_t lease_until(const Claimant& who) const;

  WallClock clock_;
  ProcessLock lock_;  ///< taken first, released last
  ConnectionPool pool_;
  // probe(): when the last write probe ran and what it found ("" = written).
  std::mutex probe_mutex_;
  std::chrono::steady_clock::time_point last_write_probe_{};
  std::string write_probe_error_;
  bool write_probe_full_ = false;
};

/// The lock file of the database at `db_path`: `<db_path>.lock`.
std::filesystem::path lock_path_for(const std::filesystem::path& db_path);

}  // namespace hmpm::server::sqlite
