// store.cpp — the SQLite job store; see store.hpp for the contract.
//
// Every write is one `BEGIN IMMEDIATE` transaction: it takes the write lock
// up front, so two writers never both hold read locks and deadlock (the case
// where SQLite returns SQLITE_BUSY without waiting). Readers use plain
// statements; under WAL they never block writers or each other.
#include "hmpm/server/store.hpp"

#include <sqlite3.h>

#include <array>
#include <utility>

#include "clock.hpp"

namespace hmpm::server {
namespace {

constexpr std::array<const char*, 5> status_names{"accepted", "running", "successful", "failed",
                                                  "dismissed"};

// Schema migrations, applied in order; migration i brings user_version to i+1.
// Never edit a released entry: append a new one.
constexpr std::array<const char*, 1> migrations{
    // 1: jobs with their spec and life cycle; result files of finished jobs.
    R"sql(
CREATE TABLE jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  name TEXT NOT NULL,
  spec TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('accepted','running','successful','failed','dismissed')),
  progress REAL NOT NULL DEFAULT 0,
  message TEXT NOT NULL DEFAULT '',
  created TEXT NOT NULL,
  started TEXT,
  finished TEXT,
  updated TEXT NOT NULL,
  attempts INTEGER NOT NULL DEFAULT 0,
  failure_reason TEXT,
  idempotency_key TEXT UNIQUE,
  body_sha256 TEXT,
  cost_particles INTEGER NOT NULL DEFAULT 0,
  cost_nodes INTEGER NOT NULL DEFAULT 0,
  cost_cells INTEGER NOT NULL DEFAULT 0,
  cost_steps INTEGER NOT NULL DEFAULT 0,
  cost_particle_steps INTEGER NOT NULL DEFAULT 0,
  cost_memory_bytes INTEGER NOT NULL DEFAULT 0,
  cost_output_bytes INTEGER NOT NULL DEFAULT 0,
  cost_dt REAL NOT NULL DEFAULT 0,
  run_seconds REAL NOT NULL DEFAULT 0
);
CREATE INDEX jobs_by_status ON jobs (status, seq);
CREATE TABLE results (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  size INTEGER NOT NULL,
  sha256 TEXT NOT NULL,
  media_type TEXT NOT NULL,
  PRIMARY KEY (job_id, name)
);
)sql",
};

[[noreturn]] void fail(sqlite3* db, const std::string& what) {
  throw StoreFailure(what + ": " + (db ? sqlite3_errmsg(db) : "out of memory"));
}

void exec(sqlite3* db, const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    throw StoreFailure(std::string("sqlite: ") + message);
  }
}

// A prepared statement with positional binding (1-based, as in SQLite).
class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) !=
        SQLITE_OK) {
      fail(db, "prepare");
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, std::string_view v) {
    check(sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int i, std::int64_t v) {
    check(sqlite3_bind_int64(stmt_, i, v));
    return *this;
  }
  Statement& bind(int i, double v) {
    check(sqlite3_bind_double(stmt_, i, v));
    return *this;
  }
  /// Binds NULL for an empty string (optional text columns).
  Statement& bind_or_null(int i, std::string_view v) {
    if (v.empty()) {
      check(sqlite3_bind_null(stmt_, i));
      return *this;
    }
    return bind(i, v);
  }

  /// True when a row is available, false when done; throws on error.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(db_, "step");
  }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p),
                           static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
             : std::string();
  }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }

 private:
  void check(int rc) {
    if (rc != SQLITE_OK) fail(db_, "bind");
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

// BEGIN IMMEDIATE ... COMMIT, rolled back if left by an exception.
class WriteTransaction {
 public:
  explicit WriteTransaction(sqlite3* db) : db_(db) { exec(db_, "BEGIN IMMEDIATE"); }
  ~WriteTransaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  WriteTransaction(const WriteTransaction&) = delete;
  WriteTransaction& operator=(const WriteTransaction&) = delete;
  void commit() {
    exec(db_, "COMMIT");
    done_ = true;
  }

 private:
  sqlite3* db_;
  bool done_ = false;
};

constexpr const char* job_columns =
    "id, seq, name, spec, status, progress, message, created, started, finished, updated, "
    "attempts, failure_reason, cost_particles, cost_nodes, cost_cells, cost_steps, "
    "cost_particle_steps, cost_memory_bytes, cost_output_bytes, cost_dt, run_seconds";

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
  return r;
}

