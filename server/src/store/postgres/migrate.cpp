// migrate.cpp — see migrate.hpp.
#include "migrate.hpp"

#include <iterator>
#include <string>

#include "clock.hpp"
#include "connection.hpp"
#include "hmpm/server/store.hpp"
#include "postgres_migrations.hpp"

namespace hmpm::server::postgres {
namespace {

// pg_advisory_xact_lock key of schema migration ("hmpm" in ASCII).
constexpr const char* migration_lock = "SELECT pg_advisory_xact_lock(1752001901)";

}  // namespace

int latest_version() {
  return static_cast<int>(std::size(migrations));
}

int recorded_version(PGconn* db) {
  // to_regclass follows search_path: the table of this schema, if any.
  if (exec(db, "SELECT to_regclass('schema_migrations') IS NULL").boolean(0, 0)) return 0;
  return static_cast<int>(
      exec(db, "SELECT coalesce(max(version), 0) FROM schema_migrations").integer(0, 0));
}

void migrate(PGconn* db) {
  for (std::size_t i = 0; i < std::size(migrations); ++i) {
    if (migrations[i].version != static_cast<int>(i) + 1)
      throw StoreFailure(std::string("migration ") + migrations[i].name + " is out of sequence");
  }
  Transaction tx(db);
  // A migration may rewrite a large table, and the servers starting beside
  // this one wait for it: no statement or lock limit here (a paused
  // migrating server is still ended by idle_in_transaction_session_timeout).
  exec(db, "SET LOCAL statement_timeout = 0");
  exec(db, "SET LOCAL lock_timeout = 0");
  exec(db, migration_lock);
  const int version = recorded_version(db);
  if (version > latest_version()) {
    throw StoreFailure("database schema version " + std::to_string(version) +
                       " is newer than this server's " + std::to_string(latest_version()));
  }
  exec(db,
       "CREATE TABLE IF NOT EXISTS schema_migrations (version INTEGER PRIMARY KEY, "
       "name TEXT NOT NULL, applied TEXT NOT NULL)");
  const std::string now = now_rfc3339();
  for (int v = version; v < latest_version(); ++v) {
    exec_script(db, migrations[v].sql);
    exec(db, "INSERT INTO schema_migrations (version, name, applied) VALUES ($1, $2, $3)",
         Params().add(std::int64_t{v + 1}).add(migrations[v].name).add(now));
  }
  tx.commit();
}

}  // namespace hmpm::server::postgres
