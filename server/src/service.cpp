// service.cpp — the life cycle of hmpm-server: open, lock, recover, bind, serve, stop.
//
// Construction takes the data folder's lock and opens the store (which locks
// the database) before anything is recovered or bound, so a second server on
// the same `--db` or `--data-dir` fails here with the other one's pid. Each
// process is one store instance (`instance_id`): its claims carry that id,
// its heartbeat renews their leases. Requests are served by http/.
#include <sys/socket.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

#include "digest.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"
#include "http/connection.hpp"
#include "http/server_setup.hpp"
#include "job_log.hpp"
#include "metrics.hpp"
#include "process_lock.hpp"
#include "retention.hpp"
#include "worker_pool.hpp"

namespace hmpm::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

// Fills in the defaults that depend on other settings and creates folders.
ServiceConfig resolved(ServiceConfig c) {
  if (c.data_dir.empty()) c.data_dir = c.db_path.parent_path() / "results";
  if (c.threads_per_job <= 0) {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    c.threads_per_job = std::max(1, cores / std::max(1, c.workers));
  }
  if (!c.db_path.parent_path().empty())
    std::filesystem::create_directories(c.db_path.parent_path());
  std::filesystem::create_directories(c.data_dir);
  return c;
}

hmpm::api::Limits limits_for(const ServiceConfig& c) {
  hmpm::api::Limits limits;
  limits.max_body_bytes = static_cast<std::int64_t>(c.max_body_bytes);
  return limits;
}

WorkerSettings worker_settings(const ServiceConfig& c, const hmpm::api::Limits& limits,
                               const std::string& instance) {
  return WorkerSettings{.workers = c.workers,
                        .threads_per_job = c.threads_per_job,
                        .wall_time_limit_s = c.job_wall_time_s,
                        .progress_interval_s = c.progress_interval_s,
                        .data_dir = c.data_dir,
                        .limits = limits,
                        .claimant = Claimant{instance, c.lease_s},
                        .lease_renewal_s = c.lease_s / 3.0};
}

http::ConnectionLimits connection_limits(const ServiceConfig& c) {
  http::ConnectionLimits limits;
  limits.head_timeout_s = c.head_timeout_s;
  limits.body_timeout_s = c.body_timeout_s;
  limits.core_threads = static_cast<std::size_t>(c.http_threads);
  limits.max_connections = static_cast<std::size_t>(std::max(c.max_connections, c.http_threads));
  return limits;
}

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

}  // namespace

struct Service::Impl {
  explicit Impl(ServiceConfig c)
      : config(resolved(std::move(c))),
        data_lock(ProcessLock::hold(config.data_dir / ".hmpm-server.lock",
                                    "data folder " + config.data_dir.string())),
        limits(limits_for(config)),
        store(open_sqlite_store(config.db_path)),
        workers(*store, metrics, worker_settings(config, limits, instance_id)),
        context{config, limits, *store, metrics, workers, stopping},
        auth(config.token),
        router(http::route_table(), context, auth),
        server(connection_limits(config)) {
    log_recovery(store->recover(config.max_attempts));
    http::configure_server(server, context, router, auth);
  }

  ServiceConfig config;
  ProcessLock data_lock;  ///< before the store: nothing is opened unless both locks are ours
  hmpm::api::Limits limits;
  std::string instance_id = new_uuid_v4();
  std::unique_ptr<JobStore> store;
  Metrics metrics;
  WorkerPool workers;
  std::atomic<bool> stopping{false};
  http::Context context;
  http::Authenticator auth;
  http::Router router;
  http::HardenedServer server;
  int port = -1;
  std::atomic<bool> run_started{false};
  std::atomic<bool> run_finished{false};
  // The retention thread: purges at start and every retention_interval_s
  // until run() ends.
  std::mutex retention_mutex;
  std::condition_variable retention_wake;
  bool retention_stop = false;

  void purge_now(std::chrono::system_clock::time_point now) {
    try {
      hmpm::server::purge_expired(*store, config.data_dir, config.retain_days, now);
    } catch (const std::exception& e) {  // a failing database: try again next time
      log_line({{"event", "store_error"}, {"during", "purge"}, {"detail", e.what()}});
    }
  }
  void retention_loop() {
    std::unique_lock<std::mutex> lock(retention_mutex);
    while (!retention_stop) {
      lock.unlock();
      purge_now(std::chrono::system_clock::now());
      lock.lock();
      retention_wake.wait_for(lock, std::chrono::duration<double>(config.retention_interval_s),
                              [&] { return retention_stop; });
    }
  }
};

Service::Service(ServiceConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}

Service::~Service() {
  stop();
  impl_->workers.shutdown();
}

int Service::bind() {
  Impl& s = *impl_;
  if (s.config.port == 0) {
    s.port = s.server.bind_to_any_port(s.config.host);
  } else {
    s.port = s.server.bind_to_port(s.config.host, s.config.port) ? s.config.port : -1;
  }
  if (s.port <= 0) s.port = -1;
  if (s.port > 0) s.server.widen_backlog(SOMAXCONN);
  return s.port;
}

bool Service::run() {
  Impl& s = *impl_;
  if (s.port < 0) return false;
  s.run_started = true;
  s.workers.start();
  log_line({{"event", "start"},
            {"host", s.config.host},
            {"port", s.port},
            {"workers", s.config.workers},
            {"threads_per_job", s.config.threads_per_job},
            {"seconds_per_particle_step", s.config.seconds_per_particle_step},
            {"db", s.config.db_path.string()},
            {"data_dir", s.config.data_dir.string()},
            {"instance", s.instance_id},
            {"auth", !s.config.token.empty()},
            {"max_connections", s.config.max_connections},
            {"retain_days", s.config.retain_days}});
  std::thread retention;
  if (s.config.retain_days > 0) retention = std::thread([&s] { s.retention_loop(); });
  const bool ok = s.stopping || s.server.listen_after_bind();
  if (retention.joinable()) {
    {
      std::lock_guard<std::mutex> lock(s.retention_mutex);
      s.retention_stop = true;
    }
    s.retention_wake.notify_all();
    retention.join();
  }
  s.workers.shutdown();  // running jobs go back to the queue
  s.run_finished = true;
  log_line({{"event", "stop"}});
  return ok;
}

void Service::stop() {
  Impl& s = *impl_;
  s.stopping = true;
  // stop() may race with run() starting to listen: give it a moment to be
  // listening, so the listener it is about to open is closed too.
  const auto until = SteadyClock::now() + std::chrono::seconds(2);
  while (s.run_started && !s.run_finished && !s.server.is_running() && SteadyClock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  s.server.stop();
}

std::vector<std::string> Service::purge_expired(std::chrono::system_clock::time_point now) {
  return hmpm::server::purge_expired(*impl_->store, impl_->config.data_dir,
                                     impl_->config.retain_days, now);
}

bool Service::is_running() const {
  return impl_->server.is_running();
}

const ServiceConfig& Service::config() const {
  return impl_->config;
}

}  // namespace hmpm::server
