// store.hpp — the durable job queue behind an interface, and its records.
//
// The store is the single source of truth for the service: the HTTP
// handlers, the workers and a restarted server all read the same rows, so a
// `201 Created` means the job is durable before the client hears about it.
//
// A running job is *claimed* by one server instance (`Claimant`): the claim
// records the owner, a lease expiry and a fencing token. The owner renews its
// leases with a heartbeat (`renew_leases`); every write on behalf of a
// running job carries its `Claim` and is refused once another claim (a
// takeover after the lease lapsed) or a dismissal has replaced it. Start-up
// recovery only requeues jobs whose lease has lapsed, so it never takes the
// jobs of another live process.
//
// Backends: the SQLite store (`open_sqlite_store`, one process per file,
// server/src/store/sqlite/) and the PostgreSQL store (`open_postgres_store`,
// any number of processes on one database, server/src/store/postgres/).
// Every backend passes the contract suite in tests/server/store_contract.hpp.
//
// Domain outcomes (unknown job, queue full, idempotency conflict, lost claim)
// are values; only a failing database (disk full, corrupt file, newer schema,
// a file another process holds) throws StoreFailure, which the HTTP edge
// turns into 503 or 507 with Retry-After and start-up into exit 1.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hmpm/server/job_status.hpp"

namespace hmpm::server {

/// Where a store reads the wall clock: timestamps, leases, the retention
/// cutoff. Empty means std::chrono::system_clock::now; tests pass their own
/// to age jobs without sleeping.
using WallClock = std::function<std::chrono::system_clock::time_point()>;

/// A database failure the service cannot recover from by itself. `no_space`:
/// the write failed for want of space (disk full, quota, file-size limit),
/// which the HTTP edge answers 507 instead of 503.
class StoreFailure : public std::runtime_error {
 public:
  explicit StoreFailure(const std::string& what, bool no_space = false)
      : std::runtime_error(what), no_space_(no_space) {}
  bool no_space() const { return no_space_; }

