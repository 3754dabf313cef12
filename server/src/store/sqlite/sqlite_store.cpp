// sqlite_store.cpp — see sqlite_store.hpp; the contract is in store.hpp.
//
// Status names in SQL come from the job-status table (`sql_name`), never
// from literals. Every write on behalf of a running job matches its claim
// (owner and fencing token); when it matches nothing, `claim_state` tells
// dismissal from a lost claim.
#include "sqlite_store.hpp"

#include <chrono>
#include <cstdio>
#include <utility>

#include "clock.hpp"
#include "migrate.hpp"
#include "store/recovery.hpp"

namespace hmpm::server::sqlite {
namespace {

// 'running', quoted for SQL.
std::string sql_name(JobStatus status) {
  return std::string("'") + status_name(status) + "'";
}

// Forgets what an earlier attempt's run reached (part of an UPDATE's SET).
constexpr const char* no_run =
    "run_time = 0, run_end_time = 0, run_steps = 0, run_dt_min = 0, run_dt_max = 0, ";

// The last column is an accepted job's place in the queue (1: next).
const std::string job_columns =
    "id, seq, name, spec, status, progress, message, created, started, finished, updated, "
    "attempts, failure_reason, cost_particles, cost_nodes, cost_cells, cost_steps, "
    "cost_particle_steps, cost_memory_bytes, cost_output_bytes, cost_dt, run_seconds, "
    "coalesce(owner, ''), lease_token, lease_expires_ms, results_deleted, run_time, "
    "run_end_time, run_steps, run_dt_min, run_dt_max, coalesce(ensemble_id, ''), "
    "ensemble_index, CASE WHEN status = " +
    sql_name(JobStatus::accepted) +
    " THEN 1 + (SELECT count(*) FROM jobs AS ahead WHERE ahead.status = " +
    sql_name(JobStatus::accepted) + " AND ahead.seq < jobs.seq) ELSE 0 END";

JobRecord read_job(const Statement& s) {
  JobRecord r;
  r.id = s.text(0);
  r.seq = s.integer(1);
  r.name = s.text(2);
  r.spec = s.text(3);
  r.status = parse_status(s.text(4)).value_or(JobStatus::failed);
  r.progress = s.real(5);
  r.message = s.text(6);
  r.created = s.text(7);
  r.started = s.text(8);
  r.finished = s.text(9);
  r.updated = s.text(10);
  r.attempts = static_cast<int>(s.integer(11));
  r.failure_reason = s.text(12);
  r.cost.particles = s.integer(13);
  r.cost.nodes = s.integer(14);
  r.cost.cells = s.integer(15);
  r.cost.steps = s.integer(16);
  r.cost.particle_steps = s.integer(17);
  r.cost.memory_bytes = s.integer(18);
  r.cost.output_bytes = s.integer(19);
  r.cost.dt = s.real(20);
  r.run_seconds = s.real(21);
  r.owner = s.text(22);
  r.lease_token = s.integer(23);
  r.lease_expires_ms = s.integer(24);
  r.results_deleted = s.integer(25) != 0;
  r.run.percent = r.progress;
  r.run.time = s.real(26);
  r.run.end_time = s.real(27);
  r.run.steps = s.integer(28);
  r.run.dt_min = s.real(29);
  r.run.dt_max = s.real(30);
  r.ensemble_id = s.text(31);
  r.ensemble_index = static_cast<int>(s.integer(32));
  r.queue_position = s.integer(33);
  return r;
}

std::optional<JobRecord> select_job(sqlite3* db, std::string_view key) {
  Statement s(db, "SELECT " + job_columns + " FROM jobs WHERE id = ?1");
  s.bind(1, key);
  if (!s.step()) return std::nullopt;
  return read_job(s);
}

// The condition a write of a running job must meet: its claim is current.
const std::string claim_held =
    "id = ?1 AND status = " + sql_name(JobStatus::running) + " AND owner = ?2 AND lease_token = ?3";

void bind_claim(Statement& s, const Claim& claim) {
  s.bind(1, claim.job_id).bind(2, claim.owner).bind(3, claim.token);
}

// Why a claimed write matched no row.
ClaimState claim_state(sqlite3* db, const Claim& claim) {
  const auto job = select_job(db, claim.job_id);
  return job && job->status == JobStatus::dismissed ? ClaimState::dismissed : ClaimState::lost;
}

void clear_results(sqlite3* db, const std::string& id) {
  Statement clear(db, "DELETE FROM results WHERE job_id = ?1");
  clear.bind(1, id);
  clear.step();
}

// A job that ends forgets its checkpoint (the worker removes the file).
void clear_checkpoint(sqlite3* db, const std::string& id) {
  Statement clear(db, "DELETE FROM checkpoints WHERE job_id = ?1");
  clear.bind(1, id);
  clear.step();
}

void insert_results(sqlite3* db, const std::string& id, const std::vector<ResultFile>& files) {
  for (const ResultFile& f : files) {
    Statement s(
        db,
        "INSERT INTO results (job_id, name, size, sha256, media_type) VALUES (?1, ?2, ?3, ?4, ?5)");
    s.bind(1, id).bind(2, f.name).bind(3, f.size).bind(4, f.sha256).bind(5, f.media_type);
    s.step();
  }
}

// Inserts `job` as accepted (sample `index` of ensemble `ensemble` when
// that is not empty), created at `now`.
void insert_job(sqlite3* db, const NewJob& job, const std::string& now,
                const std::string& ensemble = "", int index = -1) {
  Statement s(
      db,
      "INSERT INTO jobs (id, name, spec, status, message, created, updated, idempotency_key, "
      "body_sha256, cost_particles, cost_nodes, cost_cells, cost_steps, cost_particle_steps, "
      "cost_memory_bytes, cost_output_bytes, cost_dt, ensemble_id, ensemble_index) VALUES (?1, "
      "?2, ?3, ?15, 'queued', ?4, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?16, ?17)");
  s.bind(1, job.id).bind(2, job.name).bind(3, job.spec).bind(4, now);
  s.bind_or_null(5, job.idempotency_key).bind_or_null(6, job.body_sha256);
  s.bind(7, job.cost.particles).bind(8, job.cost.nodes).bind(9, job.cost.cells);
  s.bind(10, job.cost.steps).bind(11, job.cost.particle_steps).bind(12, job.cost.memory_bytes);
  s.bind(13, job.cost.output_bytes).bind(14, job.cost.dt);
  s.bind(15, status_name(JobStatus::accepted));
  s.bind_or_null(16, ensemble).bind(17, static_cast<std::int64_t>(index));
  s.step();
}

const char* const ensemble_columns =
    "id, seq, request, seed, samples, state, created, updated FROM ensembles";

EnsembleRecord read_ensemble(const Statement& s) {
  EnsembleRecord e;
  e.id = s.text(0);
  e.seq = s.integer(1);
  e.request = s.text(2);
  e.seed = s.integer(3);
  e.samples = static_cast<int>(s.integer(4));
  e.state = parse_ensemble_state(s.text(5));
  e.created = s.text(6);
  e.updated = s.text(7);
  return e;
}

// Fills e.jobs from the jobs table.
void read_samples(sqlite3* db, EnsembleRecord& e) {
  Statement s(db,
              "SELECT ensemble_index, id, status, progress, attempts, results_deleted FROM jobs "
              "WHERE ensemble_id = ?1 ORDER BY ensemble_index");
  s.bind(1, e.id);
  while (s.step()) {
    e.jobs.push_back({static_cast<int>(s.integer(0)), s.text(1),
                      parse_status(s.text(2)).value_or(JobStatus::failed), s.real(3),
                      static_cast<int>(s.integer(4)), s.integer(5) != 0});
  }
}

std::optional<EnsembleRecord> select_ensemble(sqlite3* db, const std::string& id) {
  Statement s(db, std::string("SELECT ") + ensemble_columns + " WHERE id = ?1");
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  EnsembleRecord e = read_ensemble(s);
  read_samples(db, e);
  return e;
}

}  // namespace

std::filesystem::path lock_path_for(const std::filesystem::path& db_path) {
  return db_path.string() + ".lock";
}

std::chrono::system_clock::time_point SqliteStore::now() const {
  return clock_ ? clock_() : std::chrono::system_clock::now();
}

std::string SqliteStore::now_text() const {
  return format_rfc3339(now());
}

std::int64_t SqliteStore::now_ms() const {
  return std::chrono::duration_cast<std::chrono::milliseconds>(now().time_since_epoch()).count();
}

std::int64_t SqliteStore::lease_until(const Claimant& who) const {
  return now_ms() + static_cast<std::int64_t>(who.lease_s * 1000.0);
}

namespace {

// What to do about a database file that cannot be used as it is.
constexpr const char* damaged_advice =
    "; restore it from a backup, or move it away to start with an empty queue (its jobs are "
    "then lost)";

// A file that exists but is empty would be taken by SQLite for a new
// database: an emptied file (a failed copy, a full disk) must not become an
// empty queue quietly.
void refuse_empty_file(const std::filesystem::path& db_path) {
  std::error_code ec;
  if (std::filesystem::exists(db_path, ec) && std::filesystem::file_size(db_path, ec) == 0 && !ec)
    throw StoreFailure("database " + db_path.string() +
                       " is an empty file (0 bytes), not an hmpm database" + damaged_advice);
}

// PRAGMA quick_check over the whole file (every page, index and row
// format; O(file size), a second or so per hundred MiB).
void check_integrity(sqlite3* db, const std::filesystem::path& db_path) {
  Statement s(db, "PRAGMA quick_check(5)");
  std::string found;
  while (s.step()) {
    const std::string row = s.text(0);
    if (row == "ok") continue;
    found += (found.empty() ? "" : "; ") + row;
  }
  if (!found.empty())
    throw StoreFailure("database " + db_path.string() + " is damaged (integrity check: " + found +
                       ")" + damaged_advice);
}

}  // namespace

SqliteStore::SqliteStore(const std::filesystem::path& db_path, WallClock clock)
    : clock_(std::move(clock)),
      lock_(ProcessLock::hold(lock_path_for(db_path), "database " + db_path.string())),
      pool_(db_path) {
  refuse_empty_file(db_path);
  std::optional<Connection> connection;
  try {
    connection.emplace(pool_.lease());
    check_integrity(connection->get(), db_path);
  } catch (const StoreFailure& e) {
    const std::string what = e.what();
    if (what.rfind("database ", 0) == 0) throw;
    throw StoreFailure("database " + db_path.string() + " cannot be opened (" + what + ")" +
                       damaged_advice);
  }
  sqlite3* db = connection->get();
  migrate(db);
  // The lock is ours, so no other process is running anything: every
  // earlier claim is void and recover() may requeue its job.
  WriteTransaction tx(db);
  exec(db, ("UPDATE jobs SET lease_expires_ms = 0 WHERE status = " + sql_name(JobStatus::running))
               .c_str());
  tx.commit();
}

void SqliteStore::probe() {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  try {
    recorded_version(db);
  } catch (const StoreFailure& e) {
    throw StoreFailure(std::string("the database cannot be read: ") + e.what(), e.no_space());
  }
  // The write: at most once a second (health checks may come far more
  // often); in between, the last write's outcome stands.
  const auto now = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(probe_mutex_);
    if (now - last_write_probe_ < std::chrono::seconds(1)) {
      if (!write_probe_error_.empty()) throw StoreFailure(write_probe_error_, write_probe_full_);
      return;
    }
    last_write_probe_ = now;
  }
  std::string error;
  bool full = false;
  try {
    WriteTransaction tx(db);
    Statement s(db,
                "INSERT INTO store_probe (id, written) VALUES (1, ?1) "
                "ON CONFLICT (id) DO UPDATE SET written = excluded.written");
    s.bind(1, now_text());
    s.step();
    tx.commit();
  } catch (const StoreFailure& e) {
    error = std::string("the database cannot be written: ") + e.what();
    full = e.no_space();
  }
  std::lock_guard<std::mutex> lock(probe_mutex_);
  write_probe_error_ = error;
  write_probe_full_ = full;
  if (!error.empty()) throw StoreFailure(error, full);
}

