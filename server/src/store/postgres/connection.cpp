// connection.cpp — see connection.hpp.
#include "connection.hpp"

#include <unistd.h>

#include <charconv>
#include <cstdlib>
#include <utility>

#include "hmpm/server/store.hpp"

namespace hmpm::server::postgres {
namespace {

[[noreturn]] void fail(PGconn* db, const std::string& what) {
  std::string message = db ? PQerrorMessage(db) : "out of memory";
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  throw StoreFailure("postgresql: " + what + ": " + message);
}

}  // namespace

Params& Params::add(std::string_view v) {
  values_.emplace_back(v);
  null_.push_back(false);
  return *this;
}

Params& Params::add(std::int64_t v) {
  return add(std::to_string(v));
}

Params& Params::add(double v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);  // shortest round trip
  return add(std::string_view(text, ec == std::errc() ? static_cast<std::size_t>(end - text) : 0));
}

Params& Params::add_or_null(std::string_view v) {
  add(v);
  null_.back() = v.empty();
  return *this;
}

std::vector<const char*> Params::pointers() const {
  std::vector<const char*> out;
  out.reserve(values_.size());
  for (std::size_t i = 0; i < values_.size(); ++i)
    out.push_back(null_[i] ? nullptr : values_[i].c_str());
  return out;
}

std::int64_t Result::affected() const {
  return std::strtoll(PQcmdTuples(r_.get()), nullptr, 10);
}

std::string Result::text(int row, int col) const {
  return {PQgetvalue(r_.get(), row, col),
          static_cast<std::size_t>(PQgetlength(r_.get(), row, col))};
}

std::int64_t Result::integer(int row, int col) const {
  return std::strtoll(PQgetvalue(r_.get(), row, col), nullptr, 10);
}

double Result::real(int row, int col) const {
  return std::strtod(PQgetvalue(r_.get(), row, col), nullptr);
}

bool Result::boolean(int row, int col) const {
  return PQgetvalue(r_.get(), row, col)[0] == 't';
}

std::string Result::sqlstate() const {
  const char* code = PQresultErrorField(r_.get(), PG_DIAG_SQLSTATE);
  return code ? code : "";
}

Result exec(PGconn* db, const std::string& sql, const Params& params) {
  const auto values = params.pointers();
  Result result(
      PQexecParams(db, sql.c_str(), params.size(), nullptr, values.data(), nullptr, nullptr, 0));
  if (result.status() != PGRES_COMMAND_OK && result.status() != PGRES_TUPLES_OK) {
    fail(db, sql.substr(0, sql.find(' ')));
  }
  return result;
}

void exec_script(PGconn* db, const char* sql) {
  const Result result(PQexec(db, sql));
  if (result.status() != PGRES_COMMAND_OK && result.status() != PGRES_TUPLES_OK) fail(db, "script");
}

Transaction::Transaction(PGconn* db) : db_(db) {
  exec(db_, "BEGIN");
}

Transaction::~Transaction() {
  if (!done_) PQclear(PQexec(db_, "ROLLBACK"));
}

void Transaction::commit() {
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
  for (PGconn* db : idle_) PQfinish(db);
  idle_.clear();
}

PGconn* ConnectionPool::open_connection() {
  // The client side of a cut network: give up connecting after 5 s, and
  // notice a peer that stopped answering (keepalives; unacknowledged data
  // for 30 s). Given before the URI, so the URI's own values win.
  // Sessions are named "hmpm-server <pid>" in pg_stat_activity.
  const std::string name = "hmpm-server " + std::to_string(::getpid());
  const char* keywords[] = {"connect_timeout",           "keepalives",       "keepalives_idle",
                            "keepalives_interval",       "keepalives_count", "tcp_user_timeout",
                            "fallback_application_name", "dbname",           nullptr};
  const char* values[] = {"5", "1", "10", "5", "3", "30000", name.c_str(), uri_.c_str(), nullptr};
  PGconn* db = PQconnectdbParams(keywords, values, 1);
  if (PQstatus(db) != CONNECTION_OK) {
    std::string message = db ? PQerrorMessage(db) : "out of memory";
    while (!message.empty() && message.back() == '\n') message.pop_back();
    PQfinish(db);
    throw StoreFailure("cannot connect to " + redacted(uri_) + ": " + message);
  }
  try {
    // Quiet NOTICEs (CREATE ... IF NOT EXISTS) and UTC for any server-side time.
    exec(db, "SET client_min_messages = warning");
    exec(db, "SET TIME ZONE 'UTC'");
    // The server side: no statement, lock wait or open transaction of ours
    // lasts without bound (a paused or cut-off server's transaction is
    // ended, its locks released), unless the operator set the limit (the
    // URI's options, ALTER ROLE/DATABASE ... SET, postgresql.conf).
    std::string names;
    for (const auto& [name, value] : session_limits)
      names += std::string(names.empty() ? "'" : ",'") + name + "'";
    const Result unset = exec(
        db, "SELECT name FROM pg_settings WHERE source = 'default' AND name IN (" + names + ")");
    for (int i = 0; i < unset.rows(); ++i) {
      for (const auto& [name, value] : session_limits) {
        if (unset.text(i, 0) == name) exec(db, std::string("SET ") + name + " = '" + value + "'");
      }
    }
  } catch (...) {
    PQfinish(db);
    throw;
  }
  return db;
}

Connection ConnectionPool::lease() {
  PGconn* db = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!idle_.empty()) {
      db = idle_.back();
      idle_.pop_back();
    }
  }
  if (db && PQstatus(db) != CONNECTION_OK) {  // dropped since: start afresh
    PQfinish(db);
    db = nullptr;
  }
  return Connection(*this, db ? db : open_connection());
}

void ConnectionPool::release(PGconn* db) {
  // A connection left inside a failed transaction or broken is not reused.
  if (PQstatus(db) != CONNECTION_OK || PQtransactionStatus(db) != PQTRANS_IDLE) {
    PQfinish(db);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  idle_.push_back(db);
}

std::string redacted(const std::string& uri) {
  // postgresql://user:secret@host/... -> postgresql://user:***@host/...
  const auto scheme = uri.find("://");
  const auto at = uri.find('@');
  if (scheme == std::string::npos || at == std::string::npos) return uri;
  const auto colon = uri.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return uri;
  return uri.substr(0, colon + 1) + "***" + uri.substr(at);
}

}  // namespace hmpm::server::postgres