 private:
  bool no_space_ = false;
};

/// What parse_job estimated a job will cost, kept for the status document.
struct JobCost {
  std::int64_t particles = 0;
  std::int64_t nodes = 0;
  std::int64_t cells = 0;
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  std::int64_t memory_bytes = 0;
  std::int64_t output_bytes = 0;
  double dt = 0.0;  ///< s
};

/// What a job's run reached, as its worker reports it (zeros until it runs):
/// the solver's own simulated time and end time, the steps taken and the
/// range of the time step. dt_min/dt_max are the smallest and largest mean
/// step over the intervals between progress reports (and over the whole run
/// at the end), so a single cut-back shorter than one report is averaged in.
struct RunProgress {
  double percent = 0.0;    ///< 0..100 of simulated time
  double time = 0.0;       ///< simulated time reached, s
  double end_time = 0.0;   ///< the run's end time, s (0: not known)
  std::int64_t steps = 0;  ///< time steps taken
  double dt_min = 0.0;     ///< s (0: not known)
  double dt_max = 0.0;     ///< s
};

/// One row of the jobs table. Timestamps are RFC 3339 UTC; empty = not yet.
struct JobRecord {
  std::string id;
  std::int64_t seq = 0;  ///< submission order (FIFO key)
  std::string name;
  std::string spec;
  JobStatus status = JobStatus::accepted;
  double progress = 0.0;  ///< percent, 0..100
  RunProgress run;        ///< what the run reached (run.percent == progress)
  /// Accepted jobs: 1 for the next one a worker takes, 2 for the one after…
  /// (0 for any other status).
  std::int64_t queue_position = 0;
  std::string message;
  std::string created;
  std::string started;
  std::string finished;
  std::string updated;
  int attempts = 0;  ///< how many times a worker started this job
  std::string failure_reason;
  JobCost cost;
  double run_seconds = 0.0;  ///< wall time of the last attempt's run_job
  // The claim of the last attempt (meaningful while running).
  std::string owner;                  ///< instance id of the server running it
  std::int64_t lease_token = 0;       ///< fencing token, raised by every claim
  std::int64_t lease_expires_ms = 0;  ///< Unix time in ms; the claim lapses after it
  /// Dismissed by deletion (DELETE): its files are gone. A job dismissed by
  /// cancellation keeps whatever it wrote (false).
  bool results_deleted = false;
  /// A sample of an ensemble: the ensemble's id and the sample's index
  /// (empty and -1 for a job submitted on its own).
  std::string ensemble_id;
  int ensemble_index = -1;
};

/// A result file of a finished job: `<data-dir>/<job id>/<name>`.
struct ResultFile {
  std::string name;
  std::int64_t size = 0;
  std::string sha256;  ///< lowercase hex
  std::string media_type;
};

struct NewJob {
  std::string id;
  std::string name;
  std::string spec;
  JobCost cost;
  std::string idempotency_key;  ///< empty: none
  std::string body_sha256;      ///< hash of the request body, for the key check
};

enum class SubmitOutcome {
  created,       ///< stored; `job` is the new row
  replayed,      ///< same key and body as an earlier submission; `job` is that one
  key_conflict,  ///< same key, different body; `job` is the earlier one
  queue_full,    ///< max_queue jobs already waiting; nothing stored
};

struct SubmitResult {
  SubmitOutcome outcome = SubmitOutcome::created;
  JobRecord job;
};

/// What the client did to an ensemble; its status is derived from its
/// samples' (ensembles/ensemble.hpp).
enum class EnsembleState {
  active,     ///< as submitted
  cancelled,  ///< POST /ensembles/{id}/cancel: its unfinished samples were cancelled
  deleted,    ///< DELETE /ensembles/{id}: its samples were deleted
};

/// A new ensemble (contract v3): its request, and its samples as ordinary
/// jobs, sample k at samples[k].
struct NewEnsemble {
  std::string id;
  std::string request;  ///< the POST /ensembles body as JSON text
  std::int64_t seed = 0;
  std::vector<NewJob> samples;
  std::string idempotency_key;  ///< empty: none
  std::string body_sha256;      ///< hash of the request body, for the key check
};

/// One sample of an ensemble, as the ensemble's documents need it.
struct EnsembleSample {
  int index = 0;
  std::string job_id;
  JobStatus status = JobStatus::accepted;
  double progress = 0.0;  ///< percent
  int attempts = 0;
  bool results_deleted = false;
};

/// One row of the ensembles table with its samples (index order; a sample
/// forgotten by retention is missing).
struct EnsembleRecord {
  std::string id;
  std::int64_t seq = 0;
  std::string request;
  std::int64_t seed = 0;
  int samples = 0;  ///< how many were submitted
  EnsembleState state = EnsembleState::active;
  std::string created;
  std::string updated;
  std::vector<EnsembleSample> jobs;
};

struct EnsembleSubmitResult {
  SubmitOutcome outcome = SubmitOutcome::created;  ///< as for a job
  EnsembleRecord ensemble;
};

/// "active", "cancelled", "deleted" (as stored).
inline const char* ensemble_state_name(EnsembleState state) {
  switch (state) {
    case EnsembleState::cancelled:
      return "cancelled";
    case EnsembleState::deleted:
      return "deleted";
    case EnsembleState::active:
      break;
  }
  return "active";
}

/// Inverse of ensemble_state_name (anything else: active).
inline EnsembleState parse_ensemble_state(std::string_view text) {
  if (text == "cancelled") return EnsembleState::cancelled;
  if (text == "deleted") return EnsembleState::deleted;
  return EnsembleState::active;
}

/// recover(): how many starts, in units of max_attempts, a job may have
/// without a charged crash before it fails anyway.
inline constexpr int uncharged_start_factor = 3;

/// What start-up recovery did with jobs an earlier process left `running`.
struct RecoveryReport {
  std::vector<std::string> requeued;
  std::vector<std::string> failed;
};

/// Job count per status plus figures for /metrics.
using StatusCounts = std::map<JobStatus, std::int64_t>;

/// Who claims jobs: one running server process.
struct Claimant {
  std::string instance;   ///< unique per process (Service makes one at start-up)
  double lease_s = 30.0;  ///< how long a claim holds without renewal
};

/// The right to write on behalf of one running job (from claim_next).
struct Claim {
  std::string job_id;
  std::string owner;
  std::int64_t token = 0;  ///< fencing token of this claim
};

/// The claim a claimed record carries.
inline Claim claim_of(const JobRecord& job) {
  return Claim{job.id, job.owner, job.lease_token};
}

/// What became of a write made with a claim.
enum class ClaimState {
  held,       ///< the claim is current: the write was applied
  dismissed,  ///< the job was dismissed meanwhile: stop and remove its files
  lost,       ///< another claim replaced this one (or the job ended): stop, touch nothing
};

/// The outcome of a finished attempt, as finish() records it.
struct JobEnd {
  JobStatus status = JobStatus::failed;  ///< successful or failed
  std::string message;
  std::string failure_reason;  ///< empty when successful
  std::vector<ResultFile> files;
  double run_seconds = 0.0;
  /// What the run reached (all zeros: keep what the last progress stored).
  RunProgress run;
};

/// A running job's last checkpoint: the solver state after `step`, in
/// `<data-dir>/<job id>/<file>`.
struct CheckpointRecord {
  std::string file;
  std::int64_t step = 0;
  double time = 0.0;  ///< simulated time, s
  std::int64_t size = 0;
  std::string sha256;
  std::string written;  ///< RFC 3339 UTC
};

class JobStore {
 public:
  virtual ~JobStore() = default;

