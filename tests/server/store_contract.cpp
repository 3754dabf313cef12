// store_contract.cpp — the JobStore contract: FIFO claiming with owner,
// lease and fencing token; progress and results only under a held claim;
// idempotency keys; the queue cap; dismissal races; recovery that takes only
// lapsed leases; durability across reopen; concurrent writers.
#include "store_contract.hpp"

#include <atomic>
#include <thread>
#include <vector>

#include "support.hpp"

namespace hmpm::server::testing {

void StoreContract::SetUp() {
  if (GetParam().unavailable) {
    if (const std::string reason = GetParam().unavailable(); !reason.empty())
      GTEST_SKIP() << reason;
  }
  scratch_ = make_temp_dir("store-" + GetParam().name);
}

void StoreContract::TearDown() {
  store_.reset();
  if (!scratch_.empty()) std::filesystem::remove_all(scratch_);
}

JobStore& StoreContract::store() {
  if (!store_) store_ = GetParam().open(scratch_, [this] { return now(); });
  return *store_;
}

std::chrono::system_clock::time_point StoreContract::now() const {
  return std::chrono::system_clock::now() + offset_;
}

void StoreContract::advance(std::chrono::system_clock::duration by) {
  offset_ += by;
}

void StoreContract::close() {
  store_.reset();
}

NewJob StoreContract::job(const std::string& name, const std::string& key,
                          const std::string& body_hash) {
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

NewEnsemble StoreContract::ensemble(int samples, const std::string& key,
                                    const std::string& body_hash) {
  static std::atomic<int> counter{0};
  NewEnsemble e;
  e.id = "e0000000-0000-4000-8000-" + std::to_string(100000000000 + counter++);
  e.request = R"({"samples":)" + std::to_string(samples) + "}";
  e.seed = 42;
  e.idempotency_key = key;
  e.body_sha256 = body_hash;
  for (int k = 0; k < samples; ++k) e.samples.push_back(job("sample-" + std::to_string(k)));
  return e;
}

Claimant StoreContract::live() {
  return Claimant{"live-instance", 600.0};
}

Claimant StoreContract::dead(const std::string& instance) {
  return Claimant{instance, 0.0};
}

namespace {

TEST_P(StoreContract, ReopeningKeepsJobs) {
  const std::string id = store().submit(job("kept"), 10).job.id;
  close();
  const auto found = store().find(id);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->name, "kept");
  EXPECT_EQ(found->status, JobStatus::accepted);
  EXPECT_EQ(found->cost.particles, 13);
  EXPECT_FALSE(found->created.empty());
  EXPECT_NO_THROW(store().probe());
}

TEST_P(StoreContract, ClaimsInSubmissionOrderWithOwnerLeaseAndToken) {
  const auto a = store().submit(job("a"), 10).job.id;
  const auto b = store().submit(job("b"), 10).job.id;
  const auto first = store().claim_next(live());
  ASSERT_TRUE(first);
  EXPECT_EQ(first->id, a);
  EXPECT_EQ(first->status, JobStatus::running);
  EXPECT_EQ(first->attempts, 1);
  EXPECT_FALSE(first->started.empty());
  EXPECT_EQ(first->owner, live().instance);
  EXPECT_GT(first->lease_token, 0);
  EXPECT_GT(first->lease_expires_ms, 0);
  EXPECT_EQ(store().claim_next(live())->id, b);
  EXPECT_FALSE(store().claim_next(live()));
}

TEST_P(StoreContract, AcceptedJobsKnowTheirPlaceInTheQueue) {
  const auto a = store().submit(job("a"), 10).job;
  const auto b = store().submit(job("b"), 10).job;
  const auto c = store().submit(job("c"), 10).job;
  EXPECT_EQ(a.queue_position, 1);  // as the submission returns it
  EXPECT_EQ(c.queue_position, 3);
  EXPECT_EQ(store().find(b.id)->queue_position, 2);
  store().claim_next(live());  // a runs: the others move up
  EXPECT_EQ(store().find(a.id)->queue_position, 0);
  EXPECT_EQ(store().find(b.id)->queue_position, 1);
  store().cancel(b.id);
  EXPECT_EQ(store().find(b.id)->queue_position, 0);
  const auto listed = store().list({JobStatus::accepted}, "", 10);
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].id, c.id);
  EXPECT_EQ(listed[0].queue_position, 1);
}

