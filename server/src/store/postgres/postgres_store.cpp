// postgres_store.cpp — see postgres_store.hpp; the contract is in store.hpp.
//
// Status names in SQL come from the job-status table (`sql_name`), never
// from literals. A write of a running job is one UPDATE whose WHERE matches
// its claim ($1 job id, $2 owner, $3 token); when it matches nothing,
// `claim_state` tells dismissal from a lost claim. Each claim is also a row
// of job_attempts, ended by finish, requeue, dismissal or recovery.
#include "postgres_store.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "clock.hpp"
#include "migrate.hpp"
#include "store/recovery.hpp"

namespace hmpm::server::postgres {
namespace {

// 'running', quoted for SQL.
std::string sql_name(JobStatus status) {
  return std::string("'") + status_name(status) + "'";
}

const std::string ended_statuses = "(" + sql_name(JobStatus::successful) + "," +
                                   sql_name(JobStatus::failed) + "," +
                                   sql_name(JobStatus::dismissed) + ")";

// pg_advisory_xact_lock key that serialises submissions, so the queue cap
// and the idempotency-key check hold across servers ("hmpn" in ASCII).
constexpr const char* submit_lock = "SELECT pg_advisory_xact_lock(1752001902)";

// The last column is an accepted job's place in the queue (1: next); in a
// RETURNING clause the subquery sees the rows as they were before.
const std::string job_columns =
    "id, seq, name, spec, status, progress, message, created, coalesce(started, ''), "
    "coalesce(finished, ''), updated, attempts, coalesce(failure_reason, ''), cost_particles, "
    "cost_nodes, cost_cells, cost_steps, cost_particle_steps, cost_memory_bytes, "
    "cost_output_bytes, cost_dt, run_seconds, coalesce(owner, ''), lease_token, "
    "lease_expires_ms, results_deleted, run_time, run_end_time, run_steps, run_dt_min, "
    "run_dt_max, coalesce(ensemble_id, ''), ensemble_index, CASE WHEN jobs.status = " +
    sql_name(JobStatus::accepted) +
    " THEN 1 + (SELECT count(*) FROM jobs AS ahead WHERE ahead.status = " +
    sql_name(JobStatus::accepted) + " AND ahead.seq < jobs.seq) ELSE 0 END";

// Forgets what an earlier attempt's run reached (part of an UPDATE's SET).
constexpr const char* no_run =
    "run_time = 0, run_end_time = 0, run_steps = 0, run_dt_min = 0, run_dt_max = 0, ";

// Clears the checkpoint of a job that ends (part of an UPDATE's SET).
constexpr const char* no_checkpoint =
    "checkpoint_file = NULL, checkpoint_step = 0, checkpoint_time = 0, checkpoint_size = 0, "
    "checkpoint_sha256 = NULL, checkpoint_written = NULL";

JobRecord read_job(const Result& r, int row) {
  JobRecord job;
  int c = 0;
  auto text = [&] { return r.text(row, c++); };
  auto integer = [&] { return r.integer(row, c++); };
  auto real = [&] { return r.real(row, c++); };
  job.id = text();
  job.seq = integer();
  job.name = text();
  job.spec = text();
  job.status = parse_status(text()).value_or(JobStatus::failed);
  job.progress = real();
  job.message = text();
  job.created = text();
  job.started = text();
  job.finished = text();
  job.updated = text();
  job.attempts = static_cast<int>(integer());
  job.failure_reason = text();
  for (std::int64_t* cost :
       {&job.cost.particles, &job.cost.nodes, &job.cost.cells, &job.cost.steps,
        &job.cost.particle_steps, &job.cost.memory_bytes, &job.cost.output_bytes}) {
    *cost = integer();
  }
  job.cost.dt = real();
  job.run_seconds = real();
  job.owner = text();
  job.lease_token = integer();
  job.lease_expires_ms = integer();
  job.results_deleted = r.boolean(row, c++);
  job.run.percent = job.progress;
  job.run.time = real();
  job.run.end_time = real();
  job.run.steps = integer();
  job.run.dt_min = real();
  job.run.dt_max = real();
  job.ensemble_id = text();
  job.ensemble_index = static_cast<int>(integer());
  job.queue_position = integer();
  return job;
}

std::optional<JobRecord> select_job(PGconn* db, const std::string& id, bool for_update = false) {
  const Result r = exec(
      db, "SELECT " + job_columns + " FROM jobs WHERE id = $1" + (for_update ? " FOR UPDATE" : ""),
      Params().add(id));
  if (r.rows() == 0) return std::nullopt;
  return read_job(r, 0);
}

// The condition a write of a running job must meet: its claim is current.
const std::string claim_held =
    "id = $1 AND status = " + sql_name(JobStatus::running) + " AND owner = $2 AND lease_token = $3";

Params claim_params(const Claim& claim) {
  Params p;
  p.add(claim.job_id).add(claim.owner).add(claim.token);
  return p;
}

// Why a claimed write matched no row.
ClaimState claim_state(PGconn* db, const Claim& claim) {
  const auto job = select_job(db, claim.job_id);
  return job && job->status == JobStatus::dismissed ? ClaimState::dismissed : ClaimState::lost;
}

// Ends the attempt row of `claim` (if still open) with `outcome`.
void end_attempt(PGconn* db, const Claim& claim, const char* outcome, const std::string& now) {
  exec(db,
       "UPDATE job_attempts SET ended = $3, outcome = $4 WHERE job_id = $1 AND token = $2 AND "
       "ended IS NULL",
       Params().add(claim.job_id).add(claim.token).add(now).add(outcome));
}

// Ends every open attempt row of job `id` (dismissal, recovery).
void end_attempts(PGconn* db, const std::string& id, const char* outcome, const std::string& now) {
  exec(db, "UPDATE job_attempts SET ended = $2, outcome = $3 WHERE job_id = $1 AND ended IS NULL",
       Params().add(id).add(now).add(outcome));
}

void replace_results(PGconn* db, const std::string& id, const std::vector<ResultFile>& files) {
  exec(db, "DELETE FROM results WHERE job_id = $1", Params().add(id));
  for (const ResultFile& f : files) {
    exec(db,
         "INSERT INTO results (job_id, name, size, sha256, media_type) VALUES ($1, $2, $3, $4, $5)",
         Params().add(id).add(f.name).add(f.size).add(f.sha256).add(f.media_type));
  }
}

// Inserts `job` as accepted (sample `index` of ensemble `ensemble` when
// that is not empty), created at `now`; returns the new row.
Result insert_job(PGconn* db, const NewJob& job, const std::string& now,
                  const std::string& ensemble = "", int index = -1) {
  Params p;
  p.add(job.id).add(job.name).add(job.spec).add(now);
  p.add_or_null(job.idempotency_key).add_or_null(job.body_sha256);
  p.add(job.cost.particles).add(job.cost.nodes).add(job.cost.cells).add(job.cost.steps);
  p.add(job.cost.particle_steps).add(job.cost.memory_bytes).add(job.cost.output_bytes);
  p.add(job.cost.dt).add_or_null(ensemble).add(std::int64_t{index});
  return exec(db,
              "INSERT INTO jobs (id, name, spec, status, message, created, updated, "
              "idempotency_key, body_sha256, cost_particles, cost_nodes, cost_cells, cost_steps, "
              "cost_particle_steps, cost_memory_bytes, cost_output_bytes, cost_dt, ensemble_id, "
              "ensemble_index) VALUES ($1, $2, $3, " +
                  sql_name(JobStatus::accepted) +
                  ", 'queued', $4, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16) "
                  "RETURNING " +
                  job_columns,
              p);
}

const char* const ensemble_columns =
    "id, seq, request, seed, samples, state, created, updated FROM ensembles";

EnsembleRecord read_ensemble(const Result& r, int row) {
  EnsembleRecord e;
  e.id = r.text(row, 0);
  e.seq = r.integer(row, 1);
  e.request = r.text(row, 2);
  e.seed = r.integer(row, 3);
  e.samples = static_cast<int>(r.integer(row, 4));
  e.state = parse_ensemble_state(r.text(row, 5));
  e.created = r.text(row, 6);
  e.updated = r.text(row, 7);
  return e;
}

// Fills e.jobs from the jobs table.
void read_samples(PGconn* db, EnsembleRecord& e) {
  const Result r = exec(db,
                        "SELECT ensemble_index, id, status, progress, attempts, results_deleted "
                        "FROM jobs WHERE ensemble_id = $1 ORDER BY ensemble_index",
                        Params().add(e.id));
  e.jobs.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) {
    e.jobs.push_back({static_cast<int>(r.integer(i, 0)), r.text(i, 1),
                      parse_status(r.text(i, 2)).value_or(JobStatus::failed), r.real(i, 3),
                      static_cast<int>(r.integer(i, 4)), r.boolean(i, 5)});
  }
}

std::optional<EnsembleRecord> select_ensemble(PGconn* db, const std::string& id,
                                              bool for_update = false) {
  const Result r = exec(db,
                        std::string("SELECT ") + ensemble_columns + " WHERE id = $1" +
                            (for_update ? " FOR UPDATE" : ""),
                        Params().add(id));
  if (r.rows() == 0) return std::nullopt;
  EnsembleRecord e = read_ensemble(r, 0);
  read_samples(db, e);
  return e;
}

}  // namespace

