// worker_pool.cpp — see worker_pool.hpp.
#include "worker_pool.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "digest.hpp"
#include "job_log.hpp"
#include "run_log.hpp"
#include "run_tracker.hpp"

namespace hmpm::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

double seconds_since(SteadyClock::time_point t0) {
  return std::chrono::duration<double>(SteadyClock::now() - t0).count();
}

void log_transition(const std::string& id, JobStatus to, nlohmann::ordered_json extra = {}) {
  nlohmann::ordered_json line{{"event", "job"}, {"job", id}, {"status", status_name(to)}};
  for (auto& [key, value] : extra.items()) line[key] = value;
  log_line(std::move(line));
}

// The first few spec errors as one line, for a failure reason.
std::string describe(const std::vector<hmpm::api::SpecError>& errors) {
  std::string text;
  for (std::size_t i = 0; i < errors.size() && i < 5; ++i) {
    text += (i ? "; " : "") + (errors[i].path.empty() ? std::string("/") : errors[i].path) + ": " +
            errors[i].message;
  }
  return text;
}

// `x` rounded down to a whole number.
long whole(double x) {
  return static_cast<long>(std::floor(x));
}

// `x` with 4 significant digits ("0.25", "1.234e+04").
std::string short_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

// Removes everything in `dir` but the job's log (it spans every attempt)
// and the entry named `keep` (an attempt folder), if any.
void remove_all_but_log(const std::filesystem::path& dir, const std::string& keep = "") {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != run_log_name && (keep.empty() || name != keep))
      std::filesystem::remove_all(entry.path(), ec);
  }
}

// The folder, inside the job's, where the attempt of the claim with fencing
// token `token` writes: "attempt-<token>".
std::string attempt_name(std::int64_t token) {
  return "attempt-" + std::to_string(token);
}

// Removes every file of `dir` that is neither the job's log nor one of
// `listed` (the manifest): nothing stays in a job's folder that its manifest
// does not show (the leftovers of a failed write hold space and are invisible).
void remove_unlisted(const std::filesystem::path& dir, const std::vector<ResultFile>& listed) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const bool kept =
        name == run_log_name || std::any_of(listed.begin(), listed.end(),
                                            [&](const ResultFile& f) { return f.name == name; });
    if (!kept) std::filesystem::remove_all(entry.path(), ec);
  }
}

// Checkpoint files: "checkpoint-<claim token>-<step>.hmpmck" (never a result file).
constexpr const char* checkpoint_prefix = "checkpoint-";
constexpr const char* checkpoint_suffix = ".hmpmck";

bool is_checkpoint_file(const std::string& name) {
  return name.rfind(checkpoint_prefix, 0) == 0;
}

// Copies the result files an earlier attempt wrote in `from` (the snapshots
// before its checkpoint) into this attempt's folder `to`: a resumed run
// writes only what comes after the checkpoint. Copies, not links: a revived
// earlier owner rewriting its own files must not change ours. Throws
// std::filesystem::filesystem_error.
void carry_over(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::filesystem::create_directories(to);
  for (const auto& entry : std::filesystem::directory_iterator(from)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name == run_log_name || name.rfind("checkpoint-", 0) == 0 ||
        entry.path().extension() == ".tmp")
      continue;
    std::filesystem::copy_file(entry.path(), to / name,
                               std::filesystem::copy_options::overwrite_existing);
  }
}

// Removes the job's checkpoint files but `keep` (and any half-written one).
void remove_checkpoints_but(const std::filesystem::path& dir, const std::string& keep = "") {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (is_checkpoint_file(name) && name != keep) std::filesystem::remove(entry.path(), ec);
  }
}