TEST_P(StoreContract, ProgressAndFinishApplyOnlyUnderAHeldClaim) {
  const auto id = store().submit(job("p"), 10).job.id;
  const Claim never{id, live().instance, 1};
  EXPECT_NE(store().update_progress(never, 10), ClaimState::held);  // still accepted
  const Claim claim = claim_of(*store().claim_next(live()));
  EXPECT_EQ(store().update_progress(claim, 42.5), ClaimState::held);
  EXPECT_DOUBLE_EQ(store().find(id)->progress, 42.5);
  // What the run reached comes back as it was stored (issue 44: the status
  // document's simulated time, end time, steps and step range).
  const RunProgress reached{50.0, 1.5e8, 3.0e8, 1234, 3600.0, 86400.0};
  EXPECT_EQ(store().record_progress(claim, reached), ClaimState::held);
  const auto halfway = store().find(id);
  EXPECT_DOUBLE_EQ(halfway->progress, 50.0);
  EXPECT_DOUBLE_EQ(halfway->run.time, 1.5e8);
  EXPECT_DOUBLE_EQ(halfway->run.end_time, 3.0e8);
  EXPECT_EQ(halfway->run.steps, 1234);
  EXPECT_DOUBLE_EQ(halfway->run.dt_min, 3600.0);
  EXPECT_DOUBLE_EQ(halfway->run.dt_max, 86400.0);
  EXPECT_EQ(halfway->queue_position, 0);  // running: not in the queue
  const JobEnd end{JobStatus::successful,
                   "finished",
                   "",
                   {{"summary.json", 12, std::string(64, 'a'), "application/json"}},
                   1.5,
                   {100.0, 3.0e8, 3.0e8, 2000, 1800.0, 90000.0}};
  EXPECT_EQ(store().finish(claim, end), ClaimState::held);
  const auto done = store().find(id);
  EXPECT_DOUBLE_EQ(done->run.time, 3.0e8);
  EXPECT_EQ(done->run.steps, 2000);
  EXPECT_DOUBLE_EQ(done->run.dt_min, 1800.0);
  EXPECT_DOUBLE_EQ(done->run.dt_max, 90000.0);
  EXPECT_EQ(done->status, JobStatus::successful);
  EXPECT_DOUBLE_EQ(done->progress, 100.0);
  EXPECT_FALSE(done->finished.empty());
  ASSERT_EQ(store().results(id).size(), 1u);
  EXPECT_EQ(store().results(id)[0].size, 12);
  EXPECT_EQ(store().finish(claim, JobEnd{JobStatus::failed, "again", "again", {}, 0, {}}),
            ClaimState::lost);
}

TEST_P(StoreContract, DismissingARunningJobTurnsItsClaimedWritesIntoDismissed) {
  const auto id = store().submit(job("d"), 10).job.id;
  const Claim claim = claim_of(*store().claim_next(live()));
  const auto before = store().dismiss(id);
  ASSERT_TRUE(before);
  EXPECT_EQ(before->status, JobStatus::running);
  EXPECT_EQ(store().find(id)->status, JobStatus::dismissed);
  EXPECT_EQ(store().update_progress(claim, 50), ClaimState::dismissed);
  EXPECT_EQ(store().finish(claim, JobEnd{JobStatus::successful, "finished", "", {}, 1, {}}),
            ClaimState::dismissed);
  EXPECT_EQ(store().find(id)->status, JobStatus::dismissed);
  EXPECT_EQ(store().dismiss(id)->status, JobStatus::dismissed);  // idempotent
  EXPECT_FALSE(store().dismiss("00000000-0000-4000-8000-000000000000"));
}

TEST_P(StoreContract, CancelKeepsTheFilesTheWorkerRecordsAndDeleteRemovesThem) {
  const std::vector<ResultFile> files{
      {"summary.json", 12, std::string(64, 'b'), "application/json"}};
  // Queued: dismissed at once, no files.
  const auto queued = store().submit(job("cq"), 10).job.id;
  // Running: dismissed; the worker's claim may still record what it wrote.
  const auto id = store().submit(job("c"), 10).job.id;
  const auto claimed = store().claim_next(live());
  ASSERT_EQ(claimed->id, queued);  // FIFO: the first one is claimed first
  const Claim queued_claim = claim_of(*claimed);
  EXPECT_EQ(store().cancel(queued)->status, JobStatus::running);
  const Claim claim = claim_of(*store().claim_next(live()));
  EXPECT_EQ(store().cancel(id)->status, JobStatus::running);
  EXPECT_EQ(store().find(id)->status, JobStatus::dismissed);
  EXPECT_FALSE(store().find(id)->results_deleted);
  EXPECT_EQ(store().update_progress(claim, 50), ClaimState::dismissed);
  EXPECT_EQ(store().keep_results(claim, files, 2.5), ClaimState::held);
  ASSERT_EQ(store().results(id).size(), 1u);
  // Ended: nothing changes, the row before comes back.
  EXPECT_EQ(store().cancel(id)->status, JobStatus::dismissed);
  EXPECT_EQ(store().results(id).size(), 1u);
  EXPECT_FALSE(store().cancel("00000000-0000-4000-8000-000000000000"));
  // A claim that is not the job's records nothing.
  EXPECT_EQ(store().keep_results(Claim{id, "someone-else", claim.token}, files, 1),
            ClaimState::lost);
  // Delete after cancel: the files go, and a late worker is told so.
  EXPECT_EQ(store().dismiss(queued)->status, JobStatus::dismissed);
  EXPECT_TRUE(store().find(queued)->results_deleted);
  EXPECT_EQ(store().keep_results(queued_claim, files, 1), ClaimState::dismissed);
  EXPECT_TRUE(store().results(queued).empty());
  store().dismiss(id);
  EXPECT_TRUE(store().results(id).empty());
  EXPECT_TRUE(store().find(id)->results_deleted);
  // A finished job cannot be cancelled.
  const auto done = store().submit(job("f"), 10).job.id;
  const Claim done_claim = claim_of(*store().claim_next(live()));
  store().finish(done_claim, JobEnd{JobStatus::successful, "finished", "", files, 1, {}});
  EXPECT_EQ(store().cancel(done)->status, JobStatus::successful);
  EXPECT_EQ(store().find(done)->status, JobStatus::successful);
  EXPECT_EQ(store().results(done).size(), 1u);
}