std::chrono::system_clock::time_point PostgresStore::now() const {
  return clock_ ? clock_() : std::chrono::system_clock::now();
}

std::string PostgresStore::now_text() const {
  return format_rfc3339(now());
}

std::int64_t PostgresStore::now_ms() const {
  return std::chrono::duration_cast<std::chrono::milliseconds>(now().time_since_epoch()).count();
}

std::int64_t PostgresStore::lease_until(const Claimant& who) const {
  return now_ms() + static_cast<std::int64_t>(who.lease_s * 1000.0);
}

PostgresStore::PostgresStore(const std::string& uri, WallClock clock)
    : clock_(std::move(clock)), pool_(uri) {
  auto connection = pool_.lease();
  migrate(connection.get());
}

void PostgresStore::probe() {
  auto db = pool_.lease();
  recorded_version(db.get());
}

SubmitResult PostgresStore::submit(const NewJob& job, std::int64_t max_queue) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  exec(db, submit_lock);
  if (!job.idempotency_key.empty()) {
    const Result r = exec(db, "SELECT id, body_sha256 FROM jobs WHERE idempotency_key = $1",
                          Params().add(job.idempotency_key));
    if (r.rows() > 0) {
      const bool same_body = r.text(0, 1) == job.body_sha256;
      auto earlier = select_job(db, r.text(0, 0));
      tx.commit();
      return {same_body ? SubmitOutcome::replayed : SubmitOutcome::key_conflict,
              std::move(*earlier)};
    }
  }
  if (exec(db, "SELECT count(*) FROM jobs WHERE status = " + sql_name(JobStatus::accepted))
          .integer(0, 0) >= max_queue) {
    return {SubmitOutcome::queue_full, {}};
  }
  JobRecord created = read_job(insert_job(db, job, now_text()), 0);
  tx.commit();
  return {SubmitOutcome::created, std::move(created)};
}