// Writes `bytes` to `path` durably: a temporary file, fsync, rename over
// `path`, fsync of the folder. Throws std::runtime_error.
void write_durably(const std::filesystem::path& path, const std::string& bytes) {
  const std::string tmp = path.string() + ".tmp";
  auto fail = [&](const char* what) {
    const std::string message = std::string(what) + " " + tmp + ": " + std::strerror(errno);
    ::unlink(tmp.c_str());
    throw std::runtime_error(message);
  };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("cannot create");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      fail("cannot write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("cannot sync");
  }
  if (::close(fd) != 0) fail("cannot close");
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("cannot rename");
  const int dir = ::open(path.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

// The bytes of the recorded checkpoint `rec` in `dir` when the file is
// there, has the recorded SHA-256 and belongs to `job` (spec text `key`);
// otherwise nullopt, with why in `why`.
std::optional<std::string> read_checkpoint(const std::filesystem::path& dir,
                                           const CheckpointRecord& rec,
                                           const hmpm::api::ParsedJob& job, const std::string& key,
                                           std::string& why) {
  std::ifstream in(dir / rec.file, std::ios::binary);
  if (!in) {
    why = "its file " + rec.file + " is missing";
    return std::nullopt;
  }
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (sha256_hex(bytes) != rec.sha256) {
    why = "its file " + rec.file + " does not have the recorded SHA-256";
    return std::nullopt;
  }
  try {
    (void)hmpm::inspect_checkpoint(job.problem, key, bytes);
  } catch (const std::invalid_argument& e) {
    why = std::string("the solver refuses it: ") + e.what();
    return std::nullopt;
  }
  return bytes;
}

// Size, SHA-256 and media type of each of `names` in `dir`, appended to
// `files`; the name of the first one that cannot be read back, if any.
std::optional<std::string> record_files(const std::filesystem::path& dir,
                                        const std::vector<std::string>& names,
                                        std::vector<ResultFile>& files) {
  std::optional<std::string> unreadable;
  for (const std::string& name : names) {
    const auto path = dir / name;
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    auto sha = sha256_file_hex(path);
    if (ec || !sha) {
      if (!unreadable) unreadable = name;
      continue;
    }
    files.push_back({name, static_cast<std::int64_t>(size), *sha, hmpm::api::media_type_for(name)});
  }
  return unreadable;
}

}  // namespace

void log_recovery(const RecoveryReport& recovery) {
  for (const auto& id : recovery.requeued) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", status_name(JobStatus::accepted)},
              {"recovered", true}});
  }
  for (const auto& id : recovery.failed) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", status_name(JobStatus::failed)},
              {"recovered", true},
              {"reason", "too many interrupted attempts"}});
  }
}

void WorkerPool::claim_lost(const Claim& claim, double seconds) {
  ++metrics_.claims_lost;
  log_line({{"event", "job"}, {"job", claim.job_id}, {"claim", "lost"}, {"seconds", seconds}});
  discard_if_ended(claim);
}

void WorkerPool::discard_if_ended(const Claim& claim) {
  try {
    const auto job = store_.find(claim.job_id);
    if (job && job->lease_token != claim.token &&
        (job->status == JobStatus::successful || job->status == JobStatus::failed ||
         job->status == JobStatus::dismissed)) {
      std::error_code ec;
      std::filesystem::remove_all(attempt_dir(claim), ec);
    }
  } catch (const std::exception& e) {  // the folder stays until retention removes the job
    log_line({{"event", "store_error"}, {"job", claim.job_id}, {"detail", e.what()}});
  }
}

void WorkerPool::end_dismissed(const JobRecord& job, const Claim& claim,
                               const std::vector<std::string>& written, double seconds) {
  const std::filesystem::path dir = job_dir(job.id);
  const std::filesystem::path out = attempt_dir(claim);
  std::vector<ResultFile> files;
  record_files(out, written, files);
  ClaimState state = ClaimState::lost;
  try {
    state = with_retries(job.id, "keep_results",
                         [&] { return store_.keep_results(claim, files, seconds); });
  } catch (const std::exception& e) {  // shutting down: the next start recovers the job
    log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
  }
  if (state == ClaimState::lost) {  // not ours any more: touch nothing
    claim_lost(claim, seconds);
    return;
  }
  const bool kept = state == ClaimState::held;
  std::error_code ec;
  if (kept) {
    remove_checkpoints_but(out);
    remove_all_but_log(dir, out.filename().string());  // other attempts' folders
    append_run_log(dir, "cancelled after " + short_number(seconds) + " s wall; " +
                            std::to_string(files.size()) + " result files kept");
  } else {
    std::filesystem::remove_all(dir, ec);  // deleted: the files go with it
  }
  metrics_.observe_job(seconds, JobStatus::dismissed);
  log_transition(job.id, JobStatus::dismissed, {{"seconds", seconds}, {"files_kept", kept}});
}