SubmitResult SqliteStore::submit(const NewJob& job, std::int64_t max_queue) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  if (!job.idempotency_key.empty()) {
    Statement s(db, "SELECT id, body_sha256 FROM jobs WHERE idempotency_key = ?1");
    s.bind(1, job.idempotency_key);
    if (s.step()) {
      const std::string earlier_id = s.text(0);
      const bool same_body = s.text(1) == job.body_sha256;
      auto earlier = select_job(db, earlier_id);
      tx.commit();
      return {same_body ? SubmitOutcome::replayed : SubmitOutcome::key_conflict,
              std::move(*earlier)};
    }
  }
  {
    Statement s(db, "SELECT count(*) FROM jobs WHERE status = " + sql_name(JobStatus::accepted));
    if (s.step() && s.integer(0) >= max_queue) return {SubmitOutcome::queue_full, {}};
  }
  insert_job(db, job, now_text());
  auto created = select_job(db, job.id);
  tx.commit();
  return {SubmitOutcome::created, std::move(*created)};
}

std::optional<JobRecord> SqliteStore::find(const std::string& id) {
  auto db = pool_.lease();
  return select_job(db.get(), id);
}

std::vector<JobRecord> SqliteStore::list(const std::vector<JobStatus>& statuses,
                                         const std::string& name, int limit) {
  std::string sql = "SELECT " + job_columns + " FROM jobs WHERE (?2 = '' OR name = ?2)";
  if (!statuses.empty()) {
    sql += " AND status IN (";
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      if (i > 0) sql += ",";
      sql += sql_name(statuses[i]);
    }
    sql += ")";
  }
  sql += " ORDER BY seq DESC LIMIT ?1";
  auto db = pool_.lease();
  Statement s(db.get(), sql);
  s.bind(1, static_cast<std::int64_t>(limit)).bind(2, name);
  std::vector<JobRecord> out;
  while (s.step()) out.push_back(read_job(s));
  return out;
}