std::optional<JobRecord> PostgresStore::find(const std::string& id) {
  auto db = pool_.lease();
  return select_job(db.get(), id);
}

std::vector<JobRecord> PostgresStore::list(const std::vector<JobStatus>& statuses,
                                           const std::string& name, int limit) {
  std::string sql = "SELECT " + job_columns + " FROM jobs WHERE ($2 = '' OR name = $2)";
  if (!statuses.empty()) {
    sql += " AND status IN (";
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      if (i > 0) sql += ",";
      sql += sql_name(statuses[i]);
    }
    sql += ")";
  }
  sql += " ORDER BY seq DESC LIMIT $1";
  auto db = pool_.lease();
  const Result r = exec(db.get(), sql, Params().add(std::int64_t{limit}).add(name));
  std::vector<JobRecord> out;
  out.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) out.push_back(read_job(r, i));
  return out;
}

std::vector<std::string> PostgresStore::ids_with_prefix(const std::string& prefix, int limit) {
  auto db = pool_.lease();
  // left(), not LIKE: the prefix is matched as text, whatever it holds.
  const Result r =
      exec(db.get(), "SELECT id FROM jobs WHERE left(id, length($1)) = $1 ORDER BY seq LIMIT $2",
           Params().add(prefix).add(std::int64_t{limit}));
  std::vector<std::string> out;
  out.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
  return out;
}

