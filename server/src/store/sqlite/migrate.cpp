// migrate.cpp — see migrate.hpp.
#include "migrate.hpp"

#include <algorithm>
#include <iterator>
#include <string>

#include "clock.hpp"
#include "connection.hpp"
#include "hmpm/server/store.hpp"
#include "sqlite_migrations.hpp"

namespace hmpm::server::sqlite {
namespace {

constexpr const char* version_table =
    "CREATE TABLE IF NOT EXISTS schema_migrations (version INTEGER PRIMARY KEY, "
    "name TEXT NOT NULL, applied TEXT NOT NULL)";

int table_version(sqlite3* db) {
  Statement exists(db,
                   "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND "
                   "name = 'schema_migrations'");
  if (!exists.step() || exists.integer(0) == 0) return 0;
  Statement s(db, "SELECT coalesce(max(version), 0) FROM schema_migrations");
  return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

int user_version(sqlite3* db) {
  Statement s(db, "PRAGMA user_version");
  return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

}  // namespace

int latest_version() {
  return static_cast<int>(std::size(migrations));
}

int recorded_version(sqlite3* db) {
  return std::max(table_version(db), user_version(db));
}

void migrate(sqlite3* db) {
  for (std::size_t i = 0; i < std::size(migrations); ++i) {
    if (migrations[i].version != static_cast<int>(i) + 1)
      throw StoreFailure(std::string("migration ") + migrations[i].name + " is out of sequence");
  }
  WriteTransaction tx(db);
  const int version = recorded_version(db);
  if (version > latest_version()) {
    throw StoreFailure("database schema version " + std::to_string(version) +
                       " is newer than this server's " + std::to_string(latest_version()));
  }
  exec(db, version_table);
  const std::string now = now_rfc3339();
  // A file migrated before schema_migrations existed: record what it had.
  for (int v = table_version(db); v < version; ++v) {
    Statement s(db, "INSERT INTO schema_migrations (version, name, applied) VALUES (?1, ?2, ?3)");
    s.bind(1, std::int64_t{v + 1}).bind(2, migrations[v].name).bind(3, "before " + now);
    s.step();
  }
  for (int v = version; v < latest_version(); ++v) {
    exec(db, migrations[v].sql);
    Statement s(db, "INSERT INTO schema_migrations (version, name, applied) VALUES (?1, ?2, ?3)");
    s.bind(1, std::int64_t{v + 1}).bind(2, migrations[v].name).bind(3, now);
    s.step();
  }
  exec(db, ("PRAGMA user_version = " + std::to_string(latest_version())).c_str());
  tx.commit();
}

}  // namespace hmpm::server::sqlite
