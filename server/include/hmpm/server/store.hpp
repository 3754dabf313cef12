// store.hpp — the durable job queue: every job and its result files in SQLite.
//
// The database is the single source of truth for the service: the HTTP
// handlers, the workers and a restarted server all read the same rows, so a
// `201 Created` means the job is on disk (WAL, synchronous=FULL) before the
// client hears about it. Writes run in `BEGIN IMMEDIATE` transactions with a
// busy timeout, so concurrent writers queue instead of failing with
// SQLITE_BUSY. Connections are never shared between threads: each operation
// leases one from a small pool for the calling thread and returns it after.
// The schema is versioned with `PRAGMA user_version` and migrated on open.
//
// Domain outcomes (unknown job, queue full, idempotency conflict) are values;
// only a failing database (disk full, corrupt file, newer schema) throws
// StoreFailure, which the HTTP edge turns into a 500.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

struct sqlite3;

namespace hmpm::server {

/// The contract's job states (OGC API – Processes status codes).
enum class JobStatus { accepted, running, successful, failed, dismissed };

/// "accepted", "running", ...
const char* status_name(JobStatus status);
/// Inverse of status_name; nullopt for anything else.
std::optional<JobStatus> parse_status(std::string_view text);
/// successful, failed and dismissed never change again (except dismissal).
bool is_terminal(JobStatus status);

/// A database failure the service cannot recover from by itself.
class StoreFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
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

/// One row of the jobs table. Timestamps are RFC 3339 UTC; empty = not yet.
struct JobRecord {
  std::string id;
  std::int64_t seq = 0;  ///< submission order (FIFO key)
  std::string name;
  std::string spec;
  JobStatus status = JobStatus::accepted;
  double progress = 0.0;  ///< percent, 0..100
  std::string message;
  std::string created;
  std::string started;
  std::string finished;
  std::string updated;
  int attempts = 0;  ///< how many times a worker started this job
  std::string failure_reason;
  JobCost cost;
  double run_seconds = 0.0;  ///< wall time of the last attempt's run_job
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

/// What start-up recovery did with jobs an earlier process left `running`.
struct RecoveryReport {
  std::vector<std::string> requeued;
  std::vector<std::string> failed;
};

/// Job count per status plus figures for /metrics.
using StatusCounts = std::map<JobStatus, std::int64_t>;

class JobStore {
 public:
  /// Opens (creating if needed) the database at `db_path` and migrates it to
  /// the current schema. Throws StoreFailure when the file cannot be opened
  /// or its schema is newer than this build knows.
  explicit JobStore(const std::filesystem::path& db_path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  /// Schema version this build migrates to.
  static int current_schema_version();
  /// Schema version recorded in the file (PRAGMA user_version).
  int schema_version();

  /// Stores a new accepted job unless the queue holds `max_queue` accepted
  /// jobs already, or `job.idempotency_key` was used before (then the earlier
  /// job comes back as replayed or key_conflict). Atomic.
  SubmitResult submit(const NewJob& job, std::int64_t max_queue);

  std::optional<JobRecord> find(const std::string& id);

  /// Newest first; `statuses` empty means all.
  std::vector<JobRecord> list(const std::vector<JobStatus>& statuses, int limit);

  /// Takes the oldest accepted job: status running, attempts + 1, started now.
  std::optional<JobRecord> claim_next();

  /// Sets the progress (percent) of a running job. Returns false when the job
  /// is no longer running (dismissed meanwhile), so the worker can stop.
  bool update_progress(const std::string& id, double percent);

  /// Ends a running job as successful or failed with its result files.
  /// Returns false (and records nothing) when the job is no longer running.
  bool finish(const std::string& id, JobStatus status, const std::string& message,
              const std::string& failure_reason, const std::vector<ResultFile>& files,
              double run_seconds);

  /// Puts a running job back in the queue (graceful shutdown). The attempt
  /// is not counted: the job did nothing wrong.
  bool requeue(const std::string& id);

  /// Dismisses a job in any state and forgets its result files. Returns the
  /// row as it was before (nullopt for an unknown id); already dismissed
  /// jobs stay as they are.
  std::optional<JobRecord> dismiss(const std::string& id);

  std::vector<ResultFile> results(const std::string& id);

  /// Start-up recovery: every job left `running` by a process that died goes
  /// back to `accepted` while attempts < max_attempts, else to `failed` with
  /// the reason. Call before any worker starts.
  RecoveryReport recover(int max_attempts);

  StatusCounts count_by_status();

 private:
  class Lease;
  Lease lease();
  void migrate();
  void close_idle();
  sqlite3* open_connection();
  void release(sqlite3* db);

  std::filesystem::path path_;
  std::mutex pool_mutex_;
  std::vector<sqlite3*> idle_;
};

}  // namespace hmpm::server