TEST_P(StoreContract, ListFiltersByNameAndIdsResolveFromPrefixes) {
  const auto a = store().submit(job("alpha"), 10).job.id;
  const auto b = store().submit(job("beta"), 10).job.id;
  const auto a2 = store().submit(job("alpha"), 10).job.id;
  const auto alphas = store().list({}, "alpha", 10);
  ASSERT_EQ(alphas.size(), 2u);
  EXPECT_EQ(alphas[0].id, a2);
  EXPECT_EQ(alphas[1].id, a);
  EXPECT_EQ(store().list({JobStatus::accepted}, "beta", 10).at(0).id, b);
  EXPECT_TRUE(store().list({}, "gamma", 10).empty());
  EXPECT_EQ(store().ids_with_prefix(a.substr(0, 8), 5), (std::vector<std::string>{a, b, a2}));
  EXPECT_EQ(store().ids_with_prefix(b, 5), std::vector<std::string>{b});
  EXPECT_EQ(store().ids_with_prefix("", 5).size(), 3u);
  EXPECT_EQ(store().ids_with_prefix("", 2).size(), 2u);
  EXPECT_TRUE(store().ids_with_prefix("zzzz", 5).empty());
  EXPECT_TRUE(store().ids_with_prefix("%", 5).empty());  // matched as text, not a pattern
}

TEST_P(StoreContract, IdempotencyKeyReplaysSameBodyAndRejectsAnother) {
  const auto first = store().submit(job("i", "key-1", "hash-a"), 10);
  EXPECT_EQ(first.outcome, SubmitOutcome::created);
  const auto again = store().submit(job("i", "key-1", "hash-a"), 10);
  EXPECT_EQ(again.outcome, SubmitOutcome::replayed);
  EXPECT_EQ(again.job.id, first.job.id);
  const auto other = store().submit(job("i", "key-1", "hash-b"), 10);
  EXPECT_EQ(other.outcome, SubmitOutcome::key_conflict);
  EXPECT_EQ(store().list({}, "", 10).size(), 1u);
}

TEST_P(StoreContract, QueueCapCountsOnlyWaitingJobs) {
  EXPECT_EQ(store().submit(job("q1"), 2).outcome, SubmitOutcome::created);
  EXPECT_EQ(store().submit(job("q2"), 2).outcome, SubmitOutcome::created);
  EXPECT_EQ(store().submit(job("q3"), 2).outcome, SubmitOutcome::queue_full);
  store().claim_next(live());  // one leaves the queue
  EXPECT_EQ(store().submit(job("q4"), 2).outcome, SubmitOutcome::created);
}

// The fix of the two-servers-on-one-database data loss, at the store level:
// recovery must leave a job alone while its owner's lease is live.
TEST_P(StoreContract, RecoveryDoesNotRequeueAJobWhoseLeaseIsLive) {
  const auto id = store().submit(job("owned"), 10).job.id;
  const auto claimed = store().claim_next(live());
  const auto report = store().recover(3, 0.0);
  EXPECT_TRUE(report.requeued.empty());
  EXPECT_TRUE(report.failed.empty());
  const auto job = store().find(id);
  EXPECT_EQ(job->status, JobStatus::running);
  EXPECT_EQ(job->owner, live().instance);
  EXPECT_EQ(store().update_progress(claim_of(*claimed), 5), ClaimState::held);
}

TEST_P(StoreContract, RenewedLeasesStayLiveAndOnlyTheOwnersAreRenewed) {
  const auto mine = store().submit(job("mine"), 10).job.id;
  const auto theirs = store().submit(job("theirs"), 10).job.id;
  store().claim_next(dead("me"));
  store().claim_next(dead("them"));
  EXPECT_EQ(store().renew_leases(Claimant{"me", 600.0}), 1);
  const auto report = store().recover(3, 0.0);
  ASSERT_EQ(report.requeued.size(), 1u);
  EXPECT_EQ(report.requeued[0], theirs);
  EXPECT_EQ(store().find(mine)->status, JobStatus::running);
  EXPECT_EQ(store().find(theirs)->status, JobStatus::accepted);
}