std::vector<std::string> SqliteStore::ids_with_prefix(const std::string& prefix, int limit) {
  auto db = pool_.lease();
  // substr, not LIKE/GLOB: the prefix is matched as text, whatever it holds.
  Statement s(db.get(),
              "SELECT id FROM jobs WHERE substr(id, 1, length(?1)) = ?1 ORDER BY seq LIMIT ?2");
  s.bind(1, prefix).bind(2, static_cast<std::int64_t>(limit));
  std::vector<std::string> out;
  while (s.step()) out.push_back(s.text(0));
  return out;
}

std::optional<JobRecord> SqliteStore::claim_next(const Claimant& who) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  std::string id;
  {
    Statement s(db, "SELECT id FROM jobs WHERE status = " + sql_name(JobStatus::accepted) +
                        " ORDER BY seq LIMIT 1");
    if (!s.step()) return std::nullopt;
    id = s.text(0);
  }
  const std::string now = now_text();
  Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::running) + ", progress = 0, " +
                      no_run +
                      "message = 'running', started = ?1, finished = NULL, "
                      "updated = ?1, attempts = attempts + 1, owner = ?3, "
                      "lease_token = lease_token + 1, lease_expires_ms = ?4, claimed_ms = ?5, "
                      "alive_ms = ?5 WHERE id = ?2");
  s.bind(1, now).bind(2, id).bind(3, who.instance).bind(4, lease_until(who)).bind(5, now_ms());
  s.step();
  auto job = select_job(db, id);
  tx.commit();
  return job;
}

