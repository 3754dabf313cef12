// postgres_store.hpp — the JobStore on one PostgreSQL database, shared by
// any number of hmpm-server processes.
//
// Claims take the oldest accepted row with `SELECT ... FOR UPDATE SKIP
// LOCKED`, so concurrent servers never wait on each other's claim and never
// take the same job. Every write on behalf of a running job matches its
// claim (owner and fencing token) in the same statement, so a server whose
// lease lapsed (paused, partitioned) is refused once another one has taken
// the job over. Times come from the store's WallClock (RFC 3339 text and
// Unix-ms leases, as in the SQLite store); there is no process lock: the
// database is meant to be shared.
#pragma once

#include <optional>
#include <string>

#include "connection.hpp"
#include "hmpm/server/store.hpp"

namespace hmpm::server::postgres {

class PostgresStore final : public JobStore {
 public:
  /// See open_postgres_store in store.hpp.
  PostgresStore(const std::string& uri, WallClock clock);

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
  ConnectionPool pool_;
};

}  // namespace hmpm::server::postgres