TEST_P(StoreContract, ATakenOverJobRefusesTheWritesOfItsEarlierClaim) {
  const auto id = store().submit(job("taken-over"), 10).job.id;
  const Claim stale = claim_of(*store().claim_next(dead("paused")));
  ASSERT_EQ(store().recover(3, 0.0).requeued.size(), 1u);
  const Claim current = claim_of(*store().claim_next(live()));
  EXPECT_GT(current.token, stale.token);
  EXPECT_EQ(store().update_progress(stale, 99), ClaimState::lost);
  EXPECT_EQ(store().finish(stale, JobEnd{JobStatus::failed, "late", "late", {}, 1, {}}),
            ClaimState::lost);
  EXPECT_EQ(store().requeue(stale), ClaimState::lost);
  EXPECT_EQ(store().find(id)->status, JobStatus::running);
  EXPECT_EQ(store().find(id)->owner, live().instance);
  EXPECT_EQ(store().finish(current, JobEnd{JobStatus::successful, "finished", "", {}, 1, {}}),
            ClaimState::held);
}

// The attempt limit counts only crashes that can be the job's: an attempt
// that had run at least charge_after_s (claim to its last renewal or
// progress write) is charged; one claimed just before an unrelated crash is
// not, however often that happens, until the backstop of
// uncharged_start_factor * max_attempts starts.
TEST_P(StoreContract, RecoveryChargesACrashOnlyToAnAttemptThatRanLongEnough) {
  const std::string innocent = store().submit(job("innocent"), 10).job.id;
  const int backstop = uncharged_start_factor * 3;
  for (int start = 1; start < backstop; ++start) {
    const auto claimed = store().claim_next(dead());
    ASSERT_TRUE(claimed);
    ASSERT_EQ(claimed->id, innocent);
    advance(std::chrono::seconds(5));
    EXPECT_EQ(store().update_progress(claim_of(*claimed), 1), ClaimState::held);  // alive at 5 s
    advance(std::chrono::seconds(60));  // ... and dies there, 5 s into the attempt
    const auto report = store().recover(3, 30.0);
    ASSERT_EQ(report.requeued.size(), 1u) << "start " << start;
    EXPECT_EQ(store().find(innocent)->message, "queued again: the server stopped while it ran");
  }
  // The backstop: started backstop times, each crash within 30 s.
  ASSERT_TRUE(store().claim_next(dead()));
  advance(std::chrono::seconds(60));
  const auto stopped = store().recover(3, 30.0);
  ASSERT_EQ(stopped.failed.size(), 1u);
  // One policy for every backend (store/recovery.cpp), so one wording.
  EXPECT_EQ(store().find(innocent)->failure_reason,
            "this job was started " + std::to_string(backstop) +
                " times and the server stopped every time, mostly within 30 s of the start "
                "(limit 9 starts); not retried");

  // A job whose attempts ran 40 s before each crash is charged every time.
  const std::string suspect = store().submit(job("suspect"), 10).job.id;
  for (int crash = 1; crash <= 3; ++crash) {
    const auto claimed = store().claim_next(dead());
    ASSERT_TRUE(claimed);
    ASSERT_EQ(claimed->id, suspect);
    advance(std::chrono::seconds(40));
    store().update_progress(claim_of(*claimed), 50);
    advance(std::chrono::seconds(60));
    const auto report = store().recover(3, 30.0);
    EXPECT_EQ(report.failed.size(), crash == 3 ? 1u : 0u) << "crash " << crash;
  }
  EXPECT_EQ(store().find(suspect)->status, JobStatus::failed);
  EXPECT_EQ(store().find(suspect)->failure_reason,
            "the server stopped 3 times while this job ran (each time after at least 30 s of its "
            "attempt; limit 3 attempts); not retried");
}

TEST_P(StoreContract, RecoveryRequeuesLapsedJobsUntilTheAttemptLimit) {
  const std::string id = store().submit(job("crashy"), 10).job.id;
  store().submit(job("waiting"), 10);
  for (int attempt = 1; attempt <= 3; ++attempt) {
    const auto report = store().recover(3, 0.0);  // a new process starts
    if (attempt > 1) {
      ASSERT_EQ(report.requeued.size(), 1u);
      EXPECT_EQ(report.requeued[0], id);
    }
    const auto claimed = store().claim_next(dead());
    ASSERT_TRUE(claimed);
    EXPECT_EQ(claimed->id, id);  // FIFO: the interrupted job keeps its place
    EXPECT_EQ(claimed->attempts, attempt);
    // ... and the process dies here, leaving the job running with its lease lapsing.
  }
  const auto report = store().recover(3, 0.0);
  EXPECT_TRUE(report.requeued.empty());
  ASSERT_EQ(report.failed.size(), 1u);
  const auto failed = store().find(id);
  EXPECT_EQ(failed->status, JobStatus::failed);
  EXPECT_NE(failed->failure_reason.find("3 times"), std::string::npos) << failed->failure_reason;
  EXPECT_FALSE(failed->finished.empty());
  EXPECT_EQ(store().count_by_status()[JobStatus::accepted], 1);  // the other job still waits
  EXPECT_EQ(store().count_by_status().count(JobStatus::running), 0u);
}