std::int64_t SqliteStore::renew_leases(const Claimant& who) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  Statement s(
      db, "UPDATE jobs SET lease_expires_ms = ?1, alive_ms = ?3 WHERE owner = ?2 AND status = " +
              sql_name(JobStatus::running));
  s.bind(1, lease_until(who)).bind(2, who.instance).bind(3, now_ms());
  s.step();
  const std::int64_t renewed = sqlite3_changes(db);
  tx.commit();
  return renewed;
}

ClaimState SqliteStore::record_progress(const Claim& claim, const RunProgress& run) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  Statement s(db,
              "UPDATE jobs SET progress = ?4, updated = ?5, alive_ms = ?6, run_time = ?7, "
              "run_end_time = ?8, run_steps = ?9, run_dt_min = ?10, run_dt_max = ?11 WHERE " +
                  claim_held);
  bind_claim(s, claim);
  s.bind(4, run.percent).bind(5, now_text()).bind(6, now_ms()).bind(7, run.time);
  s.bind(8, run.end_time).bind(9, run.steps).bind(10, run.dt_min).bind(11, run.dt_max);
  s.step();
  const ClaimState state = sqlite3_changes(db) == 1 ? ClaimState::held : claim_state(db, claim);
  tx.commit();
  return state;
}

ClaimState SqliteStore::finish(const Claim& claim, const JobEnd& end) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  const std::string now = now_text();
  {
    Statement s(db,
                "UPDATE jobs SET status = ?4, message = ?5, failure_reason = ?6, finished = ?7, "
                "updated = ?7, run_seconds = ?8, progress = CASE WHEN ?4 = " +
                    sql_name(JobStatus::successful) +
                    " THEN 100 ELSE progress END, run_time = CASE WHEN ?9 > 0 THEN ?10 ELSE "
                    "run_time END, run_end_time = CASE WHEN ?9 > 0 THEN ?11 ELSE run_end_time "
                    "END, run_steps = CASE WHEN ?9 > 0 THEN ?9 ELSE run_steps END, run_dt_min = "
                    "CASE WHEN ?9 > 0 THEN ?12 ELSE run_dt_min END, run_dt_max = CASE WHEN ?9 > 0 "
                    "THEN ?13 ELSE run_dt_max END WHERE " +
                    claim_held);
    bind_claim(s, claim);
    s.bind(4, status_name(end.status)).bind(5, end.message).bind_or_null(6, end.failure_reason);
    s.bind(7, now).bind(8, end.run_seconds).bind(9, end.run.steps).bind(10, end.run.time);
    s.bind(11, end.run.end_time).bind(12, end.run.dt_min).bind(13, end.run.dt_max);
    s.step();
    if (sqlite3_changes(db) != 1) return claim_state(db, claim);
  }
  clear_results(db, claim.job_id);
  insert_results(db, claim.job_id, end.files);
  clear_checkpoint(db, claim.job_id);
  tx.commit();
  return ClaimState::held;
}