std::optional<JobRecord> PostgresStore::claim_next(const Claimant& who) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  const std::string now = now_text();
  // SKIP LOCKED: a row another server is claiming right now is passed over,
  // not waited for; the next accepted one is taken instead.
  const Result r = exec(
      db,
      "UPDATE jobs SET status = " + sql_name(JobStatus::running) + ", progress = 0, " + no_run +
          "message = 'running', started = $1, finished = NULL, updated = $1, "
          "attempts = attempts + 1, owner = $2, lease_token = lease_token + 1, "
          "lease_expires_ms = $3, claimed_ms = $4, alive_ms = $4 WHERE id = (SELECT id FROM "
          "jobs WHERE status = " +
          sql_name(JobStatus::accepted) +
          " ORDER BY seq LIMIT 1 FOR UPDATE SKIP LOCKED) RETURNING " + job_columns,
      Params().add(now).add(who.instance).add(lease_until(who)).add(now_ms()));
  if (r.rows() == 0) return std::nullopt;
  JobRecord job = read_job(r, 0);
  exec(db, "INSERT INTO job_attempts (job_id, token, owner, claimed) VALUES ($1, $2, $3, $4)",
       Params().add(job.id).add(job.lease_token).add(job.owner).add(now));
  tx.commit();
  return job;
}

std::int64_t PostgresStore::renew_leases(const Claimant& who) {
  auto db = pool_.lease();
  return exec(
             db.get(),
             "UPDATE jobs SET lease_expires_ms = $1, alive_ms = $3 WHERE owner = $2 AND status = " +
                 sql_name(JobStatus::running),
             Params().add(lease_until(who)).add(who.instance).add(now_ms()))
      .affected();
}

ClaimState PostgresStore::record_progress(const Claim& claim, const RunProgress& run) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Params p = claim_params(claim);
  p.add(run.percent).add(now_text()).add(now_ms()).add(run.time).add(run.end_time);
  p.add(run.steps).add(run.dt_min).add(run.dt_max);
  const Result r =
      exec(db,
           "UPDATE jobs SET progress = $4, updated = $5, alive_ms = $6, run_time = $7, "
           "run_end_time = $8, run_steps = $9, run_dt_min = $10, run_dt_max = $11 "
           "WHERE " +
               claim_held,
           p);
  return r.affected() == 1 ? ClaimState::held : claim_state(db, claim);
}

ClaimState PostgresStore::finish(const Claim& claim, const JobEnd& end) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  const std::string now = now_text();
  Params p = claim_params(claim);
  p.add(status_name(end.status)).add(end.message).add_or_null(end.failure_reason).add(now);
  p.add(end.run_seconds).add(end.run.steps).add(end.run.time).add(end.run.end_time);
  p.add(end.run.dt_min).add(end.run.dt_max);
  const Result r = exec(
      db,
      "UPDATE jobs SET status = $4, message = $5, failure_reason = $6, finished = $7, "
      "updated = $7, run_seconds = $8, progress = CASE WHEN $4 = " +
          sql_name(JobStatus::successful) +
          " THEN 100 ELSE progress END, run_time = CASE WHEN $9::bigint > 0 THEN $10 ELSE run_time "
          "END, run_end_time = CASE WHEN $9 > 0 THEN $11 ELSE run_end_time END, run_steps = "
          "CASE WHEN $9 > 0 THEN $9 ELSE run_steps END, run_dt_min = CASE WHEN $9 > 0 THEN "
          "$12 ELSE run_dt_min END, run_dt_max = CASE WHEN $9 > 0 THEN $13 ELSE run_dt_max "
          "END, " +
          no_checkpoint + " WHERE " + claim_held,
      p);
  if (r.affected() != 1) return claim_state(db, claim);
  replace_results(db, claim.job_id, end.files);
  end_attempt(db, claim, status_name(end.status), now);
  tx.commit();
  return ClaimState::held;
}

