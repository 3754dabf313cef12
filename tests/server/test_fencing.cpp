// test_fencing.cpp — result files are fenced like every other write of a
// running job (issue 20): a server paused past its lease and then revived
// cannot change the files another server's attempt finished with.
//
// Two worker pools (two "servers", each with its own instance id) share one
// SQLite store whose clock the test moves, and one data folder. Server A
// claims a job and is paused inside the run: its store (PausedStore) blocks
// A's first progress write, renews no lease and recovers nothing, as a
// SIGSTOPped process would. The test moves the clock past A's lease; server
// B's heartbeat takes the job over, B runs it and finishes it. Then A is let
// go: its progress write is answered `held` (the paused server has not yet
// heard of the takeover, the worst case: it goes on and writes every result
// file), it writes its files and its fenced finish() is refused. B's files
// (sha256 against the manifest, inode and mtime) must be untouched, and A's
// folder gone once A knows the job ended under another claim.
//
// summary.json records the run's wall time, so A's copy of it never equals
// B's byte for byte: before result folders were per attempt, A's run
// rewrote B's summary.json in place and this test failed on its sha256.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <ostream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "digest.hpp"
#include "hmpm/server/store.hpp"
#include "job_log.hpp"
#include "metrics.hpp"
#include "support.hpp"
#include "workers/pool.hpp"

namespace hmpm::server {
namespace {

using testing::long_spec;
using testing::make_temp_dir;

// Forwards everything to `inner`, except that it is paused: the first
// progress write blocks until resume(), and the heartbeat does nothing.
class PausedStore : public JobStore {
 public:
  explicit PausedStore(JobStore& inner) : inner_(inner) {}

  void resume() {
    std::lock_guard<std::mutex> lock(mutex_);
    resumed_ = true;
    wake_.notify_all();
  }
  bool paused() {
    std::lock_guard<std::mutex> lock(mutex_);
    return paused_;
  }

  ClaimState record_progress(const Claim& claim, const RunProgress& run) override {
    std::unique_lock<std::mutex> lock(mutex_);
    if (resumed_) return inner_.record_progress(claim, run);
    paused_ = true;
    wake_.notify_all();
    wake_.wait(lock, [&] { return resumed_; });
    return ClaimState::held;  // it has not heard of the takeover yet
  }
  std::int64_t renew_leases(const Claimant&) override { return 0; }
  RecoveryReport recover(int, double) override { return {}; }

  void probe() override { inner_.probe(); }
  SubmitResult submit(const NewJob& job, std::int64_t max_queue) override {
    return inner_.submit(job, max_queue);
  }
  std::optional<JobRecord> find(const std::string& id) override { return inner_.find(id); }
  std::vector<JobRecord> list(const std::vector<JobStatus>& statuses, const std::string& name,
                              int limit) override {
    return inner_.list(statuses, name, limit);
  }
  std::vector<std::string> ids_with_prefix(const std::string& prefix, int limit) override {
    return inner_.ids_with_prefix(prefix, limit);
  }
  std::optional<JobRecord> claim_next(const Claimant& who) override {
    return inner_.claim_next(who);
  }
  ClaimState finish(const Claim& claim, const JobEnd& end) override {
    return inner_.finish(claim, end);
  }
  ClaimState requeue(const Claim& claim) override { return inner_.requeue(claim); }
  std::optional<JobRecord> cancel(const std::string& id) override { return inner_.cancel(id); }
  std::optional<JobRecord> dismiss(const std::string& id) override { return inner_.dismiss(id); }
  ClaimState keep_results(const Claim& claim, const std::vector<ResultFile>& files,
                          double run_seconds) override {
    return inner_.keep_results(claim, files, run_seconds);
  }
  std::vector<ResultFile> results(const std::string& id) override { return inner_.results(id); }
  StatusCounts count_by_status() override { return inner_.count_by_status(); }
  std::vector<std::string> purge_ended(std::chrono::system_clock::time_point before) override {
    return inner_.purge_ended(before);
  }
  ClaimState record_checkpoint(const Claim& claim, const CheckpointRecord& c) override {
    return inner_.record_checkpoint(claim, c);
  }
  std::optional<CheckpointRecord> checkpoint(const std::string& id) override {
    return inner_.checkpoint(id);
  }
  EnsembleSubmitResult submit_ensemble(const NewEnsemble& e, std::int64_t max_queue) override {
    return inner_.submit_ensemble(e, max_queue);
  }
  std::optional<EnsembleRecord> find_ensemble(const std::string& id) override {
    return inner_.find_ensemble(id);
  }
  std::vector<EnsembleRecord> list_ensembles(int limit) override {
    return inner_.list_ensembles(limit);
  }
  std::optional<EnsembleRecord> set_ensemble_state(const std::string& id,
                                                   EnsembleState state) override {
    return inner_.set_ensemble_state(id, state);
  }