ClaimState SqliteStore::requeue(const Claim& claim) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::accepted) + ", progress = 0, " +
                      no_run +
                      "started = NULL, message = ?5, updated = ?4, "
                      "attempts = max(attempts - 1, 0), lease_expires_ms = 0 WHERE " +
                      claim_held);
  bind_claim(s, claim);
  s.bind(4, now_text()).bind(5, requeued_message);
  s.step();
  const ClaimState state = sqlite3_changes(db) == 1 ? ClaimState::held : claim_state(db, claim);
  tx.commit();
  return state;
}

std::optional<JobRecord> SqliteStore::cancel(const std::string& id) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  auto before = select_job(db, id);
  if (!before || is_terminal(before->status)) return before;
  Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::dismissed) +
                      ", message = 'cancelled by the client', finished = ?1, updated = ?1 "
                      "WHERE id = ?2");
  s.bind(1, now_text()).bind(2, id);
  s.step();
  clear_checkpoint(db, id);
  tx.commit();
  return before;
}

std::optional<JobRecord> SqliteStore::dismiss(const std::string& id) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  auto before = select_job(db, id);
  if (!before || before->results_deleted) return before;
  {
    const bool was_dismissed = before->status == JobStatus::dismissed;
    Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::dismissed) +
                        ", message = ?3, results_deleted = 1, "
                        "finished = coalesce(finished, ?1), updated = ?1 WHERE id = ?2");
    s.bind(1, now_text()).bind(2, id);
    s.bind(3, was_dismissed ? before->message + "; results deleted" : "dismissed by the client");
    s.step();
  }
  clear_results(db, id);
  clear_checkpoint(db, id);
  tx.commit();
  return before;
}

ClaimState SqliteStore::keep_results(const Claim& claim, const std::vector<ResultFile>& files,
                                     double run_seconds) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  const auto job = select_job(db, claim.job_id);
  if (!job || job->owner != claim.owner || job->lease_token != claim.token ||
      job->status != JobStatus::dismissed) {
    return ClaimState::lost;
  }
  if (job->results_deleted) return ClaimState::dismissed;
  {
    Statement s(db, "UPDATE jobs SET run_seconds = ?2, updated = ?3 WHERE id = ?1");
    s.bind(1, claim.job_id).bind(2, run_seconds).bind(3, now_text());
    s.step();
  }
  clear_results(db, claim.job_id);
  insert_results(db, claim.job_id, files);
  tx.commit();
  return ClaimState::held;
}