ClaimState PostgresStore::requeue(const Claim& claim) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  const std::string now = now_text();
  // The checkpoint stays: the next claim resumes from it.
  const Result r = exec(db,
                        "UPDATE jobs SET status = " + sql_name(JobStatus::accepted) +
                            ", progress = 0, " + no_run +
                            "started = NULL, message = $5, "
                            "updated = $4, attempts = greatest(attempts - 1, 0), "
                            "lease_expires_ms = 0 WHERE " +
                            claim_held,
                        claim_params(claim).add(now).add(requeued_message));
  if (r.affected() != 1) return claim_state(db, claim);
  end_attempt(db, claim, "requeued", now);
  tx.commit();
  return ClaimState::held;
}

std::optional<JobRecord> PostgresStore::cancel(const std::string& id) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  auto before = select_job(db, id, true);
  if (!before || is_terminal(before->status)) return before;
  const std::string now = now_text();
  exec(db,
       "UPDATE jobs SET status = " + sql_name(JobStatus::dismissed) +
           ", message = 'cancelled by the client', finished = $1, updated = $1, " + no_checkpoint +
           " WHERE id = $2",
       Params().add(now).add(id));
  end_attempts(db, id, status_name(JobStatus::dismissed), now);
  tx.commit();
  return before;
}

std::optional<JobRecord> PostgresStore::dismiss(const std::string& id) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  auto before = select_job(db, id, true);
  if (!before || before->results_deleted) return before;
  const bool was_dismissed = before->status == JobStatus::dismissed;
  const std::string now = now_text();
  exec(db,
       "UPDATE jobs SET status = " + sql_name(JobStatus::dismissed) +
           ", message = $3, results_deleted = true, finished = coalesce(finished, $1), "
           "updated = $1, " +
           no_checkpoint + " WHERE id = $2",
       Params().add(now).add(id).add(was_dismissed ? before->message + "; results deleted"
                                                   : "dismissed by the client"));
  replace_results(db, id, {});
  end_attempts(db, id, status_name(JobStatus::dismissed), now);
  tx.commit();
  return before;
}

ClaimState PostgresStore::keep_results(const Claim& claim, const std::vector<ResultFile>& files,
                                       double run_seconds) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  const auto job = select_job(db, claim.job_id, true);
  if (!job || job->owner != claim.owner || job->lease_token != claim.token ||
      job->status != JobStatus::dismissed) {
    return ClaimState::lost;
  }
  if (job->results_deleted) return ClaimState::dismissed;
  exec(db, "UPDATE jobs SET run_seconds = $2, updated = $3 WHERE id = $1",
       Params().add(claim.job_id).add(run_seconds).add(now_text()));
  replace_results(db, claim.job_id, files);
  tx.commit();
  return ClaimState::held;
}

std::vector<ResultFile> PostgresStore::results(const std::string& id) {
  auto db = pool_.lease();
  const Result r =
      exec(db.get(),
           "SELECT name, size, sha256, media_type FROM results WHERE job_id = $1 ORDER BY name",
           Params().add(id));
  std::vector<ResultFile> out;
  out.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i)
    out.push_back({r.text(i, 0), r.integer(i, 1), r.text(i, 2), r.text(i, 3)});
  return out;
}