WorkerPool::WorkerPool(JobStore& store, Metrics& metrics, WorkerSettings settings)
    : store_(store), metrics_(metrics), settings_(std::move(settings)) {}

WorkerPool::~WorkerPool() {
  shutdown();
}

std::filesystem::path WorkerPool::job_dir(const std::string& id) const {
  return settings_.data_dir / id;
}

std::filesystem::path WorkerPool::attempt_dir(const Claim& claim) const {
  return job_dir(claim.job_id) / attempt_name(claim.token);
}

std::filesystem::path WorkerPool::results_dir(const JobRecord& job) const {
  std::filesystem::path dir = job_dir(job.id) / attempt_name(job.lease_token);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) dir = job_dir(job.id);  // an older server's layout
  return dir;
}

void WorkerPool::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (int i = 0; i < settings_.workers; ++i) threads_.emplace_back([this] { work(); });
  heartbeat_ = std::thread([this] { heartbeat(); });
}

void WorkerPool::heartbeat() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    heartbeat_wake_.wait_for(lock, std::chrono::duration<double>(settings_.lease_renewal_s),
                             [&] { return stopping_; });
    if (stopping_) return;
    const bool busy = !running_.empty();
    lock.unlock();
    try {
      if (busy) store_.renew_leases(settings_.claimant);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}, {"during", "lease renewal"}});
    }
    try {
      // Takes over the jobs of servers whose lease lapsed (on one SQLite
      // file there are none: the lock voided them at start-up).
      const RecoveryReport report =
          store_.recover(settings_.max_attempts, settings_.charge_after_s);
      log_recovery(report);
      metrics_.recovered_jobs += static_cast<int>(report.requeued.size() + report.failed.size());
      for (std::size_t i = 0; i < report.requeued.size(); ++i) notify();
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}, {"during", "recovery"}});
    }
    lock.lock();
  }
}

void WorkerPool::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++generation_;
  }
  wake_.notify_one();
}

bool WorkerPool::cancel(const std::string& id, double wait_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto it = running_.find(id);
  if (it == running_.end()) return false;
  it->second->dismissed = true;
  it->second->cancel = true;
  job_done_.wait_for(lock, std::chrono::duration<double>(wait_s),
                     [&] { return running_.find(id) == running_.end(); });
  return true;
}

void WorkerPool::stop_claiming() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [id, running] : running_) running->cancel = true;
  }
  wake_.notify_all();
  heartbeat_wake_.notify_all();
  retry_wake_.notify_all();
}

ClaimState WorkerPool::with_retries(const std::string& id, const char* during,
                                    const std::function<ClaimState()>& write) {
  double wait_s = first_retry_s;
  for (int attempt = 1;; ++attempt) {
    try {
      return write();
    } catch (const StoreFailure& e) {
      std::unique_lock<std::mutex> lock(mutex_);
      log_line({{"event", "store_error"},
                {"job", id},
                {"during", during},
                {"attempt", attempt},
                {"detail", e.what()},
                {"retry_in_s", stopping_ ? 0.0 : wait_s}});
      if (stopping_) throw;  // the job stays running; recovery at the next start requeues it
      retry_wake_.wait_for(lock, std::chrono::duration<double>(wait_s), [&] { return stopping_; });
      wait_s = std::min(2 * wait_s, last_retry_s);
    }
  }
}