std::vector<ResultFile> SqliteStore::results(const std::string& id) {
  auto db = pool_.lease();
  Statement s(db.get(),
              "SELECT name, size, sha256, media_type FROM results WHERE job_id = ?1 ORDER BY name");
  s.bind(1, id);
  std::vector<ResultFile> out;
  while (s.step()) out.push_back({s.text(0), s.integer(1), s.text(2), s.text(3)});
  return out;
}

RecoveryReport SqliteStore::recover(int max_attempts, double charge_after_s) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  std::vector<std::pair<std::string, LapsedAttempt>> lapsed;
  {
    Statement s(db,
                "SELECT id, attempts, charged, alive_ms - claimed_ms FROM jobs WHERE status = " +
                    sql_name(JobStatus::running) + " AND lease_expires_ms <= ?1 ORDER BY seq");
    s.bind(1, now_ms());
    while (s.step()) {
      lapsed.emplace_back(s.text(0), LapsedAttempt{s.integer(1), s.integer(2),
                                                   static_cast<double>(s.integer(3)) / 1000.0});
    }
  }
  RecoveryReport report;
  const std::string now = now_text();
  for (const auto& [id, attempt] : lapsed) {
    const auto [charged, reason] = decide_recovery(attempt, max_attempts, charge_after_s);
    if (reason.empty()) {
      Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::accepted) +
                          ", progress = 0, " + no_run +
                          "started = NULL, updated = ?1, charged = ?3, message = ?4 WHERE id = ?2");
      s.bind(1, now).bind(2, id).bind(3, charged).bind(4, requeued_message);
      s.step();
      report.requeued.push_back(id);
    } else {
      Statement s(db, "UPDATE jobs SET status = " + sql_name(JobStatus::failed) +
                          ", message = ?1, failure_reason = ?1, finished = ?2, updated = ?2, "
                          "charged = ?4 WHERE id = ?3");
      s.bind(1, reason).bind(2, now).bind(3, id).bind(4, charged);
      s.step();
      clear_checkpoint(db, id);
      report.failed.push_back(id);
    }
  }
  tx.commit();
  return report;
}

StatusCounts SqliteStore::count_by_status() {
  auto db = pool_.lease();
  Statement s(db.get(), "SELECT status, count(*) FROM jobs GROUP BY status");
  StatusCounts counts;
  while (s.step()) {
    if (auto status = parse_status(s.text(0))) counts[*status] = s.integer(1);
  }
  return counts;
}

std::vector<std::string> SqliteStore::purge_ended(
    std::chrono::system_clock::time_point ended_before) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  // RFC 3339 with fixed-width milliseconds sorts as text, so the cutoff is a
  // string comparison (and the status index narrows the scan).
  const std::string ended = "status IN (" + sql_name(JobStatus::successful) + "," +
                            sql_name(JobStatus::failed) + "," + sql_name(JobStatus::dismissed) +
                            ") AND finished IS NOT NULL AND finished < ?1";
  const std::string cutoff = format_rfc3339(ended_before);
  std::vector<std::string> ids;
  {
    Statement s(db, "SELECT id FROM jobs WHERE " + ended + " ORDER BY seq");
    s.bind(1, cutoff);
    while (s.step()) ids.push_back(s.text(0));
  }
  for (const std::string& id : ids) {
    clear_results(db, id);
    clear_checkpoint(db, id);
  }
  Statement s(db, "DELETE FROM jobs WHERE " + ended);
  s.bind(1, cutoff);
  s.step();
  exec(db,
       "DELETE FROM ensembles WHERE NOT EXISTS (SELECT 1 FROM jobs WHERE jobs.ensemble_id = "
       "ensembles.id)");
  tx.commit();
  return ids;
}