RecoveryReport PostgresStore::recover(int max_attempts, double charge_after_s) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  // SKIP LOCKED: a row its owner is renewing (or another server is
  // recovering) right now is left to that transaction.
  const Result lapsed =
      exec(db,
           "SELECT id, attempts, charged, alive_ms - claimed_ms FROM jobs WHERE status = " +
               sql_name(JobStatus::running) +
               " AND lease_expires_ms <= $1 ORDER BY seq FOR UPDATE SKIP LOCKED",
           Params().add(now_ms()));
  RecoveryReport report;
  const std::string now = now_text();
  for (int i = 0; i < lapsed.rows(); ++i) {
    const std::string id = lapsed.text(i, 0);
    const auto [charged, reason] =
        decide_recovery({lapsed.integer(i, 1), lapsed.integer(i, 2),
                         static_cast<double>(lapsed.integer(i, 3)) / 1000.0},
                        max_attempts, charge_after_s);
    if (reason.empty()) {
      exec(db,
           "UPDATE jobs SET status = " + sql_name(JobStatus::accepted) + ", progress = 0, " +
               no_run + "started = NULL, updated = $1, charged = $3, message = $4 WHERE id = $2",
           Params().add(now).add(id).add(charged).add(requeued_message));
      report.requeued.push_back(id);
    } else {
      exec(db,
           "UPDATE jobs SET status = " + sql_name(JobStatus::failed) +
               ", message = $1, failure_reason = $1, finished = $2, updated = $2, charged = $4, " +
               no_checkpoint + " WHERE id = $3",
           Params().add(reason).add(now).add(id).add(charged));
      report.failed.push_back(id);
    }
    end_attempts(db, id, "lapsed", now);
  }
  tx.commit();
  return report;
}

StatusCounts PostgresStore::count_by_status() {
  auto db = pool_.lease();
  const Result r = exec(db.get(), "SELECT status, count(*) FROM jobs GROUP BY status");
  StatusCounts counts;
  for (int i = 0; i < r.rows(); ++i) {
    if (auto status = parse_status(r.text(i, 0))) counts[*status] = r.integer(i, 1);
  }
  return counts;
}

std::vector<std::string> PostgresStore::purge_ended(
    std::chrono::system_clock::time_point ended_before) {
  auto db = pool_.lease();
  // Result rows and attempts go with the job (ON DELETE CASCADE), and so
  // does its idempotency key (a column of the row).
  const Result r = exec(db.get(),
                        "WITH gone AS (DELETE FROM jobs WHERE status IN " + ended_statuses +
                            " AND finished IS NOT NULL AND finished < $1 RETURNING id, seq) "
                            "SELECT id FROM gone ORDER BY seq",
                        Params().add(format_rfc3339(ended_before)));
  std::vector<std::string> ids;
  ids.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) ids.push_back(r.text(i, 0));
  // An ensemble is stored with its samples in one transaction, so one
  // without any is one whose samples were all purged.
  exec(db.get(),
       "DELETE FROM ensembles WHERE NOT EXISTS (SELECT 1 FROM jobs WHERE jobs.ensemble_id = "
       "ensembles.id)");
  return ids;
}

ClaimState PostgresStore::record_checkpoint(const Claim& claim,
                                            const CheckpointRecord& checkpoint) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  const std::string now = now_text();
  Params p = claim_params(claim);
  p.add(checkpoint.file).add(checkpoint.step).add(checkpoint.time).add(checkpoint.size);
  p.add(checkpoint.sha256).add(checkpoint.written.empty() ? now : checkpoint.written).add(now);
  const Result r = exec(db,
                        "UPDATE jobs SET checkpoint_file = $4, checkpoint_step = $5, "
                        "checkpoint_time = $6, checkpoint_size = $7, checkpoint_sha256 = $8, "
                        "checkpoint_written = $9, updated = $10 WHERE " +
                            claim_held,
                        p);
  return r.affected() == 1 ? ClaimState::held : claim_state(db, claim);
}

