// connection.hpp — thin RAII over libpq for the PostgreSQL job store.
//
// A `ConnectionPool` hands each operation a connection of its own
// (`Connection`), returned to the pool afterwards: a PGconn is never shared
// between threads. A connection the server dropped (a restart, a network
// cut) is reset when it is next leased, so one failed operation is a
// StoreFailure and the next one reconnects. `exec` sends the statement with
// text parameters ($1, $2, ...: never spliced into the SQL) and throws
// StoreFailure on any error; `Transaction` is BEGIN ... COMMIT, rolled back
// if left by an exception.
#pragma once

#include <libpq-fe.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hmpm::server::postgres {

/// Text parameters of one statement, in $1, $2, ... order.
class Params {
 public:
  Params& add(std::string_view v);
  Params& add(std::int64_t v);
  Params& add(double v);
  /// NULL for an empty string (optional text columns).
  Params& add_or_null(std::string_view v);

  int size() const { return static_cast<int>(values_.size()); }
  /// The C strings libpq reads (nullptr for NULL); valid while this lives.
  std::vector<const char*> pointers() const;

 private:
  std::vector<std::string> values_;
  std::vector<bool> null_;
};

/// The rows of one statement; columns by index, as text.
class Result {
 public:
  explicit Result(PGresult* r) : r_(r, PQclear) {}
  int rows() const { return PQntuples(r_.get()); }
  int columns() const { return PQnfields(r_.get()); }
  /// Rows an UPDATE/DELETE/INSERT changed.
  std::int64_t affected() const;
  std::string text(int row, int col) const;
  std::int64_t integer(int row, int col) const;
  double real(int row, int col) const;
  bool boolean(int row, int col) const;
  bool is_null(int row, int col) const { return PQgetisnull(r_.get(), row, col) != 0; }
  ExecStatusType status() const { return PQresultStatus(r_.get()); }
  /// SQLSTATE of a failed statement ("23505": unique violation), "" if none.
  std::string sqlstate() const;

 private:
  std::unique_ptr<PGresult, void (*)(PGresult*)> r_;
};

/// Runs one statement; throws StoreFailure on error.
Result exec(PGconn* db, const std::string& sql, const Params& params = {});

/// Runs `sql` (any number of statements, no parameters: migrations).
void exec_script(PGconn* db, const char* sql);

class Transaction {
 public:
  explicit Transaction(PGconn* db);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  PGconn* db_;
  bool done_ = false;
};

class ConnectionPool;

/// A connection leased to the calling thread for one operation.
class Connection {
 public:
  Connection(ConnectionPool& pool, PGconn* db) : pool_(&pool), db_(db) {}
  ~Connection();
  Connection(Connection&& other) noexcept;
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  Connection& operator=(Connection&&) = delete;
  PGconn* get() const { return db_; }

 private:
  ConnectionPool* pool_;
  PGconn* db_;
};

/// Connections to the database of one libpq URI (postgresql://...).
class ConnectionPool {
 public:
  explicit ConnectionPool(std::string uri) : uri_(std::move(uri)) {}
  ~ConnectionPool();
  ConnectionPool(const ConnectionPool&) = delete;
  ConnectionPool& operator=(const ConnectionPool&) = delete;

  /// An idle connection (reset if the server dropped it), or a new one;
  /// throws StoreFailure if it cannot connect.
  Connection lease();

 private:
  friend class Connection;
  PGconn* open_connection();
  void release(PGconn* db);

  std::string uri_;
  std::mutex mutex_;
  std::vector<PGconn*> idle_;
};

/// The limits every connection sets (name, value) unless the operator
/// configured them: a statement runs at most 30 s, waits for a lock at
/// most 2 s, and a transaction left idle (its server paused or cut off) is
/// ended after 10 s, which releases its locks.
inline constexpr std::pair<const char*, const char*> session_limits[] = {
    {"statement_timeout", "30s"},
    {"lock_timeout", "2s"},
    {"idle_in_transaction_session_timeout", "10s"},
};

/// `uri` without its password, for messages and logs.
std::string redacted(const std::string& uri);

}  // namespace hmpm::server::postgres