TEST_P(StoreContract, GracefulRequeueDoesNotCountTheAttempt) {
  const auto id = store().submit(job("r"), 10).job.id;
  const Claim claim = claim_of(*store().claim_next(live()));
  EXPECT_EQ(store().requeue(claim), ClaimState::held);
  const auto back = store().find(id);
  EXPECT_EQ(back->status, JobStatus::accepted);
  EXPECT_EQ(back->attempts, 0);
  EXPECT_TRUE(back->started.empty());
  EXPECT_EQ(store().requeue(claim), ClaimState::lost);  // not running any more
}

TEST_P(StoreContract, ListFiltersByStatusNewestFirst) {
  const auto a = store().submit(job("a"), 10).job.id;
  const auto b = store().submit(job("b"), 10).job.id;
  const auto c = store().submit(job("c"), 10).job.id;
  store().claim_next(live());  // a runs
  const auto all = store().list({}, "", 10);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].id, c);
  EXPECT_EQ(store().list({}, "", 2).size(), 2u);
  const auto waiting = store().list({JobStatus::accepted}, "", 10);
  ASSERT_EQ(waiting.size(), 2u);
  EXPECT_EQ(waiting[1].id, b);
  EXPECT_EQ(store().list({JobStatus::running, JobStatus::failed}, "", 10).at(0).id, a);
}

TEST_P(StoreContract, EveryStatusOfTheTableIsStoredAndCounted) {
  // One job per row of job_statuses, each driven there through the interface.
  const auto ok = store().submit(job("successful"), 10).job.id;
  const auto bad = store().submit(job("failed"), 10).job.id;
  const auto running = store().submit(job("running"), 10).job.id;
  store().submit(job("accepted"), 10);
  store().dismiss(store().submit(job("dismissed"), 10).job.id);
  const Claim c_ok = claim_of(*store().claim_next(live()));
  const Claim c_bad = claim_of(*store().claim_next(live()));
  const auto c_running = store().claim_next(live());
  ASSERT_EQ(c_ok.job_id, ok);
  ASSERT_EQ(c_bad.job_id, bad);
  ASSERT_EQ(c_running->id, running);
  store().finish(c_ok, JobEnd{JobStatus::successful, "finished", "", {}, 1, {}});
  store().finish(c_bad, JobEnd{JobStatus::failed, "boom", "boom", {}, 1, {}});
  const auto counts = store().count_by_status();
  for (const auto& row : job_statuses) {
    EXPECT_EQ(counts.count(row.status) ? counts.at(row.status) : 0, 1) << row.name;
    const auto listed = store().list({row.status}, "", 10);
    ASSERT_EQ(listed.size(), 1u) << row.name;
    EXPECT_EQ(listed[0].name, row.name);
  }
}