  /// Reads the store and, at most about once a second, writes to it (a
  /// probe for /health); throws StoreFailure if either fails.
  virtual void probe() = 0;

  /// Stores a new accepted job unless the queue holds `max_queue` accepted
  /// jobs already, or `job.idempotency_key` was used before (then the earlier
  /// job comes back as replayed or key_conflict). Atomic.
  virtual SubmitResult submit(const NewJob& job, std::int64_t max_queue) = 0;

  virtual std::optional<JobRecord> find(const std::string& id) = 0;

  /// Newest first; `statuses` empty means all, `name` empty any name.
  virtual std::vector<JobRecord> list(const std::vector<JobStatus>& statuses,
                                      const std::string& name, int limit) = 0;

  /// The ids that start with `prefix` (lowercase hex and '-'), at most
  /// `limit` of them, in submission order.
  virtual std::vector<std::string> ids_with_prefix(const std::string& prefix, int limit) = 0;

  /// Takes the oldest accepted job for `who`: status running, attempts + 1,
  /// started now, owner = who.instance, lease until now + who.lease_s, a new
  /// fencing token. nullopt when nothing waits.
  virtual std::optional<JobRecord> claim_next(const Claimant& who) = 0;

  /// Extends the lease of every job `who` is running to now + who.lease_s.
  /// Returns how many leases were renewed.
  virtual std::int64_t renew_leases(const Claimant& who) = 0;

  /// Sets what a running job's run reached (its progress percent, simulated
  /// time, steps and step range).
  virtual ClaimState record_progress(const Claim& claim, const RunProgress& run) = 0;
  /// Sets the progress (percent) of a running job alone.
  ClaimState update_progress(const Claim& claim, double percent) {
    RunProgress run;
    run.percent = percent;
    return record_progress(claim, run);
  }

  /// Ends a running job as successful or failed with its result files.
  /// Records nothing unless the claim is held.
  virtual ClaimState finish(const Claim& claim, const JobEnd& end) = 0;

  /// Puts a running job back in the queue (graceful shutdown). The attempt
  /// is not counted: the job did nothing wrong.
  virtual ClaimState requeue(const Claim& claim) = 0;

  /// Cancels an accepted or running job: status dismissed, its result files
  /// kept (a running job's worker records them with keep_results). A job that
  /// has ended (successful, failed, dismissed) is left as it is. Returns the
  /// row as it was before; nullopt for an unknown id.
  virtual std::optional<JobRecord> cancel(const std::string& id) = 0;

  /// Dismisses a job in any state and forgets its result files (also those a
  /// cancelled job kept): results_deleted. Returns the row as it was before
  /// (nullopt for an unknown id); a deleted job stays as it is.
  virtual std::optional<JobRecord> dismiss(const std::string& id) = 0;

  /// Records the files a cancelled job wrote before its worker stopped.
  /// held: recorded; dismissed: the job was deleted meanwhile (remove the
  /// files); lost: another claim replaced this one, or the job was not
  /// cancelled (touch nothing).
  virtual ClaimState keep_results(const Claim& claim, const std::vector<ResultFile>& files,
                                  double run_seconds) = 0;

  virtual std::vector<ResultFile> results(const std::string& id) = 0;

