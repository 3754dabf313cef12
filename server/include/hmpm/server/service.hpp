// service.hpp — hmpm-server as a library: the durable job queue behind HTTP.
//
// A Service owns the job store, the worker threads that run jobs and the
// HTTP front end (cpp-httplib). The `hmpm-server` executable and the tests
// drive it the same way: construct it from a ServiceConfig (this locks the
// data folder and the database, so a second server on either refuses to
// start; opens and migrates the database and recovers jobs whose lease has
// lapsed), `bind()`, then `run()` on a thread of your own until `stop()` is
// called from elsewhere (a signal handler thread, a test's TearDown).
//
// Routes, status codes and problem types are documented in docs/api.md.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace hmpm::server {

struct ServiceConfig {
  std::string host = "127.0.0.1";
  int port = 8080;  ///< 0: any free port
  /// SQLite file (created if missing), or a PostgreSQL libpq URI
  /// (postgresql://...; see is_postgres_uri in store.hpp).
  std::filesystem::path db_path;
  /// Result files; empty: <db dir>/results (SQLite only). With PostgreSQL it
  /// is shared by every server on the database, and not locked.
  std::filesystem::path data_dir;
  /// Jobs run at the same time. Two by default: a long job never holds the
  /// queue, a short one submitted meanwhile runs beside it (issue 44).
  int workers = 2;
  int threads_per_job = 0;  ///< solver threads per job; <= 0: cores / workers (at least 1)
  std::string token;        ///< non-empty: Bearer token required (not on /health)
  long max_queue = 1000;    ///< accepted jobs before POST /jobs answers 503
  /// Per-job wall-clock limit, set-up included; <= 0: none.
  double job_wall_time_s = 86'400.0;
  std::int64_t max_particles = 2'000'000;  ///< particles per job (the parser's budget)
  /// Particles x steps per job, refused at submit beyond (about a day of one
  /// thread at the built-in calibration, 1e-7 s per particle-step); <= 0: none.
  std::int64_t max_particle_steps = 1'000'000'000'000;
  /// Estimated memory per job (cost.memory_bytes), refused at submit
  /// beyond; 0: half the physical memory / workers (job_limits.hpp); < 0: none.
  std::int64_t max_job_memory = 0;
  int max_attempts = 3;  ///< crashes charged to a job before recovery fails it
  /// A crash is charged to a running job only when its attempt had run at
  /// least this long (JobStore::recover).
  double charge_after_s = 30.0;
  std::size_t max_body_bytes = std::size_t{16} << 20;  ///< request body limit (413)
  int max_event_streams = 8;          ///< concurrent GET /jobs/{id}/events (503 beyond)
  int http_threads = 24;              ///< HTTP threads kept ready (more are made on demand)
  int max_connections = 256;          ///< connections served at once (a thread each); 503 beyond
  double head_timeout_s = 10.0;       ///< a request's line and headers must arrive within this
  double body_timeout_s = 60.0;       ///< a request's body must arrive within this
  double send_stall_s = 120.0;        ///< an answer whose client took no byte for this long ends
  double event_stream_max_s = 300.0;  ///< an event stream ends after this; the client reconnects
  bool allow_no_token = false;  ///< a non-loopback --host without a token starts (with a warning)
  /// Host header values accepted besides the listening address (NAME, any
  /// port, or NAME:PORT): the names clients and proxies reach the server by.
  std::vector<std::string> allowed_hosts;
  /// Origins (scheme://host[:port]) whose pages may write (POST, DELETE...)
  /// and get CORS headers; the server's own origin needs no entry.
  std::vector<std::string> allowed_origins;
  double progress_interval_s = 1.0;    ///< how often a running job's progress is stored
  double heartbeat_interval_s = 10.0;  ///< SSE comment line when nothing else was sent
  double lease_s = 30.0;  ///< a running job's claim lapses this long after its last renewal
  /// Wall time between checkpoints of a running job; 0: none (a job
  /// interrupted by a crash then starts again from step 0).
  double checkpoint_interval_s = 60.0;
  /// Calibration of the wall-time estimate (hmpm::api::calibrate, which
  /// hmpm-server runs at start-up); <= 0: the api's built-in default.
  double seconds_per_particle_step = 0.0;
  /// Ended jobs (and their files) are purged this many days after they
  /// ended, at start-up and hourly; 0 keeps them forever (retention.hpp).
  int retain_days = 30;
  double retention_interval_s = 3600.0;  ///< how often run() purges
  /// stop(): how long connections may finish their requests before their
  /// sockets are shut down (a client trickling a request holds its thread
  /// for ever otherwise).
  double shutdown_drain_s = 5.0;
};

class Service {
 public:
  /// Creates and locks the data folder, opens and locks the database and
  /// recovers interrupted jobs. With PostgreSQL neither is locked (servers
  /// share both) and only jobs whose lease lapsed are recovered, here and
  /// at every heartbeat. Throws hmpm::server::StoreFailure if the database
  /// cannot be opened, or another process holds it or the data folder (the
  /// message names its pid).
  explicit Service(ServiceConfig config);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  /// Binds the listening socket; returns the port, or -1 if binding failed.
  int bind();
  /// Starts the workers and serves until stop(); then joins every thread
  /// (the workers have put their jobs back in the queue). Returns false if
  /// serving could not start.
  bool run();
  /// Thread-safe and idempotent: stop claiming jobs and cancel the running
  /// ones (their workers put them back in the queue), stop accepting, end
  /// event streams, give open connections shutdown_drain_s to finish, then
  /// shut down the sockets of those left so run() returns. Returns once run()
  /// has stopped serving, or about 2 s after the drain if it cannot.
  void stop();
  /// True once run() is accepting connections.
  bool is_running() const;
  /// Purges the jobs that ended more than retain_days before `now`, with
  /// their folders; returns their ids. run() calls it at start-up and every
  /// retention_interval_s with the system clock; tests pass a later `now`.
  std::vector<std::string> purge_expired(std::chrono::system_clock::time_point now);

  const ServiceConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hmpm::server
