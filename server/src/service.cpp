// service.cpp — the life cycle of hmpm-server: open, lock, recover, bind, serve, stop.
//
// With SQLite, construction takes the data folder's lock and opens the store
// (which locks the database) before anything is recovered or bound, so a
// second server on the same `--db` or `--data-dir` fails here with the other
// one's pid. With PostgreSQL (`--db postgresql://...`) neither is locked:
// servers share the database and the data folder, and the claims keep them
// apart. Each process is one store instance (`instance_id`): its claims carry
// that id, its heartbeat renews their leases and takes over lapsed ones
// (workers/pool.hpp). Requests are served by http/.
#include <sys/socket.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "digest.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"
#include "http/connection.hpp"
#include "http/drain.hpp"
#include "http/server_setup.hpp"
#include "http/validation_gate.hpp"
#include "job_limits.hpp"
#include "job_log.hpp"
#include "metrics.hpp"
#include "process_lock.hpp"
#include "retention.hpp"
#include "store/postgres/connection.hpp"
#include "workers/pool.hpp"

namespace hmpm::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

// Fills in the defaults that depend on other settings and creates folders.
bool on_postgres(const ServiceConfig& c) {
  return is_postgres_uri(c.db_path.string());
}

ServiceConfig resolved(ServiceConfig c) {
  if (c.threads_per_job <= 0) {
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    c.threads_per_job = std::max(1, cores / std::max(1, c.workers));
  }
  if (c.max_job_memory == 0) c.max_job_memory = default_job_memory(c.workers);
  if (on_postgres(c)) {
    if (c.data_dir.empty()) throw StoreFailure("--data-dir is required with a PostgreSQL database");
  } else {
    if (c.data_dir.empty()) c.data_dir = c.db_path.parent_path() / "results";
    if (!c.db_path.parent_path().empty())
      std::filesystem::create_directories(c.db_path.parent_path());
  }
  std::filesystem::create_directories(c.data_dir);
  return c;
}

hmpm::api::Limits limits_for(const ServiceConfig& c) {
  hmpm::api::Limits limits;
  limits.max_body_bytes = static_cast<std::int64_t>(c.max_body_bytes);
  limits.max_particles = c.max_particles;
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
                        .lease_renewal_s = c.lease_s / 3.0,
                        .checkpoint_interval_s = c.checkpoint_interval_s,
                        .max_attempts = c.max_attempts,
                        .charge_after_s = c.charge_after_s};
}

// Validations running at once: half the cores (at least one), so the
// workers and the other HTTP threads keep a core; a quarter of the HTTP
// threads may hold a request for one (http/validation_gate.hpp), each
// waiting at most validation_wait_s for its turn.
int validation_turns() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / 2);
}
constexpr double validation_wait_s = 10.0;

http::ConnectionLimits connection_limits(const ServiceConfig& c) {
  http::ConnectionLimits limits;
  limits.head_timeout_s = c.head_timeout_s;
  limits.body_timeout_s = c.body_timeout_s;
  limits.send_stall_s = c.send_stall_s;
  limits.core_threads = static_cast<std::size_t>(c.http_threads);
  limits.max_connections = static_cast<std::size_t>(std::max(c.max_connections, c.http_threads));
  return limits;
}

}  // namespace

struct Service::Impl {
  explicit Impl(ServiceConfig c)
      : config(resolved(std::move(c))),
        data_lock(lock_data_dir(config)),
        limits(limits_for(config)),
        store(open_store(config)),
        workers(*store, metrics, worker_settings(config, limits, instance_id)),
        validation(validation_turns(), std::max(2, config.http_threads / 4), validation_wait_s),
        context{config, limits, *store, metrics, workers, workers.files(), stopping, validation},
        auth(config.token),
        router(http::route_table(), context, auth),
        server(connection_limits(config)) {
    metrics.instance = instance_id;
    log_recovery(store->recover(config.max_attempts, config.charge_after_s));
    http::configure_server(server, context, router, auth);
  }