TEST_P(StoreContract, PurgeForgetsOnlyJobsThatEndedBeforeTheCutoff) {
  using std::chrono::hours;
  const std::vector<ResultFile> files{
      {"summary.json", 10, std::string(64, 'a'), "application/json"}};
  // Ten days ago: one job of each ended kind, plus one still queued and one
  // still running (never purged, however old).
  const auto finished_old = store().submit(job("old-ok", "done-key", "h1"), 100).job.id;
  const auto c_ok = claim_of(*store().claim_next(live()));
  store().finish(c_ok, JobEnd{JobStatus::successful, "finished", "", files, 1, {}});
  const auto failed_old = store().submit(job("old-failed"), 100).job.id;
  const auto c_bad = claim_of(*store().claim_next(live()));
  store().finish(c_bad, JobEnd{JobStatus::failed, "boom", "boom", {}, 1, {}});
  const auto cancelled_old = store().submit(job("old-cancelled"), 100).job.id;
  store().cancel(cancelled_old);
  const auto deleted_old = store().submit(job("old-deleted"), 100).job.id;
  store().dismiss(deleted_old);
  const auto running_old = store().submit(job("old-running"), 100).job.id;
  const auto c_run = claim_of(*store().claim_next(live()));
  ASSERT_EQ(c_run.job_id, running_old);
  const auto queued_old = store().submit(job("old-queued"), 100).job.id;
  advance(hours(24 * 10));
  // Today: ended jobs that are recent.
  const auto finished_new = store().submit(job("new-ok"), 100).job.id;
  const auto c_queued = claim_of(*store().claim_next(live()));  // FIFO: the old queued job
  const auto c_new = claim_of(*store().claim_next(live()));
  ASSERT_EQ(c_new.job_id, finished_new);
  ASSERT_EQ(store().requeue(c_queued), ClaimState::held);  // back in the queue
  store().finish(c_new, JobEnd{JobStatus::successful, "finished", "", files, 1, {}});
  const auto cancelled_new = store().submit(job("new-cancelled"), 100).job.id;
  store().cancel(cancelled_new);
  const auto queued_new = store().submit(job("new-queued"), 100).job.id;

  // A cutoff five days back takes exactly the four old ended jobs.
  const auto purged = store().purge_ended(now() - hours(24 * 5));
  EXPECT_EQ(purged,
            (std::vector<std::string>{finished_old, failed_old, cancelled_old, deleted_old}));
  for (const auto& id : purged) {
    EXPECT_FALSE(store().find(id)) << id;
    EXPECT_TRUE(store().results(id).empty()) << id;
    EXPECT_TRUE(store().ids_with_prefix(id, 5).empty()) << id;
  }
  for (const auto& id : {running_old, queued_old, finished_new, cancelled_new, queued_new}) {
    EXPECT_TRUE(store().find(id)) << id;
  }
  EXPECT_EQ(store().results(finished_new).size(), 1u);
  EXPECT_TRUE(store().purge_ended(now() - hours(24 * 5)).empty()) << "a second purge finds nothing";

  // A cutoff in the future takes every ended job but never a queued or
  // running one; the old running job still finishes under its claim.
  const auto later = store().purge_ended(now() + hours(1));
  EXPECT_EQ(later, (std::vector<std::string>{finished_new, cancelled_new}));
  EXPECT_EQ(store().find(running_old)->status, JobStatus::running);
  EXPECT_EQ(store().find(queued_old)->status, JobStatus::accepted);
  EXPECT_EQ(store().find(queued_new)->status, JobStatus::accepted);
  EXPECT_EQ(store().finish(c_run, JobEnd{JobStatus::successful, "finished", "", {}, 1, {}}),
            ClaimState::held);
  // The purge survives a reopen, and the counts agree.
  close();
  EXPECT_FALSE(store().find(finished_old));
  const auto counts = store().count_by_status();
  EXPECT_EQ(counts.count(JobStatus::failed) ? counts.at(JobStatus::failed) : 0, 0);
  EXPECT_EQ(store().list({}, "", 100).size(), 3u);
  // A purged job's idempotency key is free again: the same key makes a new job.
  EXPECT_EQ(store().submit(job("again", "done-key", "h2"), 100).outcome, SubmitOutcome::created);
}

CheckpointRecord checkpoint_at(std::int64_t step, const Claim& claim) {
  return CheckpointRecord{"checkpoint-" + std::to_string(claim.token) + "-" + std::to_string(step),
                          step,
                          0.5 * static_cast<double>(step),
                          1000 + step,
                          std::string(64, 'c'),
                          "2026-12-02T12:00:00.000Z"};
}

// Checkpoints: written under the claim like progress, replaced by the next
// one, kept while the job waits to be resumed (requeue, recovery after a
// crash, the next claim), forgotten when the job ends.
TEST_P(StoreContract, CheckpointsAreFencedKeptForTheNextAttemptAndClearedAtTheEnd) {
  const auto id = store().submit(job("checkpointed"), 10).job.id;
  EXPECT_FALSE(store().checkpoint(id));
  EXPECT_FALSE(store().checkpoint("no-such-job"));
  const Claim never{id, live().instance, 1};
  EXPECT_EQ(store().record_checkpoint(never, checkpoint_at(1, never)), ClaimState::lost);
  EXPECT_FALSE(store().checkpoint(id));

  const Claim first = claim_of(*store().claim_next(live()));
  EXPECT_EQ(store().record_checkpoint(first, checkpoint_at(10, first)), ClaimState::held);
  EXPECT_EQ(store().record_checkpoint(first, checkpoint_at(20, first)), ClaimState::held);
  auto kept = store().checkpoint(id);
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->file, checkpoint_at(20, first).file);
  EXPECT_EQ(kept->step, 20);
  EXPECT_DOUBLE_EQ(kept->time, 10.0);
  EXPECT_EQ(kept->size, 1020);
  EXPECT_EQ(kept->sha256, std::string(64, 'c'));
  EXPECT_EQ(kept->written, "2026-12-02T12:00:00.000Z");

  // Requeued (graceful stop): kept, and the next claim resumes from it.
  EXPECT_EQ(store().requeue(first), ClaimState::held);
  EXPECT_EQ(store().checkpoint(id)->step, 20);
  EXPECT_EQ(store().record_checkpoint(first, checkpoint_at(30, first)), ClaimState::lost);
  const Claim second = claim_of(*store().claim_next(dead("crashed")));
  EXPECT_EQ(store().checkpoint(id)->step, 20);
  EXPECT_EQ(store().record_checkpoint(second, checkpoint_at(40, second)), ClaimState::held);
  // Recovered after a crash: kept; the crashed claim's writes are refused.
  ASSERT_EQ(store().recover(5, 0.0).requeued.size(), 1u);
  EXPECT_EQ(store().checkpoint(id)->step, 40);
  const Claim third = claim_of(*store().claim_next(live()));
  EXPECT_EQ(store().record_checkpoint(second, checkpoint_at(50, second)), ClaimState::lost);
  EXPECT_EQ(store().checkpoint(id)->file, checkpoint_at(40, second).file);
  close();  // durable
  EXPECT_EQ(store().checkpoint(id)->step, 40);
  EXPECT_EQ(store().record_checkpoint(third, checkpoint_at(60, third)), ClaimState::held);

  EXPECT_EQ(store().finish(third, JobEnd{JobStatus::successful, "finished", "", {}, 1, {}}),
            ClaimState::held);
  EXPECT_FALSE(store().checkpoint(id));
  EXPECT_EQ(store().record_checkpoint(third, checkpoint_at(70, third)), ClaimState::lost);
  EXPECT_FALSE(store().checkpoint(id));
}