std::optional<CheckpointRecord> PostgresStore::checkpoint(const std::string& id) {
  auto db = pool_.lease();
  const Result r = exec(db.get(),
                        "SELECT checkpoint_file, checkpoint_step, checkpoint_time, "
                        "checkpoint_size, checkpoint_sha256, checkpoint_written FROM jobs "
                        "WHERE id = $1 AND checkpoint_file IS NOT NULL",
                        Params().add(id));
  if (r.rows() == 0) return std::nullopt;
  return CheckpointRecord{r.text(0, 0),    r.integer(0, 1), r.real(0, 2),
                          r.integer(0, 3), r.text(0, 4),    r.text(0, 5)};
}

EnsembleSubmitResult PostgresStore::submit_ensemble(const NewEnsemble& ensemble,
                                                    std::int64_t max_queue) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  exec(db, submit_lock);
  if (!ensemble.idempotency_key.empty()) {
    const Result r = exec(db, "SELECT id, body_sha256 FROM ensembles WHERE idempotency_key = $1",
                          Params().add(ensemble.idempotency_key));
    if (r.rows() > 0) {
      const bool same_body = r.text(0, 1) == ensemble.body_sha256;
      auto earlier = select_ensemble(db, r.text(0, 0));
      tx.commit();
      return {same_body ? SubmitOutcome::replayed : SubmitOutcome::key_conflict,
              std::move(*earlier)};
    }
  }
  if (exec(db, "SELECT count(*) FROM jobs WHERE status = " + sql_name(JobStatus::accepted))
              .integer(0, 0) +
          static_cast<std::int64_t>(ensemble.samples.size()) >
      max_queue) {
    return {SubmitOutcome::queue_full, {}};
  }
  const std::string now = now_text();
  exec(db,
       "INSERT INTO ensembles (id, request, seed, samples, created, updated, idempotency_key, "
       "body_sha256) VALUES ($1, $2, $3, $4, $5, $5, $6, $7)",
       Params()
           .add(ensemble.id)
           .add(ensemble.request)
           .add(ensemble.seed)
           .add(static_cast<std::int64_t>(ensemble.samples.size()))
           .add(now)
           .add_or_null(ensemble.idempotency_key)
           .add_or_null(ensemble.body_sha256));
  for (std::size_t k = 0; k < ensemble.samples.size(); ++k)
    insert_job(db, ensemble.samples[k], now, ensemble.id, static_cast<int>(k));
  auto created = select_ensemble(db, ensemble.id);
  tx.commit();
  return {SubmitOutcome::created, std::move(*created)};
}

std::optional<EnsembleRecord> PostgresStore::find_ensemble(const std::string& id) {
  auto db = pool_.lease();
  return select_ensemble(db.get(), id);
}

std::vector<EnsembleRecord> PostgresStore::list_ensembles(int limit) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  const Result r =
      exec(db, std::string("SELECT ") + ensemble_columns + " ORDER BY seq DESC LIMIT $1",
           Params().add(std::int64_t{limit}));
  std::vector<EnsembleRecord> out;
  out.reserve(static_cast<std::size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) out.push_back(read_ensemble(r, i));
  for (EnsembleRecord& e : out) read_samples(db, e);
  return out;
}

std::optional<EnsembleRecord> PostgresStore::set_ensemble_state(const std::string& id,
                                                                EnsembleState state) {
  auto connection = pool_.lease();
  PGconn* db = connection.get();
  Transaction tx(db);
  auto before = select_ensemble(db, id, true);
  if (!before || before->state == EnsembleState::deleted) return before;
  exec(db, "UPDATE ensembles SET state = $2, updated = $3 WHERE id = $1",
       Params().add(id).add(ensemble_state_name(state)).add(now_text()));
  tx.commit();
  return before;
}

}  // namespace hmpm::server::postgres

namespace hmpm::server {

bool is_postgres_uri(std::string_view db) {
  return db.rfind("postgresql://", 0) == 0 || db.rfind("postgres://", 0) == 0;
}

std::unique_ptr<JobStore> open_postgres_store(const std::string& uri, WallClock clock) {
  return std::make_unique<postgres::PostgresStore>(uri, std::move(clock));
}

}  // namespace hmpm::server