  // SQLite: one process per data folder. PostgreSQL: the folder is shared.
  static std::optional<ProcessLock> lock_data_dir(const ServiceConfig& c) {
    if (on_postgres(c)) return std::nullopt;
    return ProcessLock::hold(c.data_dir / ".hmpm-server.lock",
                             "data folder " + c.data_dir.string());
  }
  static std::unique_ptr<JobStore> open_store(const ServiceConfig& c) {
    if (on_postgres(c)) return open_postgres_store(c.db_path.string(), {}, c.data_dir);
    return open_sqlite_store(c.db_path);
  }

  ServiceConfig config;
  /// Before the store: nothing is opened unless both locks are ours (SQLite).
  std::optional<ProcessLock> data_lock;
  hmpm::api::Limits limits;
  std::string instance_id = new_uuid_v4();
  std::unique_ptr<JobStore> store;
  Metrics metrics;
  WorkerPool workers;
  std::atomic<bool> stopping{false};
  http::ValidationGate validation;
  http::Context context;
  http::Authenticator auth;
  http::Router router;
  http::HardenedServer server;
  int port = -1;
  std::atomic<bool> run_started{false};
  std::atomic<bool> run_finished{false};
  // Set when listen_after_bind() has returned (every connection thread ended).
  std::mutex serve_mutex;
  std::condition_variable serve_ended;
  bool serving_done = false;

  // Waits up to `seconds` for listen_after_bind() to return.
  bool wait_serving_done(double seconds) {
    std::unique_lock<std::mutex> lock(serve_mutex);
    return serve_ended.wait_for(lock, std::chrono::duration<double>(seconds),
                                [&] { return serving_done; });
  }
  // The retention thread: purges at start and every retention_interval_s
  // until run() ends.
  std::mutex retention_mutex;
  std::condition_variable retention_wake;
  bool retention_stop = false;

  void purge_now(std::chrono::system_clock::time_point now) {
    try {
      hmpm::server::purge_expired(*store, workers.files(), config.retain_days, now);
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
            {"db", postgres::redacted(s.config.db_path.string())},
            {"data_dir", s.config.data_dir.string()},
            {"instance", s.instance_id},
            {"auth", !s.config.token.empty()},
            {"retain_days", s.config.retain_days},
            {"job_wall_time_s", s.config.job_wall_time_s},
            {"max_particles", s.config.max_particles},
            {"max_particle_steps", s.config.max_particle_steps},
            {"max_job_memory", s.config.max_job_memory},
            {"max_connections", s.config.max_connections}});
  std::thread retention;
  if (s.config.retain_days > 0) retention = std::thread([&s] { s.retention_loop(); });
  const bool ok = s.stopping || s.server.listen_after_bind();
  {
    std::lock_guard<std::mutex> lock(s.serve_mutex);
    s.serving_done = true;
  }
  s.serve_ended.notify_all();
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
  const bool first = !s.stopping.exchange(true);
  // No job is claimed from here on; running ones are cancelled and their
  // workers requeue them while the connections drain.
  s.workers.stop_claiming();
  // stop() may race with run() starting to listen: give it a moment to be
  // listening, so the listener it is about to open is closed too.
  const auto until = SteadyClock::now() + std::chrono::seconds(2);
  while (s.run_started && !s.run_finished && !s.server.is_running() && SteadyClock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  s.server.stop();
  if (!first || !s.run_started) return;
  if (s.wait_serving_done(s.config.shutdown_drain_s)) return;
  // A connection still open after the drain (a client trickling its request,
  // or one that does not read): shut its socket down so its thread ends.
  const int cut = http::shut_down_connections(s.port);
  log_line(
      {{"event", "drain"}, {"seconds", s.config.shutdown_drain_s}, {"connections_shut_down", cut}});
  if (!s.wait_serving_done(2.0))
    log_line({{"event", "drain"}, {"detail", "connection threads still busy after 2 s"}});
}

std::vector<std::string> Service::purge_expired(std::chrono::system_clock::time_point now) {
  return hmpm::server::purge_expired(*impl_->store, impl_->workers.files(),
                                     impl_->config.retain_days, now);
}

bool Service::is_running() const {
  return impl_->server.is_running();
}

const ServiceConfig& Service::config() const {
  return impl_->config;
}

}  // namespace hmpm::server