TEST_P(StoreContract, ACancelledOrDeletedJobForgetsItsCheckpointAndRefusesNewOnes) {
  for (bool deleted : {false, true}) {
    const auto id = store().submit(job("stopped"), 10).job.id;
    const Claim claim = claim_of(*store().claim_next(live()));
    EXPECT_EQ(store().record_checkpoint(claim, checkpoint_at(5, claim)), ClaimState::held);
    if (deleted)
      store().dismiss(id);
    else
      store().cancel(id);
    EXPECT_FALSE(store().checkpoint(id)) << (deleted ? "deleted" : "cancelled");
    EXPECT_EQ(store().record_checkpoint(claim, checkpoint_at(6, claim)), ClaimState::dismissed);
    EXPECT_FALSE(store().checkpoint(id));
  }
}

TEST_P(StoreContract, AJobFailedByRecoveryForgetsItsCheckpoint) {
  const auto id = store().submit(job("crashing"), 10).job.id;
  const Claim claim = claim_of(*store().claim_next(dead("crashed")));
  EXPECT_EQ(store().record_checkpoint(claim, checkpoint_at(5, claim)), ClaimState::held);
  ASSERT_EQ(store().recover(1, 0.0).failed.size(), 1u);  // attempts 1 >= max 1
  EXPECT_FALSE(store().checkpoint(id));
}