void WorkerPool::shutdown() {
  stop_claiming();
  std::vector<std::thread> threads;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    threads.swap(threads_);
    if (heartbeat_.joinable()) threads.push_back(std::move(heartbeat_));
  }
  for (auto& t : threads) t.join();
}

void WorkerPool::work() {
  for (;;) {
    std::uint64_t seen = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;
      seen = generation_;
    }
    std::optional<JobRecord> job;
    try {
      job = store_.claim_next(settings_.claimant);
    } catch (const std::exception& e) {
      log_line({{"event", "store_error"}, {"detail", e.what()}});
    }
    if (!job) {
      // Nothing queued: sleep until a submission (or at most a second, which
      // also picks up jobs queued by another process on the same database).
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait_for(lock, std::chrono::seconds(1),
                     [&] { return stopping_ || generation_ != seen; });
      continue;
    }
    auto running = std::make_shared<Running>();
    bool registered = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!stopping_) running_[job->id] = running;
      registered = !stopping_;
    }
    if (!registered) {  // shutdown began between claim and here
      try {
        store_.requeue(claim_of(*job));
      } catch (const std::exception& e) {  // recovery at the next start requeues it
        log_line({{"event", "store_error"}, {"job", job->id}, {"detail", e.what()}});
      }
      return;
    }
    ++metrics_.busy_workers;
    try {
      run_one(*job, *running);
    } catch (const std::exception& e) {
      // Only the store can throw here; the job stays running and start-up
      // recovery will deal with it.
      log_line({{"event", "worker_error"}, {"job", job->id}, {"detail", e.what()}});
    }
    --metrics_.busy_workers;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_.erase(job->id);
    }
    job_done_.notify_all();
  }
}