  /// Recovery: every running job whose lease has lapsed (its server died)
  /// goes back to `accepted`, or to `failed` with the reason. The crash is
  /// charged to the job only if its attempt had been running for at least
  /// `charge_after_s` (claim to its last lease renewal or progress write):
  /// a job claimed just before an unrelated crash is innocent. A job fails
  /// once max_attempts crashes were charged to it, or, as a backstop against
  /// a job that kills its server within charge_after_s of every start, once
  /// it was started uncharged_start_factor * max_attempts times. Queued jobs
  /// are never charged. Jobs with a live lease are left alone, whoever owns
  /// them.
  virtual RecoveryReport recover(int max_attempts, double charge_after_s) = 0;

  virtual StatusCounts count_by_status() = 0;

  /// Retention: forgets every ended job (successful, failed, dismissed)
  /// whose end (`finished`) is before `ended_before`, with its result-file
  /// rows and idempotency key, and returns the ids in submission order; the
  /// caller removes their folders. Accepted and running jobs are never
  /// purged, however old. A purged id is unknown from then on (find: nullopt).
  /// An ensemble goes with its last sample.
  virtual std::vector<std::string> purge_ended(
      std::chrono::system_clock::time_point ended_before) = 0;

  /// Records the checkpoint a running job just wrote (its file under the
  /// job's data folder, named by the claim's token so a stale writer never
  /// overwrites the current one). held: recorded; dismissed/lost as for
  /// update_progress (the file is then the caller's to remove).
  virtual ClaimState record_checkpoint(const Claim& claim, const CheckpointRecord& checkpoint) = 0;
  /// The job's last recorded checkpoint, if any (cleared when the job ends).
  virtual std::optional<CheckpointRecord> checkpoint(const std::string& id) = 0;

  /// Stores an ensemble and all its samples as accepted jobs in one
  /// transaction: all or nothing, so a crash never leaves half an ensemble.
  /// Refused (queue_full, nothing stored) when the accepted jobs and the
  /// samples together would exceed `max_queue`; an idempotency key used
  /// before gives back that ensemble (replayed or key_conflict) as submit does.
  virtual EnsembleSubmitResult submit_ensemble(const NewEnsemble& ensemble,
                                               std::int64_t max_queue) = 0;
  /// The ensemble with its samples; nullopt for an unknown id.
  virtual std::optional<EnsembleRecord> find_ensemble(const std::string& id) = 0;
  /// Newest first, each with its samples.
  virtual std::vector<EnsembleRecord> list_ensembles(int limit) = 0;
  /// Records what the client did (cancelled, deleted); deleted stays deleted
  /// (a cancel after it changes nothing). Returns the row as it was before;
  /// nullopt for an unknown id. The samples are cancelled or dismissed by
  /// the caller, one by one, with cancel() and dismiss().
  virtual std::optional<EnsembleRecord> set_ensemble_state(const std::string& id,
                                                           EnsembleState state) = 0;
};

/// Opens (creating if needed) the SQLite database at `db_path` for this
/// process alone and migrates it to the current schema. Throws StoreFailure
/// when the file cannot be opened, its schema is newer than this build
/// knows, or another live process holds it (the message names its pid).
/// Holding the file proves that no other process runs any job, so the leases
/// of earlier processes end on open and recover() requeues their jobs.
/// `clock` is the store's time (empty: the system clock).
std::unique_ptr<JobStore> open_sqlite_store(const std::filesystem::path& db_path,
                                            WallClock clock = {});

/// True when `db` names a PostgreSQL database (a libpq URI: postgresql://
/// or postgres://) rather than a SQLite file.
bool is_postgres_uri(std::string_view db);

/// Connects to the PostgreSQL database of the libpq URI `uri` and migrates
/// it to the current schema (concurrent servers migrate one at a time).
/// Any number of processes may share the database: each claims with its own
/// Claimant, and recover() takes only the jobs whose lease has lapsed.
/// Timestamps and leases come from `clock` (empty: the system clock), so
/// the servers' clocks must agree to well under a lease (NTP). Throws
/// StoreFailure when it cannot connect or the schema is newer than this build.
std::unique_ptr<JobStore> open_postgres_store(const std::string& uri, WallClock clock = {});

}  // namespace hmpm::server
