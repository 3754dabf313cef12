// connection.cpp — see connection.hpp.
#include "connection.hpp"

#include <sys/resource.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>

#include "hmpm/server/store.hpp"

namespace hmpm::server::sqlite {

namespace {

// The operating system's error behind the last failure of `db`, 0 if it was
// not an I/O failure (SQLite keeps the errno of its last failed system call).
int system_error(sqlite3* db) {
  const int code = db ? sqlite3_errcode(db) : SQLITE_NOMEM;
  return code == SQLITE_IOERR || code == SQLITE_FULL || code == SQLITE_CANTOPEN
             ? sqlite3_system_errno(db)
             : 0;
}

// Whether a file of the database has reached the process's file-size limit
// (RLIMIT_FSIZE), or its file system has less than 1 MiB left.
bool files_at_their_limit(sqlite3* db) {
  const char* name = sqlite3_db_filename(db, "main");
  if (!name || !*name) return false;
  const std::filesystem::path path(name);
  std::error_code ec;
  const auto space = std::filesystem::space(path.parent_path(), ec);
  if (!ec && space.available < (std::uintmax_t{1} << 20)) return true;
  rlimit limit{};
  if (::getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return false;
  for (const std::string suffix : {"", "-wal", "-shm"}) {
    const auto size = std::filesystem::file_size(path.string() + suffix, ec);
    if (!ec && size >= limit.rlim_cur) return true;
  }
  return false;
}

// Whether the last failure of `db` was for want of space: SQLITE_FULL, or an
// I/O error from a full disk, a quota or a file-size limit. SQLite's errno
// of an I/O error is not always the write's, so the files are looked at too.
bool out_of_space(sqlite3* db) {
  if (!db) return false;
  const int error = system_error(db);
  return sqlite3_errcode(db) == SQLITE_FULL || error == ENOSPC || error == EFBIG ||
         error == EDQUOT || (sqlite3_errcode(db) == SQLITE_IOERR && files_at_their_limit(db));
}

}  // namespace

void fail(sqlite3* db, const std::string& what) {
  std::string message = what + ": " + (db ? sqlite3_errmsg(db) : "out of memory");
  if (const int error = system_error(db)) message += std::string(" (") + std::strerror(error) + ")";
  throw StoreFailure(message, out_of_space(db));
}

void exec(sqlite3* db, const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    throw StoreFailure(std::string("sqlite: ") + message, out_of_space(db));
  }
}

Statement::Statement(sqlite3* db, std::string_view sql) : db_(db) {
  if (sqlite3_prepare_v2(db, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr) !=
      SQLITE_OK) {
    fail(db, "prepare");
  }
}

Statement::~Statement() {
  sqlite3_finalize(stmt_);
}

Statement& Statement::bind(int i, std::string_view v) {
  check(sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
  return *this;
}

Statement& Statement::bind(int i, std::int64_t v) {
  check(sqlite3_bind_int64(stmt_, i, v));
  return *this;
}

Statement& Statement::bind(int i, double v) {
  check(sqlite3_bind_double(stmt_, i, v));
  return *this;
}

Statement& Statement::bind_or_null(int i, std::string_view v) {
  if (v.empty()) {
    check(sqlite3_bind_null(stmt_, i));
    return *this;
  }
  return bind(i, v);
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  fail(db_, "step");
}

std::string Statement::text(int col) const {
  const auto* p = sqlite3_column_text(stmt_, col);
  return p ? std::string(reinterpret_cast<const char*>(p),
                         static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
           : std::string();
}

std::int64_t Statement::integer(int col) const {
  return sqlite3_column_int64(stmt_, col);
}

double Statement::real(int col) const {
  return sqlite3_column_double(stmt_, col);
}

void Statement::check(int rc) {
  if (rc != SQLITE_OK) fail(db_, "bind");
}

WriteTransaction::WriteTransaction(sqlite3* db) : db_(db) {
  exec(db_, "BEGIN IMMEDIATE");
}

WriteTransaction::~WriteTransaction() {
  if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
}

void WriteTransaction::commit() {
  exec(db_, "COMMIT");
  done_ = true;
}

Connection::~Connection() {
  if (db_) pool_->release(db_);
}

Connection::Connection(Connection&& other) noexcept
    : pool_(other.pool_), db_(std::exchange(other.db_, nullptr)) {}

ConnectionPool::~ConnectionPool() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (sqlite3* db : idle_) sqlite3_close(db);
  idle_.clear();
}

sqlite3* ConnectionPool::open_connection() {
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

Connection ConnectionPool::lease() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!idle_.empty()) {
      sqlite3* db = idle_.back();
      idle_.pop_back();
      return Connection(*this, db);
    }
  }
  return Connection(*this, open_connection());
}

void ConnectionPool::release(sqlite3* db) {
  std::lock_guard<std::mutex> lock(mutex_);
  idle_.push_back(db);
}

}  // namespace hmpm::server::sqlite
