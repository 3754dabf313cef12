// test_store.cpp — the SQLite job store on a real database file: schema
// migrations, durability across reopen, FIFO claiming, idempotency keys, the
// queue cap, dismissal races and start-up recovery of interrupted jobs.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <atomic>
#include <thread>

#include "hmpm/server/store.hpp"
#include "support.hpp"

namespace hmpm::server {
namespace {

using testing::make_temp_dir;

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir("store"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path db_path() const { return dir_ / "jobs.sqlite"; }

  static NewJob job(const std::string& name, const std::string& key = "",
                    const std::string& body_hash = "") {
    static std::atomic<int> counter{0};
    NewJob j;
    j.id = "00000000-0000-4000-8000-" + std::to_string(100000000000 + counter++);
    j.name = name;
    j.spec = "{\"name\":\"" + name + "\"}";
    j.cost.particles = 13;
    j.cost.steps = 500;
    j.idempotency_key = key;
    j.body_sha256 = body_hash;
    return j;
  }

  // Runs one SQL query on the file with a separate raw connection.
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

  std::filesystem::path dir_;
};

TEST_F(StoreTest, FreshDatabaseIsMigratedToTheCurrentSchemaInWalMode) {
  JobStore store(db_path());
  EXPECT_EQ(store.schema_version(), JobStore::current_schema_version());
  EXPECT_EQ(query("PRAGMA user_version"), std::to_string(JobStore::current_schema_version()) + ";");
  EXPECT_EQ(query("PRAGMA journal_mode"), "wal;");
  EXPECT_EQ(query("SELECT name FROM sqlite_master WHERE type = 'table' AND name IN "
                  "('jobs','results') ORDER BY name"),
            "jobs;results;");
}

TEST_F(StoreTest, ReopeningKeepsJobsAndDoesNotMigrateAgain) {
  std::string id;
  {
    JobStore store(db_path());
    id = store.submit(job("kept"), 10).job.id;
  }
  JobStore reopened(db_path());
  const auto found = reopened.find(id);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->name, "kept");
  EXPECT_EQ(found->status, JobStatus::accepted);
  EXPECT_EQ(found->cost.particles, 13);
  EXPECT_FALSE(found->created.empty());
}

TEST_F(StoreTest, RefusesADatabaseWithANewerSchema) {
  { JobStore store(db_path()); }
  query("PRAGMA user_version = 99");
  EXPECT_THROW(JobStore store(db_path()), StoreFailure);
}

TEST_F(StoreTest, MigratesAnEmptyVersionZeroFile) {
  query("CREATE TABLE unrelated (x)");  // an existing file at user_version 0
  JobStore store(db_path());
  EXPECT_EQ(store.schema_version(), JobStore::current_schema_version());
  EXPECT_TRUE(store.list({}, 10).empty());
}

TEST_F(StoreTest, ClaimsInSubmissionOrderAndCountsAttempts) {
  JobStore store(db_path());
  const auto a = store.submit(job("a"), 10).job.id;
  const auto b = store.submit(job("b"), 10).job.id;
  const auto first = store.claim_next();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->id, a);
  EXPECT_EQ(first->status, JobStatus::running);
  EXPECT_EQ(first->attempts, 1);
  EXPECT_FALSE(first->started.empty());
  EXPECT_EQ(store.claim_next()->id, b);
  EXPECT_FALSE(store.claim_next());
}

TEST_F(StoreTest, ProgressAndFinishApplyOnlyToRunningJobs) {
  JobStore store(db_path());
  const auto id = store.submit(job("p"), 10).job.id;
  EXPECT_FALSE(store.update_progress(id, 10));  // still accepted
  store.claim_next();
  EXPECT_TRUE(store.update_progress(id, 42.5));
  EXPECT_DOUBLE_EQ(store.find(id)->progress, 42.5);
  const std::vector<ResultFile> files{
      {"summary.json", 12, std::string(64, 'a'), "application/json"}};
  EXPECT_TRUE(store.finish(id, JobStatus::successful, "finished", "", files, 1.5));
  const auto done = store.find(id);
  EXPECT_EQ(done->status, JobStatus::successful);
  EXPECT_DOUBLE_EQ(done->progress, 100.0);
  EXPECT_FALSE(done->finished.empty());
  ASSERT_EQ(store.results(id).size(), 1u);
  EXPECT_EQ(store.results(id)[0].size, 12);
  EXPECT_FALSE(store.finish(id, JobStatus::failed, "again", "again", {}, 0));
}

TEST_F(StoreTest, DismissingARunningJobMakesTheWorkerUpdatesNoOps) {
  JobStore store(db_path());
  const auto id = store.submit(job("d"), 10).job.id;
  store.claim_next();
  const auto before = store.dismiss(id);
  ASSERT_TRUE(before);
  EXPECT_EQ(before->status, JobStatus::running);
  EXPECT_EQ(store.find(id)->status, JobStatus::dismissed);
  EXPECT_FALSE(store.update_progress(id, 50));
  EXPECT_FALSE(store.finish(id, JobStatus::successful, "finished", "", {}, 1));
  EXPECT_EQ(store.find(id)->status, JobStatus::dismissed);
  EXPECT_EQ(store.dismiss(id)->status, JobStatus::dismissed);  // idempotent
  EXPECT_FALSE(store.dismiss("00000000-0000-4000-8000-000000000000"));
}