void WorkerPool::run_one(const JobRecord& job, Running& running) {
  const auto t0 = SteadyClock::now();
  const Claim claim = claim_of(job);
  log_transition(job.id, JobStatus::running, {{"attempt", job.attempts}});
  const std::filesystem::path dir = job_dir(job.id);
  const std::filesystem::path out = attempt_dir(claim);  // this attempt's files, fenced
  const std::string out_name = out.filename().string();
  auto parsed = hmpm::api::parse_job(job.spec, settings_.limits);
  // An earlier attempt's checkpoint: resume from it when it is intact, else
  // start afresh (the folder then loses that attempt's leftovers).
  std::optional<std::string> resume;
  std::string checkpoint_file;  // the recorded checkpoint of this job, if any (from `dir`)
  std::optional<CheckpointRecord> recorded;
  try {
    recorded = store_.checkpoint(job.id);
  } catch (const std::exception& e) {
    log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
  }
  if (recorded && parsed.ok() && settings_.checkpoint_interval_s > 0) {
    std::string why;
    resume = read_checkpoint(dir, *recorded, *parsed.job, job.spec, why);
    if (!resume) {
      append_run_log(dir, "checkpoint at step " + std::to_string(recorded->step) + " not usable (" +
                              why + "): starting from step 0");
      log_line({{"event", "checkpoint"}, {"job", job.id}, {"unusable", why}});
    }
  }
  if (resume) {
    // The snapshots so far come along into this attempt's folder; the
    // folder resumed from stays until this attempt records a checkpoint of
    // its own (until then a crash resumes from the same one).
    checkpoint_file = recorded->file;
    const std::string from = std::filesystem::path(checkpoint_file).begin()->string();
    const bool legacy = from == checkpoint_file;  // an older server's file in `dir` itself
    try {
      if (legacy) {
        carry_over(dir, out);
      } else {
        remove_all_but_log(dir, from);  // folders of attempts before that one
        carry_over(dir / from, out);
      }
    } catch (const std::exception& e) {
      append_run_log(dir, std::string("the results before the checkpoint could not be copied (") +
                              e.what() + "): starting from step 0");
      resume.reset();
      checkpoint_file.clear();
    }
  }
  if (!resume) remove_all_but_log(dir);  // leftovers of interrupted attempts
  append_run_log(dir, "attempt " + std::to_string(job.attempts) + " started on " +
                          settings_.claimant.instance + ": " + std::to_string(job.cost.particles) +
                          " particles, " + std::to_string(job.cost.steps) + " steps, " +
                          std::to_string(settings_.threads_per_job) + " solver threads");
  if (resume) {
    append_run_log(dir, "resumed from the checkpoint at step " + std::to_string(recorded->step) +
                            ", t = " + short_number(recorded->time) + " s (" + recorded->file +
                            ", written " + recorded->written + ")");
    log_line({{"event", "checkpoint"}, {"job", job.id}, {"resumed_step", recorded->step}});
  }

  JobStatus outcome = JobStatus::failed;
  std::string reason;
  hmpm::api::JobOutcome result;
  RunTracker tracker;  // what the run reached, for the store
  if (!parsed.ok()) {
    reason = "the stored spec is no longer valid: " + describe(parsed.errors);
  } else {
    for (const auto& w : parsed.job->warnings) {
      append_run_log(dir,
                     "warning: " + (w.path.empty() ? std::string("/") : w.path) + ": " + w.message);
    }
    hmpm::RunOptions options;
    options.threads = settings_.threads_per_job;
    options.cancel = &running.cancel;
    options.wall_time_limit_s = settings_.wall_time_limit_s;
    options.progress_interval_s = settings_.progress_interval_s;
    auto last_write = SteadyClock::now() - std::chrono::hours(1);
    ProgressLogPacer pacer;
    options.on_progress = [&](const hmpm::Progress& p) {
      const RunProgress& reached = tracker.observe(p);
      const auto now = SteadyClock::now();
      if (pacer.due(p.fraction, now)) {
        append_run_log(dir, "progress " + std::to_string(whole(100.0 * p.fraction)) + " %: step " +
                                std::to_string(p.step) + " of " + std::to_string(p.total_steps) +
                                ", t = " + short_number(p.time) + " of " +
                                short_number(p.end_time) + " s, " +
                                short_number(seconds_since(t0)) + " s wall");
      }
      if (now - last_write < std::chrono::duration<double>(0.5 * settings_.progress_interval_s))
        return;
      last_write = now;
      try {
        const ClaimState state = store_.record_progress(claim, reached);
        if (state != ClaimState::held) {  // dismissed through another path, or taken over: stop
          running.dismissed = state == ClaimState::dismissed;
          running.lost = state == ClaimState::lost;
          running.cancel = true;
        }
      } catch (const std::exception& e) {
        log_line({{"event", "store_error"}, {"job", job.id}, {"detail", e.what()}});
      }
    };
    options.checkpoint_key = job.spec;
    options.checkpoint_interval_s = settings_.checkpoint_interval_s;
    if (resume) options.resume = &*resume;
    if (settings_.checkpoint_interval_s > 0) {
      options.on_checkpoint = [&](const hmpm::Checkpoint& c) {
        // The solver's last checkpoint of a cancelled run is kept for a
        // shutdown only (a dismissed job, or one another claim took, is over).
        if (running.dismissed || running.lost) return;
        const auto t1 = SteadyClock::now();
        // Recorded relative to the job's folder:
        // "attempt-<token>/checkpoint-<token>-<step>.hmpmck".
        const std::string name = out_name + "/" + checkpoint_prefix + std::to_string(claim.token) +
                                 "-" + std::to_string(c.step) + checkpoint_suffix;
        try {
          write_durably(dir / name, c.bytes);
          const CheckpointRecord rec{
              name, c.step, c.time, static_cast<std::int64_t>(c.bytes.size()), sha256_hex(c.bytes),
              ""};
          const ClaimState state = store_.record_checkpoint(claim, rec);
          if (state != ClaimState::held) {  // not ours to record: stop, as for progress
            std::error_code ec;
            std::filesystem::remove(dir / name, ec);
            running.dismissed = state == ClaimState::dismissed;
            running.lost = state == ClaimState::lost;
            running.cancel = true;
            return;
          }
          if (!checkpoint_file.empty() && checkpoint_file != name) {
            std::error_code ec;
            std::filesystem::remove(dir / checkpoint_file, ec);
            remove_all_but_log(dir, out_name);  // the folder resumed from, if any
          }
          checkpoint_file = name;
          append_run_log(dir, "checkpoint at step " + std::to_string(c.step) + ", t = " +
                                  short_number(c.time) + " s: " + std::to_string(c.bytes.size()) +
                                  " bytes in " + short_number(seconds_since(t1)) + " s");
        } catch (const std::exception& e) {  // the run goes on; the last checkpoint stays
          std::error_code ec;
          std::filesystem::remove(dir / name, ec);
          log_line({{"event", "checkpoint_error"}, {"job", job.id}, {"detail", e.what()}});
        }
      };
    }
    try {
      std::filesystem::create_directories(out);
      result = hmpm::api::run_job(*parsed.job, out, options);
      for (const std::string& w : result.run.run_warnings) append_run_log(dir, "warning: " + w);
      if (result.run.status == hmpm::RunStatus::successful) {
        outcome = JobStatus::successful;
      } else {
        reason = result.run.message.empty()
                     ? std::string("the run ended as ") + hmpm::status_name(result.run.status)
                     : result.run.message;
      }
    } catch (const std::exception& e) {
      reason = std::string("could not write the result files: ") + e.what();
    }
  }
  const double seconds = seconds_since(t0);

  if (running.lost) {  // another instance owns the job now
    claim_lost(claim, seconds);
    return;
  }
  if (running.dismissed) {
    end_dismissed(job, claim, result.files, seconds);
    return;
  }
  if (running.cancel && outcome != JobStatus::successful) {  // shutdown: run it again next start
    const ClaimState state = with_retries(job.id, "requeue", [&] { return store_.requeue(claim); });
    if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
    if (state == ClaimState::lost) {
      claim_lost(claim, seconds);
      return;
    }
    if (checkpoint_file.empty()) {
      remove_all_but_log(dir);
      append_run_log(dir, "stopped after " + short_number(seconds) +
                              " s: the server is shutting down; queued again");
    } else {  // the next attempt resumes from the checkpoint and the snapshots before it
      append_run_log(dir, "stopped after " + short_number(seconds) +
                              " s: the server is shutting down; queued again, to resume from " +
                              checkpoint_file);
    }
    log_transition(job.id, JobStatus::accepted, {{"requeued", true}, {"seconds", seconds}});
    return;
  }

  std::vector<ResultFile> files;
  if (const auto unreadable = record_files(out, result.files, files)) {
    outcome = JobStatus::failed;
    reason = "result file " + *unreadable + " could not be read back";
  }
  remove_unlisted(out, files);
  const std::string message = outcome == JobStatus::successful ? "finished" : reason;
  // The end of a job must reach the store, or it would stay running until a
  // restart: a failing write (disk full) is retried with backoff.
  const ClaimState state = with_retries(job.id, "finish", [&] {
    return store_.finish(claim, JobEnd{outcome, message, reason, files, seconds,
                                       tracker.finish(result.run.steps, result.run.end_time)});
  });
  if (state == ClaimState::lost) {  // taken over while finishing: not served, never will be
    claim_lost(claim, seconds);
    return;
  }
  if (state == ClaimState::dismissed) return end_dismissed(job, claim, result.files, seconds);
  // The job has ended: its checkpoints and other attempts' folders are of no use now.
  remove_checkpoints_but(out);
  remove_all_but_log(dir, out_name);
  append_run_log(dir, std::string(status_name(outcome)) + " after " + short_number(seconds) +
                          " s wall, " + std::to_string(files.size()) + " result files" +
                          (reason.empty() ? "" : ": " + reason));
  metrics_.observe_job(seconds, outcome);
  nlohmann::ordered_json extra{{"seconds", seconds}, {"files", files.size()}};
  if (!reason.empty()) extra["reason"] = reason;
  log_transition(job.id, outcome, std::move(extra));
}

}  // namespace hmpm::server
