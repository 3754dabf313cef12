// test_sqlite_store.cpp — the SQLite store: the contract suite, plus what is
// SQLite's own: embedded migrations and their version table, WAL, refusing
// a newer schema, upgrading a version-1 file, the lock that keeps a second
// process off the file, and void leases once the lock is ours.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <fstream>

#include "sqlite_migrations.hpp"
#include "store/sqlite/migrate.hpp"
#include "store_contract.hpp"
#include "support.hpp"

namespace hmpm::server::testing {
namespace {

std::unique_ptr<JobStore> open_in(const std::filesystem::path& scratch, WallClock clock) {
  return open_sqlite_store(scratch / "jobs.sqlite", std::move(clock));
}

INSTANTIATE_TEST_SUITE_P(Sqlite, StoreContract, ::testing::Values(StoreBackend{"sqlite", open_in}),
                         backend_name);

class SqliteStoreTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir("sqlite-store"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path db_path() const { return dir_ / "jobs.sqlite"; }

  // Runs SQL on the file with a separate raw connection; the rows as "a;b;".
  std::string query(const std::string& sql) const {
    sqlite3* db = nullptr;
    sqlite3_open(db_path().c_str(), &db);
    std::string out;
    sqlite3_exec(
        db, sql.c_str(),
        [](void* o, int n, char** values, char**) {
          for (int i = 0; i < n; ++i)
            *static_cast<std::string*>(o) += (values[i] ? values[i] : "NULL") + std::string(";");
          return 0;
        },
        &out, nullptr);
    sqlite3_close(db);
    return out;
  }

  static NewJob job(const std::string& id) {
    NewJob j;
    j.id = id;
    j.name = "n";
    j.spec = "{}";
    return j;
  }

  std::filesystem::path dir_;
};

TEST_F(SqliteStoreTest, FreshFileGetsEveryEmbeddedMigrationInOrderInWalMode) {
  auto store = open_sqlite_store(db_path());
  const int latest = sqlite::latest_version();
  ASSERT_EQ(latest, static_cast<int>(std::size(sqlite::migrations)));
  EXPECT_EQ(std::string(sqlite::migrations[0].name), "0001_init");
  EXPECT_EQ(query("PRAGMA user_version"), std::to_string(latest) + ";");
  std::string expected;
  for (const auto& m : sqlite::migrations)
    expected += std::to_string(m.version) + ";" + m.name + ";";
  EXPECT_EQ(query("SELECT version, name FROM schema_migrations ORDER BY version"), expected);
  EXPECT_EQ(query("PRAGMA journal_mode"), "wal;");
  EXPECT_EQ(query("SELECT name FROM sqlite_master WHERE type = 'table' AND name IN "
                  "('jobs','results') ORDER BY name"),
            "jobs;results;");
}

TEST_F(SqliteStoreTest, ReopeningDoesNotMigrateAgain) {
  { auto store = open_sqlite_store(db_path()); }
  const std::string recorded = query("SELECT version, applied FROM schema_migrations");
  { auto store = open_sqlite_store(db_path()); }
  EXPECT_EQ(query("SELECT version, applied FROM schema_migrations"), recorded);
}

TEST_F(SqliteStoreTest, RefusesADatabaseWithANewerSchema) {
  { auto store = open_sqlite_store(db_path()); }
  query("PRAGMA user_version = 99");
  EXPECT_THROW(open_sqlite_store(db_path()), StoreFailure);
}

// SQLite would take an empty file for a new database: an emptied file must
// not quietly become an empty queue.
TEST_F(SqliteStoreTest, RefusesAnEmptyFileSayingSo) {
  { std::ofstream touch(db_path()); }
  try {
    open_sqlite_store(db_path());
    FAIL() << "an empty file was opened as a database";
  } catch (const StoreFailure& e) {
    EXPECT_NE(std::string(e.what()).find("is an empty file (0 bytes)"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(std::filesystem::file_size(db_path()), 0u);  // left as it was
}

// Pages overwritten with garbage (a bad disk, a torn copy): the integrity
// check at open refuses the file instead of serving half of it.
TEST_F(SqliteStoreTest, RefusesADamagedFileAfterItsIntegrityCheck) {
  {
    auto store = open_sqlite_store(db_path());
    NewJob j = job("00000000-0000-4000-8000-000000000000");
    for (int i = 0; i < 50; ++i) {
      j.id[34] = static_cast<char>('0' + i / 10);
      j.id[35] = static_cast<char>('0' + i % 10);
      store->submit(j, 100);
    }
  }
  const auto size = std::filesystem::file_size(db_path());
  ASSERT_GT(size, 4u * 4096u);
  {
    std::fstream f(db_path(), std::ios::in | std::ios::out | std::ios::binary);
    const std::string garbage(size - 4096, '\x5a');
    f.seekp(4096);  // every page but the header's
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  try {
    open_sqlite_store(db_path());
    FAIL() << "a damaged file was opened";
  } catch (const StoreFailure& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(db_path().string()), std::string::npos) << what;
    EXPECT_NE(what.find("restore it from a backup"), std::string::npos) << what;
  }
}

TEST_F(SqliteStoreTest, MigratesAnUnrelatedVersionZeroFile) {
  query("CREATE TABLE unrelated (x)");  // an existing file at user_version 0
  auto store = open_sqlite_store(db_path());
  EXPECT_EQ(query("PRAGMA user_version"), std::to_string(sqlite::latest_version()) + ";");
  EXPECT_TRUE(store->list({}, "", 10).empty());
}

// A file written by the release before leases (user_version 1, no version
// table) keeps its jobs, and its running job is requeued on open.
TEST_F(SqliteStoreTest, UpgradesAVersionOneFileAndRecoversItsRunningJob) {
  query(std::string(sqlite::migrations[0].sql) + "; PRAGMA user_version = 1;");
  query(
      "INSERT INTO jobs (id, name, spec, status, created, updated, attempts) VALUES "
      "('00000000-0000-4000-8000-000000000001', 'old', '{}', 'running', 't', 't', 1)");
  auto store = open_sqlite_store(db_path());
  std::string versions;  // every migration after the first ran
  for (const auto& m : sqlite::migrations) versions += std::to_string(m.version) + ";";
  EXPECT_EQ(query("SELECT version FROM schema_migrations ORDER BY version"), versions);
  const auto report = store->recover(3, 0.0);
  ASSERT_EQ(report.requeued.size(), 1u);
  EXPECT_EQ(store->find(report.requeued[0])->name, "old");
}

TEST_F(SqliteStoreTest, TheStatusColumnAcceptsExactlyTheStatusTable) {
  auto store = open_sqlite_store(db_path());
  const std::string id = store->submit(job("00000000-0000-4000-8000-000000000002"), 10).job.id;
  for (const auto& row : job_statuses) {
    query("UPDATE jobs SET status = '" + std::string(row.name) + "' WHERE id = '" + id + "'");
    EXPECT_EQ(store->find(id)->status, row.status) << row.name;
  }
  query("UPDATE jobs SET status = 'bogus' WHERE id = '" + id + "'");
  EXPECT_EQ(store->find(id)->status, job_statuses.back().status);  // refused by CHECK
}

TEST_F(SqliteStoreTest, ASecondOpenWhileTheFirstHoldsTheFileIsRefusedNamingThePid) {
  auto first = open_sqlite_store(db_path());
  try {
    open_sqlite_store(db_path());
    FAIL() << "a second store opened the same file";
  } catch (const StoreFailure& e) {
    EXPECT_NE(std::string(e.what()).find("pid " + std::to_string(::getpid())), std::string::npos)
        << e.what();
  }
  first.reset();
  EXPECT_NO_THROW(open_sqlite_store(db_path()));  // released with the store
}

// The lock proves that the process which claimed a job is gone, so its
// lease is void on open even if it had not lapsed yet (kill -9, restart).
TEST_F(SqliteStoreTest, LeasesOfAnEarlierProcessEndWhenTheLockIsOurs) {
  std::string id;
  {
    auto store = open_sqlite_store(db_path());
    id = store->submit(job("00000000-0000-4000-8000-000000000003"), 10).job.id;
    store->claim_next(Claimant{"earlier-process", 600.0});
    EXPECT_TRUE(store->recover(3, 0.0).requeued.empty());  // live while that store is open
  }
  auto store = open_sqlite_store(db_path());
  const auto report = store->recover(3, 0.0);
  ASSERT_EQ(report.requeued.size(), 1u);
  EXPECT_EQ(report.requeued[0], id);
}

}  // namespace
}  // namespace hmpm::server::testing