std::optional<JobRecord> select_job(sqlite3* db, std::string_view where, std::string_view key) {
  Statement s(db, std::string("SELECT ") + job_columns + " FROM jobs WHERE " + std::string(where));
  s.bind(1, key);
  if (!s.step()) return std::nullopt;
  return read_job(s);
}

}  // namespace

const char* status_name(JobStatus status) {
  return status_names[static_cast<std::size_t>(status)];
}

std::optional<JobStatus> parse_status(std::string_view text) {
  for (std::size_t i = 0; i < status_names.size(); ++i) {
    if (text == status_names[i]) return static_cast<JobStatus>(i);
  }
  return std::nullopt;
}

bool is_terminal(JobStatus status) {
  return status == JobStatus::successful || status == JobStatus::failed ||
         status == JobStatus::dismissed;
}

// A connection leased to the calling thread for one operation.
class JobStore::Lease {
 public:
  Lease(JobStore& store, sqlite3* db) : store_(&store), db_(db) {}
  ~Lease() {
    if (db_) store_->release(db_);
  }
  Lease(Lease&& other) noexcept : store_(other.store_), db_(std::exchange(other.db_, nullptr)) {}
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;
  Lease& operator=(Lease&&) = delete;
  sqlite3* get() const { return db_; }

 private:
  JobStore* store_;
  sqlite3* db_;
};

JobStore::JobStore(const std::filesystem::path& db_path) : path_(db_path) {
  try {
    migrate();
  } catch (...) {
    close_idle();  // the destructor will not run
    throw;
  }
}

void JobStore::migrate() {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  int version = 0;
  {
    Statement s(db, "PRAGMA user_version");
    if (s.step()) version = static_cast<int>(s.integer(0));
  }
  if (version > current_schema_version()) {
    throw StoreFailure("database schema version " + std::to_string(version) +
                       " is newer than this server's " + std::to_string(current_schema_version()));
  }
  for (int v = version; v < current_schema_version(); ++v)
    exec(db, migrations[static_cast<std::size_t>(v)]);
  exec(db, ("PRAGMA user_version = " + std::to_string(current_schema_version())).c_str());
  tx.commit();
}

void JobStore::close_idle() {
  std::lock_guard<std::mutex> lock(pool_mutex_);
  for (sqlite3* db : idle_) sqlite3_close(db);
  idle_.clear();
}

JobStore::~JobStore() {
  close_idle();
}
int JobStore::current_schema_version() {
  return static_cast<int>(migrations.size());
}

