// migrate.hpp — the SQLite store's schema, migrated in order on open.
//
// The migrations are the files migrations/NNNN_name.sql, embedded at build
// time (server/cmake/embed_sql.cmake generates sqlite_migrations.hpp), so a
// server never reads SQL from disk. Each applied migration is a row of
// `schema_migrations` (version, name, applied); `PRAGMA user_version` mirrors
// the highest version for tools, and files from before the table existed are
// recognised by it. Never edit a released file: add the next one.
#pragma once

#include <sqlite3.h>

namespace hmpm::server::sqlite {

/// The highest version this build knows (the last migration file).
int latest_version();

/// The version recorded in the database (0 for a new file).
int recorded_version(sqlite3* db);

/// Applies every migration above the recorded version, in one transaction.
/// Throws StoreFailure if the database is newer than this build.
void migrate(sqlite3* db);

}  // namespace hmpm::server::sqlite