 private:
  JobStore& inner_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool paused_ = false;
  bool resumed_ = false;
};

WorkerSettings settings_for(const std::string& instance, const std::filesystem::path& data) {
  WorkerSettings s;
  s.workers = 1;
  s.threads_per_job = 1;
  s.progress_interval_s = 0.01;
  s.data_dir = data;
  s.claimant = Claimant{instance, 30.0};
  s.lease_renewal_s = 0.05;
  s.checkpoint_interval_s = 0.0;
  return s;
}

bool wait_for(const std::function<bool()>& done, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

struct FileState {
  std::string sha256;
  ino_t inode = 0;
  std::int64_t mtime_ns = 0;
  bool operator==(const FileState& o) const {
    return sha256 == o.sha256 && inode == o.inode && mtime_ns == o.mtime_ns;
  }
};

// For gtest's failure messages.
// NOLINTNEXTLINE(readability-identifier-naming): GoogleTest looks the printer up by this name.
void PrintTo(const FileState& f, std::ostream* os) {
  *os << "{sha256 " << f.sha256 << ", inode " << f.inode << ", mtime " << f.mtime_ns << " ns}";
}

FileState state_of(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  return {sha256_file_hex(path).value_or(""), st.st_ino,
          static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec};
}

TEST(Fencing, ARevivedServerCannotChangeTheFilesOfTheAttemptThatFinished) {
  set_logging_enabled(false);
  const auto dir = make_temp_dir("fencing");
  const auto data = dir / "results";
  std::atomic<std::int64_t> offset_s{0};
  auto store = open_sqlite_store(dir / "db.sqlite", [&] {
    return std::chrono::system_clock::now() + std::chrono::seconds(offset_s.load());
  });
  // 20 000 steps of a 1000-particle bar: about half a second of solver work.
  const auto submitted = store->submit(NewJob{"0f0f0f0f-0000-4000-8000-000000000001", "fenced",
                                              long_spec("fenced", 20.0), JobCost{}, "", ""},
                                       10);
  ASSERT_EQ(submitted.outcome, SubmitOutcome::created);
  const std::string id = submitted.job.id;

  PausedStore paused(*store);
  Metrics metrics_a;
  Metrics metrics_b;
  WorkerPool a(paused, metrics_a, settings_for("server-a", data));
  a.start();
  ASSERT_TRUE(wait_for([&] { return paused.paused(); }, 30)) << "A never reached its run";
  const auto claimed_by_a = store->find(id);
  ASSERT_TRUE(claimed_by_a);
  EXPECT_EQ(claimed_by_a->owner, "server-a");
  const std::int64_t token_a = claimed_by_a->lease_token;

  // A's lease lapses; B's heartbeat takes the job over and B finishes it.
  offset_s = 120;
  WorkerPool b(*store, metrics_b, settings_for("server-b", data));
  b.start();
  ASSERT_TRUE(wait_for(
      [&] {
        const auto j = store->find(id);
        return j && j->status == JobStatus::successful;
      },
      60))
      << "B did not finish the job";
  const auto done = store->find(id);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->owner, "server-b");
  EXPECT_GT(done->lease_token, token_a);
  const auto served = b.files().results_dir(*done);
  EXPECT_EQ(served, data / id / ("attempt-" + std::to_string(done->lease_token)));
  const auto manifest = store->results(id);
  ASSERT_FALSE(manifest.empty());
  std::map<std::string, FileState> before;
  for (const auto& f : manifest) {
    before[f.name] = state_of(served / f.name);
    EXPECT_EQ(before[f.name].sha256, f.sha256) << f.name;
  }

  // A wakes up, believes it still holds the job, runs to its end and writes
  // every file of its own; its finish is refused.
  paused.resume();
  ASSERT_TRUE(wait_for([&] { return metrics_a.claims_lost.load() == 1; }, 60))
      << "A's lost claim was not noticed";
  a.shutdown();
  b.shutdown();

  for (const auto& f : store->results(id)) {
    EXPECT_EQ(state_of(served / f.name), before[f.name]) << f.name << " was changed by A";
    EXPECT_EQ(state_of(served / f.name).sha256, f.sha256) << f.name;
  }
  std::set<std::string> entries;
  for (const auto& e : std::filesystem::directory_iterator(data / id))
    entries.insert(e.path().filename().string());
  EXPECT_EQ(entries, (std::set<std::string>{served.filename().string(), "job.log"}))
      << "A's folder should be gone once it knew the job had ended";
  const auto after = store->find(id);
  ASSERT_TRUE(after);
  EXPECT_EQ(after->status, JobStatus::successful);
  EXPECT_EQ(after->lease_token, done->lease_token);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hmpm::server