// Ensembles: stored with all their samples or not at all (the queue cap
// counts every sample); the samples are ordinary jobs in index order that
// know their ensemble; an idempotency key replays the whole ensemble; the
// state survives a reopen; an ensemble goes with its last purged sample.
TEST_P(StoreContract, AnEnsembleIsStoredWithAllItsSamplesAsOrdinaryJobs) {
  store().submit(job("before"), 100);
  // Over the cap: nothing at all is stored.
  const NewEnsemble too_many = ensemble(10);
  EXPECT_EQ(store().submit_ensemble(too_many, 10).outcome, SubmitOutcome::queue_full);
  EXPECT_FALSE(store().find_ensemble(too_many.id));
  for (const NewJob& j : too_many.samples) EXPECT_FALSE(store().find(j.id));
  EXPECT_EQ(store().list({}, "", 100).size(), 1u);

  const NewEnsemble e = ensemble(4, "ens-key", "h1");
  const auto created = store().submit_ensemble(e, 100);
  ASSERT_EQ(created.outcome, SubmitOutcome::created);
  EXPECT_EQ(created.ensemble.id, e.id);
  EXPECT_EQ(created.ensemble.request, e.request);
  EXPECT_EQ(created.ensemble.seed, 42);
  EXPECT_EQ(created.ensemble.samples, 4);
  EXPECT_EQ(created.ensemble.state, EnsembleState::active);
  EXPECT_FALSE(created.ensemble.created.empty());
  ASSERT_EQ(created.ensemble.jobs.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const EnsembleSample& sample = created.ensemble.jobs[static_cast<std::size_t>(k)];
    EXPECT_EQ(sample.index, k);
    EXPECT_EQ(sample.job_id, e.samples[static_cast<std::size_t>(k)].id);
    EXPECT_EQ(sample.status, JobStatus::accepted);
    const auto j = store().find(sample.job_id);
    ASSERT_TRUE(j);
    EXPECT_EQ(j->ensemble_id, e.id);
    EXPECT_EQ(j->ensemble_index, k);
    EXPECT_EQ(j->name, "sample-" + std::to_string(k));
  }
  EXPECT_EQ(store().find(store().list({}, "before", 1).at(0).id)->ensemble_index, -1);
  EXPECT_TRUE(store().find(store().list({}, "before", 1).at(0).id)->ensemble_id.empty());
  // The samples queue like any job (FIFO after the job before them).
  const auto first = store().claim_next(live());
  ASSERT_TRUE(first);
  EXPECT_EQ(first->name, "before");
  const auto sample0 = store().claim_next(live());
  ASSERT_TRUE(sample0);
  EXPECT_EQ(sample0->id, e.samples[0].id);
  store().update_progress(claim_of(*sample0), 40);
  auto found = store().find_ensemble(e.id);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->jobs[0].status, JobStatus::running);
  EXPECT_DOUBLE_EQ(found->jobs[0].progress, 40);
  EXPECT_EQ(found->jobs[0].attempts, 1);

  // The key replays the whole ensemble; another body under it is a conflict.
  NewEnsemble again = ensemble(4, "ens-key", "h1");
  const auto replayed = store().submit_ensemble(again, 100);
  EXPECT_EQ(replayed.outcome, SubmitOutcome::replayed);
  EXPECT_EQ(replayed.ensemble.id, e.id);
  EXPECT_FALSE(store().find(again.samples[0].id));
  EXPECT_EQ(store().submit_ensemble(ensemble(4, "ens-key", "h2"), 100).outcome,
            SubmitOutcome::key_conflict);

  // Newest first; the state is kept, and deleted stays deleted.
  const NewEnsemble later = ensemble(2);
  ASSERT_EQ(store().submit_ensemble(later, 100).outcome, SubmitOutcome::created);
  const auto listed = store().list_ensembles(10);
  ASSERT_EQ(listed.size(), 2u);
  EXPECT_EQ(listed[0].id, later.id);
  EXPECT_EQ(listed[1].id, e.id);
  EXPECT_EQ(listed[1].jobs.size(), 4u);
  EXPECT_EQ(store().list_ensembles(1).size(), 1u);
  EXPECT_FALSE(store().find_ensemble("no-such-ensemble"));
  EXPECT_FALSE(store().set_ensemble_state("no-such-ensemble", EnsembleState::cancelled));
  const auto before = store().set_ensemble_state(e.id, EnsembleState::cancelled);
  ASSERT_TRUE(before);
  EXPECT_EQ(before->state, EnsembleState::active);
  EXPECT_EQ(store().set_ensemble_state(e.id, EnsembleState::deleted)->state,
            EnsembleState::cancelled);
  EXPECT_EQ(store().set_ensemble_state(e.id, EnsembleState::cancelled)->state,
            EnsembleState::deleted);
  close();
  EXPECT_EQ(store().find_ensemble(e.id)->state, EnsembleState::deleted);
  EXPECT_EQ(store().find_ensemble(later.id)->state, EnsembleState::active);
  EXPECT_EQ(store().find_ensemble(e.id)->jobs.size(), 4u);
}

TEST_P(StoreContract, AnEnsembleGoesWithItsLastPurgedSample) {
  using std::chrono::hours;
  const NewEnsemble e = ensemble(2);
  ASSERT_EQ(store().submit_ensemble(e, 100).outcome, SubmitOutcome::created);
  store().cancel(e.samples[0].id);
  advance(hours(24 * 10));
  EXPECT_EQ(store().purge_ended(now() - hours(24)), std::vector<std::string>{e.samples[0].id});
  const auto left = store().find_ensemble(e.id);
  ASSERT_TRUE(left) << "one sample is still queued";
  ASSERT_EQ(left->jobs.size(), 1u);
  EXPECT_EQ(left->jobs[0].index, 1);
  EXPECT_EQ(left->samples, 2);
  store().cancel(e.samples[1].id);
  advance(hours(24 * 10));
  EXPECT_EQ(store().purge_ended(now() - hours(24)), std::vector<std::string>{e.samples[1].id});
  EXPECT_FALSE(store().find_ensemble(e.id));
  EXPECT_TRUE(store().list_ensembles(10).empty());
}

TEST_P(StoreContract, ConcurrentWritersNeverFail) {
  constexpr int threads = 8;
  constexpr int per_thread = 40;
  JobStore& s = store();
  std::vector<std::thread> pool;
  pool.reserve(threads);
  std::atomic<int> failures{0};
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&, t] {
      for (int i = 0; i < per_thread; ++i) {
        try {
          NewJob j = job("concurrent");
          j.id = "10000000-0000-4000-8000-";
          j.id += std::to_string(100000000000 + t * 1000L + i);
          s.submit(j, 100000);
          if (auto claimed = s.claim_next(live())) s.update_progress(claim_of(*claimed), 1);
          s.list({}, "", 5);
        } catch (const StoreFailure&) {
          ++failures;
        }
      }
    });
  }
  for (auto& t : pool) t.join();
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(s.list({}, "", 1000).size(), static_cast<std::size_t>(threads * per_thread));
}

}  // namespace
}  // namespace hmpm::server::testing
