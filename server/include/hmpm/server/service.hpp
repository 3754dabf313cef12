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
  int port = 8080;                 ///< 0: any free port
  std::filesystem::path db_path;   ///< SQLite file (created if missing)
  std::filesystem::path data_dir;  ///< result files; empty: <db dir>/results
  int workers = 1;                 ///< jobs run at the same time
  int threads_per_job = 0;         ///< solver threads per job; <= 0: cores / workers
  std::string token;               ///< non-empty: Bearer token required (not on /health)
  long max_queue = 1000;           ///< accepted jobs before POST /jobs answers 503
  double job_wall_time_s = 0.0;    ///< per-job wall-clock limit; <= 0: none
  int max_attempts = 3;            ///< starts of one job before restart recovery fails it
  std::size_t max_body_bytes = std::size_t{16} << 20;  ///< request body limit (413)
  int max_event_streams = 8;          ///< concurrent GET /jobs/{id}/events (503 beyond)
  int http_threads = 24;              ///< HTTP threads kept ready (more are made on demand)
  int max_connections = 256;          ///< connections served at once (a thread each); 503 beyond
  double head_timeout_s = 10.0;       ///< a request's line and headers must arrive within this
  double body_timeout_s = 60.0;       ///< a request's body must arrive within this
  double event_stream_max_s = 300.0;  ///< an event stream ends after this; the client reconnects
  bool allow_no_token = false;  ///< a non-loopback --host without a token starts (with a warning)
  double progress_interval_s = 1.0;    ///< how often a running job's progress is stored
  double heartbeat_interval_s = 10.0;  ///< SSE comment line when nothing else was sent
  double lease_s = 30.0;  ///< a running job's claim lapses this long after its last renewal
  /// Calibration of the wall-time estimate (hmpm::api::calibrate, which
  /// hmpm-server runs at start-up); <= 0: the api's built-in default.
  double seconds_per_particle_step = 0.0;
  /// Ended jobs (and their files) are purged this many days after they
  /// ended, at start-up and hourly; 0 keeps them forever (retention.hpp).
  int retain_days = 30;
  double retention_interval_s = 3600.0;  ///< how often run() purges
};

class Service {
 public:
  /// Creates and locks the data folder, opens and locks the database and
  /// recovers interrupted jobs. Throws hmpm::server::StoreFailure if the
  /// database cannot be opened, or another process holds it or the data
  /// folder (the message names its pid).
  explicit Service(ServiceConfig config);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  /// Binds the listening socket; returns the port, or -1 if binding failed.
  int bind();
  /// Starts the workers and serves until stop(); then cancels running jobs,
  /// puts them back in the queue and joins every thread. Returns false if
  /// serving could not start.
  bool run();
  /// Thread-safe and idempotent: stop accepting, end event streams, make
  /// run() return.
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
