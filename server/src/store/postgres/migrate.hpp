// migrate.hpp — the PostgreSQL store's schema, migrated in order on connect.
//
// As in the SQLite store: the files migrations/NNNN_name.sql are embedded at
// build time (postgres_migrations.hpp, from server/cmake/embed_sql.cmake)
// and every applied one is a row of `schema_migrations` (version, name,
// applied). Servers starting together on one database take a transaction
// advisory lock first, so exactly one of them migrates and the others see
// its rows. Never edit a released file: add the next one.
#pragma once

#include <libpq-fe.h>

namespace hmpm::server::postgres {

/// The highest version this build knows (the last migration file).
int latest_version();

/// The version recorded in the database (0 for a new one).
int recorded_version(PGconn* db);

/// Applies every migration above the recorded version, in one transaction.
/// Throws StoreFailure if the database is newer than this build.
void migrate(PGconn* db);

}  // namespace hmpm::server::postgres