sqlite3* JobStore::open_connection() {
  sqlite3* db = nullptr;
  const int rc =
      sqlite3_open_v2(path_.c_str(), &db,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    throw StoreFailure("cannot open database " + path_.string() + ": " + message);
  }
  try {
    sqlite3_busy_timeout(db, 10'000);
    exec(db, "PRAGMA journal_mode = WAL");
    exec(db, "PRAGMA synchronous = FULL");
    exec(db, "PRAGMA foreign_keys = ON");
  } catch (...) {
    sqlite3_close(db);
    throw;
  }
  return db;
}

JobStore::Lease JobStore::lease() {
  {
    std::lock_guard<std::mutex> lock(pool_mutex_);
    if (!idle_.empty()) {
      sqlite3* db = idle_.back();
      idle_.pop_back();
      return Lease(*this, db);
    }
  }
  return Lease(*this, open_connection());
}

void JobStore::release(sqlite3* db) {
  std::lock_guard<std::mutex> lock(pool_mutex_);
  idle_.push_back(db);
}

int JobStore::schema_version() {
  auto db = lease();
  Statement s(db.get(), "PRAGMA user_version");
  return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

SubmitResult JobStore::submit(const NewJob& job, std::int64_t max_queue) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  if (!job.idempotency_key.empty()) {
    Statement s(db, "SELECT id, body_sha256 FROM jobs WHERE idempotency_key = ?1");
    s.bind(1, job.idempotency_key);
    if (s.step()) {
      const std::string earlier_id = s.text(0);
      const bool same_body = s.text(1) == job.body_sha256;
      auto earlier = select_job(db, "id = ?1", earlier_id);
      tx.commit();
      return {same_body ? SubmitOutcome::replayed : SubmitOutcome::key_conflict,
              std::move(*earlier)};
    }
  }
  {
    Statement s(db, "SELECT count(*) FROM jobs WHERE status = 'accepted'");
    if (s.step() && s.integer(0) >= max_queue) return {SubmitOutcome::queue_full, {}};
  }
  const std::string now = now_rfc3339();
  Statement s(
      db,
      "INSERT INTO jobs (id, name, spec, status, message, created, updated, idempotency_key, "
      "body_sha256, cost_particles, cost_nodes, cost_cells, cost_steps, cost_particle_steps, "
      "cost_memory_bytes, cost_output_bytes, cost_dt) VALUES (?1, ?2, ?3, 'accepted', "
      "'queued', ?4, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14)");
  s.bind(1, job.id).bind(2, job.name).bind(3, job.spec).bind(4, now);
  s.bind_or_null(5, job.idempotency_key).bind_or_null(6, job.body_sha256);
  s.bind(7, job.cost.particles).bind(8, job.cost.nodes).bind(9, job.cost.cells);
  s.bind(10, job.cost.steps).bind(11, job.cost.particle_steps).bind(12, job.cost.memory_bytes);
  s.bind(13, job.cost.output_bytes).bind(14, job.cost.dt);
  s.step();
  auto created = select_job(db, "id = ?1", job.id);
  tx.commit();
  return {SubmitOutcome::created, std::move(*created)};
}

std::optional<JobRecord> JobStore::find(const std::string& id) {
  auto db = lease();
  return select_job(db.get(), "id = ?1", id);
}

std::vector<JobRecord> JobStore::list(const std::vector<JobStatus>& statuses, int limit) {
  std::string sql = std::string("SELECT ") + job_columns + " FROM jobs";
  if (!statuses.empty()) {
    sql += " WHERE status IN (";
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      sql += (i ? ",'" : "'") + std::string(status_name(statuses[i])) + "'";
    }
    sql += ")";
  }
  sql += " ORDER BY seq DESC LIMIT ?1";
  auto db = lease();
  Statement s(db.get(), sql);
  s.bind(1, static_cast<std::int64_t>(limit));
  std::vector<JobRecord> out;
  while (s.step()) out.push_back(read_job(s));
  return out;
}

std::optional<JobRecord> JobStore::claim_next() {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  std::string id;
  {
    Statement s(db, "SELECT id FROM jobs WHERE status = 'accepted' ORDER BY seq LIMIT 1");
    if (!s.step()) return std::nullopt;
    id = s.text(0);
  }
  const std::string now = now_rfc3339();
  Statement s(
      db,
      "UPDATE jobs SET status = 'running', progress = 0, message = 'running', started = ?1, "
      "finished = NULL, updated = ?1, attempts = attempts + 1 WHERE id = ?2");
  s.bind(1, now).bind(2, id);
  s.step();
  auto job = select_job(db, "id = ?1", id);
  tx.commit();
  return job;
}

bool JobStore::update_progress(const std::string& id, double percent) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  Statement s(db,
              "UPDATE jobs SET progress = ?1, updated = ?2 WHERE id = ?3 AND status = 'running'");
  s.bind(1, percent).bind(2, now_rfc3339()).bind(3, id);
  s.step();
  const bool running = sqlite3_changes(db) == 1;
  tx.commit();
  return running;
}