TEST_F(StoreTest, IdempotencyKeyReplaysSameBodyAndRejectsAnother) {
  JobStore store(db_path());
  const auto first = store.submit(job("i", "key-1", "hash-a"), 10);
  EXPECT_EQ(first.outcome, SubmitOutcome::created);
  const auto again = store.submit(job("i", "key-1", "hash-a"), 10);
  EXPECT_EQ(again.outcome, SubmitOutcome::replayed);
  EXPECT_EQ(again.job.id, first.job.id);
  const auto other = store.submit(job("i", "key-1", "hash-b"), 10);
  EXPECT_EQ(other.outcome, SubmitOutcome::key_conflict);
  EXPECT_EQ(store.list({}, 10).size(), 1u);
}

TEST_F(StoreTest, QueueCapCountsOnlyWaitingJobs) {
  JobStore store(db_path());
  EXPECT_EQ(store.submit(job("q1"), 2).outcome, SubmitOutcome::created);
  EXPECT_EQ(store.submit(job("q2"), 2).outcome, SubmitOutcome::created);
  EXPECT_EQ(store.submit(job("q3"), 2).outcome, SubmitOutcome::queue_full);
  store.claim_next();  // one leaves the queue
  EXPECT_EQ(store.submit(job("q4"), 2).outcome, SubmitOutcome::created);
}

TEST_F(StoreTest, RecoveryRequeuesInterruptedJobsUntilTheAttemptLimit) {
  std::string id;
  {
    JobStore store(db_path());
    id = store.submit(job("crashy"), 10).job.id;
    store.submit(job("waiting"), 10);
  }
  for (int attempt = 1; attempt <= 3; ++attempt) {
    JobStore store(db_path());  // a new process: recover, then a worker claims
    const auto report = store.recover(3);
    if (attempt > 1) {
      ASSERT_EQ(report.requeued.size(), 1u);
      EXPECT_EQ(report.requeued[0], id);
    }
    const auto claimed = store.claim_next();
    ASSERT_TRUE(claimed);
    EXPECT_EQ(claimed->id, id);  // FIFO: the interrupted job keeps its place
    EXPECT_EQ(claimed->attempts, attempt);
    // ... and the process dies here, leaving the job running.
  }
  JobStore store(db_path());
  const auto report = store.recover(3);
  EXPECT_TRUE(report.requeued.empty());
  ASSERT_EQ(report.failed.size(), 1u);
  const auto failed = store.find(id);
  EXPECT_EQ(failed->status, JobStatus::failed);
  EXPECT_NE(failed->failure_reason.find("3 times"), std::string::npos) << failed->failure_reason;
  EXPECT_FALSE(failed->finished.empty());
  EXPECT_EQ(store.count_by_status()[JobStatus::accepted], 1);  // the other job still waits
  EXPECT_EQ(store.count_by_status().count(JobStatus::running), 0u);
}

TEST_F(StoreTest, GracefulRequeueDoesNotCountTheAttempt) {
  JobStore store(db_path());
  const auto id = store.submit(job("r"), 10).job.id;
  store.claim_next();
  EXPECT_TRUE(store.requeue(id));
  const auto back = store.find(id);
  EXPECT_EQ(back->status, JobStatus::accepted);
  EXPECT_EQ(back->attempts, 0);
  EXPECT_TRUE(back->started.empty());
  EXPECT_FALSE(store.requeue(id));  // not running any more
}

TEST_F(StoreTest, ListFiltersByStatusNewestFirst) {
  JobStore store(db_path());
  const auto a = store.submit(job("a"), 10).job.id;
  const auto b = store.submit(job("b"), 10).job.id;
  const auto c = store.submit(job("c"), 10).job.id;
  store.claim_next();  // a runs
  const auto all = store.list({}, 10);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].id, c);
  EXPECT_EQ(store.list({}, 2).size(), 2u);
  const auto waiting = store.list({JobStatus::accepted}, 10);
  ASSERT_EQ(waiting.size(), 2u);
  EXPECT_EQ(waiting[1].id, b);
  EXPECT_EQ(store.list({JobStatus::running, JobStatus::failed}, 10).at(0).id, a);
}

TEST_F(StoreTest, ConcurrentWritersNeverSeeBusy) {
  JobStore store(db_path());
  constexpr int threads = 8;
  constexpr int per_thread = 40;
  std::vector<std::thread> pool;
  std::atomic<int> failures{0};
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      for (int i = 0; i < per_thread; ++i) {
        try {
          NewJob j = job("concurrent");
          j.id = "10000000-0000-4000-8000-";
          j.id += std::to_string(100000000000 + t * 1000 + i);
          store.submit(j, 100000);
          if (auto claimed = store.claim_next()) store.update_progress(claimed->id, 1);
          store.list({}, 5);
        } catch (const StoreFailure&) {
          ++failures;
        }
      }
    });
  }
  for (auto& t : pool) t.join();
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(store.list({}, 1000).size(), static_cast<std::size_t>(threads * per_thread));
}

}  // namespace
}  // namespace hmpm::server