ClaimState SqliteStore::record_checkpoint(const Claim& claim, const CheckpointRecord& checkpoint) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  {
    Statement s(db, "UPDATE jobs SET updated = ?4 WHERE " + claim_held);
    bind_claim(s, claim);
    s.bind(4, now_text());
    s.step();
    if (sqlite3_changes(db) != 1) return claim_state(db, claim);
  }
  Statement s(db,
              "INSERT OR REPLACE INTO checkpoints (job_id, file, step, time, size, sha256, "
              "written) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)");
  s.bind(1, claim.job_id).bind(2, checkpoint.file).bind(3, checkpoint.step);
  s.bind(4, checkpoint.time).bind(5, checkpoint.size).bind(6, checkpoint.sha256);
  s.bind(7, checkpoint.written.empty() ? now_text() : checkpoint.written);
  s.step();
  tx.commit();
  return ClaimState::held;
}

std::optional<CheckpointRecord> SqliteStore::checkpoint(const std::string& id) {
  auto db = pool_.lease();
  Statement s(db.get(),
              "SELECT file, step, time, size, sha256, written FROM checkpoints WHERE job_id = ?1");
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return CheckpointRecord{s.text(0), s.integer(1), s.real(2), s.integer(3), s.text(4), s.text(5)};
}

EnsembleSubmitResult SqliteStore::submit_ensemble(const NewEnsemble& ensemble,
                                                  std::int64_t max_queue) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  if (!ensemble.idempotency_key.empty()) {
    Statement s(db, "SELECT id, body_sha256 FROM ensembles WHERE idempotency_key = ?1");
    s.bind(1, ensemble.idempotency_key);
    if (s.step()) {
      const bool same_body = s.text(1) == ensemble.body_sha256;
      auto earlier = select_ensemble(db, s.text(0));
      tx.commit();
      return {same_body ? SubmitOutcome::replayed : SubmitOutcome::key_conflict,
              std::move(*earlier)};
    }
  }
  {
    Statement s(db, "SELECT count(*) FROM jobs WHERE status = " + sql_name(JobStatus::accepted));
    if (s.step() && s.integer(0) + static_cast<std::int64_t>(ensemble.samples.size()) > max_queue)
      return {SubmitOutcome::queue_full, {}};
  }
  const std::string now = now_text();
  {
    Statement s(db,
                "INSERT INTO ensembles (id, request, seed, samples, created, updated, "
                "idempotency_key, body_sha256) VALUES (?1, ?2, ?3, ?4, ?5, ?5, ?6, ?7)");
    s.bind(1, ensemble.id).bind(2, ensemble.request).bind(3, ensemble.seed);
    s.bind(4, static_cast<std::int64_t>(ensemble.samples.size())).bind(5, now);
    s.bind_or_null(6, ensemble.idempotency_key).bind_or_null(7, ensemble.body_sha256);
    s.step();
  }
  for (std::size_t k = 0; k < ensemble.samples.size(); ++k)
    insert_job(db, ensemble.samples[k], now, ensemble.id, static_cast<int>(k));
  auto created = select_ensemble(db, ensemble.id);
  tx.commit();
  return {SubmitOutcome::created, std::move(*created)};
}

std::optional<EnsembleRecord> SqliteStore::find_ensemble(const std::string& id) {
  auto db = pool_.lease();
  return select_ensemble(db.get(), id);
}

std::vector<EnsembleRecord> SqliteStore::list_ensembles(int limit) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  Statement s(db, std::string("SELECT ") + ensemble_columns + " ORDER BY seq DESC LIMIT ?1");
  s.bind(1, static_cast<std::int64_t>(limit));
  std::vector<EnsembleRecord> out;
  while (s.step()) out.push_back(read_ensemble(s));
  for (EnsembleRecord& e : out) read_samples(db, e);
  return out;
}

std::optional<EnsembleRecord> SqliteStore::set_ensemble_state(const std::string& id,
                                                              EnsembleState state) {
  auto connection = pool_.lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  auto before = select_ensemble(db, id);
  if (!before || before->state == EnsembleState::deleted) return before;
  Statement s(db, "UPDATE ensembles SET state = ?2, updated = ?3 WHERE id = ?1");
  s.bind(1, id).bind(2, ensemble_state_name(state)).bind(3, now_text());
  s.step();
  tx.commit();
  return before;
}

}  // namespace hmpm::server::sqlite

namespace hmpm::server {

std::unique_ptr<JobStore> open_sqlite_store(const std::filesystem::path& db_path, WallClock clock) {
  return std::make_unique<sqlite::SqliteStore>(db_path, std::move(clock));
}

}  // namespace hmpm::server