bool JobStore::finish(const std::string& id, JobStatus status, const std::string& message,
                      const std::string& failure_reason, const std::vector<ResultFile>& files,
                      double run_seconds) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  const std::string now = now_rfc3339();
  {
    Statement s(db,
                "UPDATE jobs SET status = ?1, message = ?2, failure_reason = ?3, finished = ?4, "
                "updated = ?4, run_seconds = ?5, progress = CASE WHEN ?1 = 'successful' THEN 100 "
                "ELSE progress END WHERE id = ?6 AND status = 'running'");
    s.bind(1, status_name(status)).bind(2, message).bind_or_null(3, failure_reason).bind(4, now);
    s.bind(5, run_seconds).bind(6, id);
    s.step();
    if (sqlite3_changes(db) != 1) return false;
  }
  {
    Statement clear(db, "DELETE FROM results WHERE job_id = ?1");
    clear.bind(1, id);
    clear.step();
  }
  for (const ResultFile& f : files) {
    Statement s(
        db,
        "INSERT INTO results (job_id, name, size, sha256, media_type) VALUES (?1, ?2, ?3, ?4, ?5)");
    s.bind(1, id).bind(2, f.name).bind(3, f.size).bind(4, f.sha256).bind(5, f.media_type);
    s.step();
  }
  tx.commit();
  return true;
}

bool JobStore::requeue(const std::string& id) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  Statement s(db,
              "UPDATE jobs SET status = 'accepted', progress = 0, started = NULL, "
              "message = 'queued again: the server stopped while it ran', updated = ?1, "
              "attempts = max(attempts - 1, 0) WHERE id = ?2 AND status = 'running'");
  s.bind(1, now_rfc3339()).bind(2, id);
  s.step();
  const bool done = sqlite3_changes(db) == 1;
  tx.commit();
  return done;
}

std::optional<JobRecord> JobStore::dismiss(const std::string& id) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  auto before = select_job(db, "id = ?1", id);
  if (!before || before->status == JobStatus::dismissed) return before;
  {
    Statement s(db,
                "UPDATE jobs SET status = 'dismissed', message = 'dismissed by the client', "
                "finished = coalesce(finished, ?1), updated = ?1 WHERE id = ?2");
    s.bind(1, now_rfc3339()).bind(2, id);
    s.step();
  }
  Statement clear(db, "DELETE FROM results WHERE job_id = ?1");
  clear.bind(1, id);
  clear.step();
  tx.commit();
  return before;
}

std::vector<ResultFile> JobStore::results(const std::string& id) {
  auto db = lease();
  Statement s(db.get(),
              "SELECT name, size, sha256, media_type FROM results WHERE job_id = ?1 ORDER BY name");
  s.bind(1, id);
  std::vector<ResultFile> out;
  while (s.step()) out.push_back({s.text(0), s.integer(1), s.text(2), s.text(3)});
  return out;
}

RecoveryReport JobStore::recover(int max_attempts) {
  auto connection = lease();
  sqlite3* db = connection.get();
  WriteTransaction tx(db);
  std::vector<std::pair<std::string, int>> interrupted;
  {
    Statement s(db, "SELECT id, attempts FROM jobs WHERE status = 'running' ORDER BY seq");
    while (s.step()) interrupted.emplace_back(s.text(0), static_cast<int>(s.integer(1)));
  }
  RecoveryReport report;
  const std::string now = now_rfc3339();
  for (const auto& [id, attempts] : interrupted) {
    if (attempts < max_attempts) {
      Statement s(
          db,
          "UPDATE jobs SET status = 'accepted', progress = 0, started = NULL, updated = ?1, "
          "message = 'queued again: the server stopped while it ran' WHERE id = ?2");
      s.bind(1, now).bind(2, id);
      s.step();
      report.requeued.push_back(id);
    } else {
      const std::string reason = "the server stopped while this job ran, " +
                                 std::to_string(attempts) + " times (limit " +
                                 std::to_string(max_attempts) + " attempts); not retried";
      Statement s(db,
                  "UPDATE jobs SET status = 'failed', message = ?1, failure_reason = ?1, "
                  "finished = ?2, updated = ?2 WHERE id = ?3");
      s.bind(1, reason).bind(2, now).bind(3, id);
      s.step();
      report.failed.push_back(id);
    }
  }
  tx.commit();
  return report;
}

StatusCounts JobStore::count_by_status() {
  auto db = lease();
  Statement s(db.get(), "SELECT status, count(*) FROM jobs GROUP BY status");
  StatusCounts counts;
  while (s.step()) {
    if (auto status = parse_status(s.text(0))) counts[*status] = s.integer(1);
  }
  return counts;
}

}  // namespace hmpm::server
