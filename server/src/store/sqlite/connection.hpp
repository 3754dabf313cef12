// connection.hpp — thin RAII over the SQLite C API for the SQLite job store.
//
// A `ConnectionPool` hands each operation a connection of its own
// (`Connection`), returned to the pool afterwards: connections are never
// shared between threads. `Statement` binds positionally (1-based, as in
// SQLite) and throws StoreFailure on any error; `WriteTransaction` is
// `BEGIN IMMEDIATE` ... `COMMIT`, rolled back if left by an exception. Taking
// the write lock up front means two writers never both hold read locks and
// deadlock (the case where SQLite answers SQLITE_BUSY without waiting).
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace hmpm::server::sqlite {

/// Throws StoreFailure with `what` and the connection's last error.
[[noreturn]] void fail(sqlite3* db, const std::string& what);

/// Runs `sql` (any number of statements); throws StoreFailure on error.
void exec(sqlite3* db, const char* sql);

class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, std::string_view v);
  Statement& bind(int i, std::int64_t v);
  Statement& bind(int i, double v);
  /// Binds NULL for an empty string (optional text columns).
  Statement& bind_or_null(int i, std::string_view v);

  /// True when a row is available, false when done; throws on error.
  bool step();
  std::string text(int col) const;
  std::int64_t integer(int col) const;
  double real(int col) const;

 private:
  void check(int rc);
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

class WriteTransaction {
 public:
  explicit WriteTransaction(sqlite3* db);
  ~WriteTransaction();
  WriteTransaction(const WriteTransaction&) = delete;
  WriteTransaction& operator=(const WriteTransaction&) = delete;
  void commit();

 private:
  sqlite3* db_;
  bool done_ = false;
};

class ConnectionPool;

/// A connection leased to the calling thread for one operation.
class Connection {
 public:
  Connection(ConnectionPool& pool, sqlite3* db) : pool_(&pool), db_(db) {}
  ~Connection();
  Connection(Connection&& other) noexcept;
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  Connection& operator=(Connection&&) = delete;
  sqlite3* get() const { return db_; }

 private:
  ConnectionPool* pool_;
  sqlite3* db_;
};

/// Connections to one database file in WAL mode, synchronous=FULL, foreign
/// keys on and a 10 s busy timeout.
class ConnectionPool {
 public:
  explicit ConnectionPool(std::filesystem::path path) : path_(std::move(path)) {}
  ~ConnectionPool();
  ConnectionPool(const ConnectionPool&) = delete;
  ConnectionPool& operator=(const ConnectionPool&) = delete;

  /// An idle connection, or a new one; throws StoreFailure if it cannot open.
  Connection lease();

 private:
  friend class Connection;
  sqlite3* open_connection();
  void release(sqlite3* db);

  std::filesystem::path path_;
  std::mutex mutex_;
  std::vector<sqlite3*> idle_;
};

}  // namespace hmpm::server::sqlite
