// http_service.cpp — the HTTP front end of hmpm-server (cpp-httplib 0.11.4).
//
// This is the one place where outcomes become HTTP: store results, spec
// errors and worker states are values until a handler here picks a status
// code and a problem document (RFC 9457, `application/problem+json`). The
// handlers only read and write the store and nudge the workers; solver work
// never runs on an HTTP thread.
//
// cpp-httplib 0.11.4 has a few sharp edges handled here:
// - it enforces the body limit only for a declared Content-Length, so bodies
//   without one (chunked, or read-until-close) are refused with 411 before
//   routing;
// - without an exception handler it copies `e.what()` into a response header,
//   so one is installed that logs the text and answers a generic 500;
// - it parses `application/x-www-form-urlencoded` bodies (what `curl -d`
//   sends) and refuses them above 8 KiB, so POST /jobs reads its body through
//   a content reader, which skips that;
// - each Server-Sent Events stream holds a server thread, so streams are
//   capped and end promptly on shutdown.
#include <httplib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <regex>
#include <thread>
#include <utility>

#include "clock.hpp"
#include "digest.hpp"
#include "hmpm/api/job.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"
#include "job_log.hpp"
#include "metrics.hpp"
#include "worker_pool.hpp"

namespace hmpm::server {
namespace {

using Json = nlohmann::ordered_json;
using httplib::Request;
using httplib::Response;
using SteadyClock = std::chrono::steady_clock;

constexpr const char* uuid_pattern =
    "([0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12})";
constexpr std::size_t max_reported_errors = 200;

// When the current request reached routing, for the log line's duration.
thread_local SteadyClock::time_point request_start{};
thread_local bool request_timed = false;

std::string dump(const Json& doc) {
  return doc.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

void send_json(Response& res, int status, const Json& doc) {
  res.status = status;
  res.set_content(dump(doc), "application/json");
}

// A problem document; `extra` members (e.g. `errors`) are appended.
void send_problem(Response& res, int status, const std::string& type, const std::string& title,
                  const std::string& detail, const Json& extra = Json::object()) {
  Json doc{{"type", type}, {"title", title}, {"status", status}, {"detail", detail}};
  for (const auto& [key, value] : extra.items()) doc[key] = value;
  res.status = status;
  res.set_content(dump(doc), "application/problem+json");
}

void send_not_found(Response& res, const std::string& what) {
  send_problem(res, 404, "not-found", "Not found", what);
}

// The problem document for a status httplib chose by itself.
void send_default_problem(Response& res) {
  switch (res.status) {
    case 400:
      return send_problem(res, 400, "bad-request", "Bad request",
                          "the request could not be read as HTTP");
    case 404:
      return send_not_found(res, "no such resource; see docs/api.md for the routes");
    case 413:
      return send_problem(res, 413, "payload-too-large", "Payload too large",
                          "the request body exceeds the server's limit");
    case 414:
      return send_problem(res, 414, "uri-too-long", "URI too long",
                          "the request target exceeds the server's limit");
    default:
      return send_problem(res, res.status, "http-error", "HTTP error",
                          "the request could not be served");
  }
}

Json link(const std::string& href, const char* rel, const char* type, const char* title) {
  return Json{{"href", href}, {"rel", rel}, {"type", type}, {"title", title}};
}

Json timestamp_or_null(const std::string& t) {
  return t.empty() ? Json(nullptr) : Json(t);
}

int whole_percent(double progress) {
  return static_cast<int>(std::clamp(std::floor(progress), 0.0, 100.0));
}

// The contract's status document plus hmpm's extras (name, attempts, cost).
Json status_document(const JobRecord& job) {
  const std::string self = "/jobs/" + job.id;
  Json doc{{"jobID", job.id},
           {"type", "process"},
           {"processID", "hmpm"},
           {"name", job.name},
           {"status", status_name(job.status)},
           {"progress", whole_percent(job.progress)},
           {"message", job.message},
           {"created", job.created},
           {"started", timestamp_or_null(job.started)},
           {"finished", timestamp_or_null(job.finished)},
           {"updated", job.updated},
           {"attempts", job.attempts}};
  if (!job.failure_reason.empty()) doc["reason"] = job.failure_reason;
  doc["cost"] = Json{{"particles", job.cost.particles},
                     {"nodes", job.cost.nodes},
                     {"cells", job.cost.cells},
                     {"steps", job.cost.steps},
                     {"dt", job.cost.dt},
                     {"particle_steps", job.cost.particle_steps},
                     {"memory_bytes", job.cost.memory_bytes},
                     {"output_bytes", job.cost.output_bytes}};
  if (job.run_seconds > 0) doc["run_seconds"] = job.run_seconds;
  doc["links"] = Json::array(
      {link(self, "self", "application/json", "this status document"),
       link(self + "/results", "results", "application/json", "manifest of the result files"),
       link(self + "/events", "events", "text/event-stream", "progress as Server-Sent Events")});
  return doc;
}

JobCost cost_of(const hmpm::api::CostEstimate& c) {
  return JobCost{.particles = c.particles,
                 .nodes = c.nodes,
                 .cells = c.cells,
                 .steps = c.steps,
                 .particle_steps = c.particle_steps,
                 .memory_bytes = c.memory_bytes,
                 .output_bytes = c.output_bytes,
                 .dt = c.dt};
}

// Compares without an early exit, so the time taken does not reveal how
// many leading characters of a guessed token were right.
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = static_cast<unsigned char>(diff | (a[i] ^ b[i % (b.empty() ? 1 : b.size())]));
  }
  return diff == 0 && !b.empty();
}

std::optional<std::uint64_t> content_length(const Request& req) {
  if (!req.has_header("Content-Length")) return std::nullopt;
  const std::string v = req.get_header_value("Content-Length");
  std::uint64_t n = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
  if (ec != std::errc() || end != v.data() + v.size()) return std::nullopt;
  return n;
}

// Paths that exist for some method (a wrong method there is 405, not 404).
bool is_known_resource(const std::string& path) {
  static const std::regex known(std::string("/health|/metrics|/jobs(/") + uuid_pattern +
                                "(/results(/.+)?|/events|/spec)?)?");
  return std::regex_match(path, known);
}

}  // namespace

struct Service::Impl {
  explicit Impl(ServiceConfig c);

  void install_routes();
  bool authorized(const Request& req) const;
  void send_unauthorized(Response& res) const;
  /// Wraps a handler with the Bearer token check.
  httplib::Server::Handler guarded(httplib::Server::Handler handler);

  void post_job(const Request& req, Response& res, const httplib::ContentReader& reader);
  void list_jobs(const Request& req, Response& res);
  void get_job(const Request& req, Response& res);
  void dismiss_job(const Request& req, Response& res);
  void get_manifest(const Request& req, Response& res);
  void get_result_file(const Request& req, Response& res);
  void stream_events(const Request& req, Response& res);
  /// A job whose results are asked for: nullopt (and the answer set) unless finished.
  std::optional<JobRecord> finished_job(const std::string& id, Response& res);

  ServiceConfig config;
  hmpm::api::Limits limits;
  JobStore store;
  Metrics metrics;
  WorkerPool workers;
  httplib::Server http;
  int port = -1;
  std::atomic<bool> stopping{false};
  std::atomic<bool> run_started{false};
  std::atomic<bool> run_finished{false};
};

namespace {

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

WorkerSettings worker_settings(const ServiceConfig& c, const hmpm::api::Limits& limits) {
  return WorkerSettings{.workers = c.workers,
                        .threads_per_job = c.threads_per_job,
                        .wall_time_limit_s = c.job_wall_time_s,
                        .progress_interval_s = c.progress_interval_s,
                        .data_dir = c.data_dir,
                        .limits = limits};
}

hmpm::api::Limits limits_for(const ServiceConfig& c) {
  hmpm::api::Limits limits;
  limits.max_body_bytes = static_cast<std::int64_t>(c.max_body_bytes);
  return limits;
}

}  // namespace

Service::Impl::Impl(ServiceConfig c)
    : config(resolved(std::move(c))),
      limits(limits_for(config)),
      store(config.db_path),
      workers(store, metrics, worker_settings(config, limits)) {
  const RecoveryReport recovery = store.recover(config.max_attempts);
  for (const auto& id : recovery.requeued) {
    log_line({{"event", "job"}, {"job", id}, {"status", "accepted"}, {"recovered", true}});
  }
  for (const auto& id : recovery.failed) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", "failed"},
              {"recovered", true},
              {"reason", "too many interrupted attempts"}});
  }
  install_routes();
}

bool Service::Impl::authorized(const Request& req) const {
  if (config.token.empty()) return true;
  const std::string header = req.get_header_value("Authorization");
  constexpr std::string_view scheme = "bearer ";
  if (header.size() <= scheme.size()) return false;
  for (std::size_t i = 0; i < scheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(header[i])) != scheme[i]) return false;
  }
  return same_secret(header.substr(scheme.size()), config.token);
}

void Service::Impl::send_unauthorized(Response& res) const {
  res.set_header("WWW-Authenticate", "Bearer realm=\"hmpm\"");
  send_problem(res, 401, "unauthorized", "Unauthorized",
               "send 'Authorization: Bearer <token>' with the server's token");
}

httplib::Server::Handler Service::Impl::guarded(httplib::Server::Handler handler) {
  return [this, handler = std::move(handler)](const Request& req, Response& res) {
    if (!authorized(req)) return send_unauthorized(res);
    handler(req, res);
  };
}

void Service::Impl::install_routes() {
  const auto http_threads = static_cast<std::size_t>(config.http_threads);
  http.new_task_queue = [http_threads] { return new httplib::ThreadPool(http_threads); };
  http.set_payload_max_length(config.max_body_bytes);
  http.set_keep_alive_timeout(2);  // bounds how long shutdown waits for idle connections
  http.set_keep_alive_max_count(100);
  // Headers and body go out in separate writes: without TCP_NODELAY, Nagle's
  // algorithm and the client's delayed ACK add ~40 ms to every response.
  http.set_tcp_nodelay(true);
  http.set_read_timeout(10);

  http.set_pre_routing_handler([this](const Request& req, Response& res) {
    request_start = SteadyClock::now();
    request_timed = true;
    const bool body_method = req.method == "POST" || req.method == "PUT" || req.method == "PATCH";
    if (req.has_header("Transfer-Encoding") || (body_method && !req.has_header("Content-Length"))) {
      res.set_header("Connection", "close");
      send_problem(res, 411, "length-required", "Length required",
                   "send the body with a Content-Length header; chunked or unterminated bodies "
                   "are not accepted");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (req.has_header("Content-Length") && !content_length(req)) {
      res.set_header("Connection", "close");
      send_problem(res, 400, "bad-request", "Bad request", "Content-Length is not a number");
      return httplib::Server::HandlerResponse::Handled;
    }
    // Requests with a body are checked by their handler once the body has
    // been read, so an unread body is never left on a kept-alive connection.
    if (req.path != "/health" && content_length(req).value_or(0) == 0 && !authorized(req)) {
      send_unauthorized(res);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });

  // `Expect: 100-continue` (curl, for large bodies): refuse before the body is sent.
  http.set_expect_100_continue_handler([this](const Request& req, Response& res) {
    if (content_length(req).value_or(0) > config.max_body_bytes) {
      send_problem(res, 413, "payload-too-large", "Payload too large",
                   "the request body exceeds " + std::to_string(config.max_body_bytes) + " bytes");
      return 413;
    }
    if (req.path != "/health" && !authorized(req)) {
      send_unauthorized(res);
      return 401;
    }
    return 100;
  });

  http.set_error_handler(httplib::Server::HandlerWithResponse([](const Request&, Response& res) {
    if (res.body.empty()) send_default_problem(res);
    return httplib::Server::HandlerResponse::Handled;
  }));

  http.set_exception_handler([](const Request& req, Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    try {
      std::rethrow_exception(std::move(ep));
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    log_line({{"event", "error"}, {"method", req.method}, {"path", req.path}, {"detail", what}});
    res = Response();
    send_problem(res, 500, "internal-error", "Internal server error",
                 "the server could not complete the request; its log has the details");
  });

  http.set_logger([this](const Request& req, const Response& res) {
    metrics.count_request(res.status);
    Json line{{"event", "request"},
              {"method", req.method},
              {"path", req.path},
              {"status", res.status},
              {"remote", req.remote_addr}};
    if (request_timed) {
      line["ms"] =
          std::chrono::duration<double, std::milli>(SteadyClock::now() - request_start).count();
      request_timed = false;
    }
    log_line(std::move(line));
  });

  http.Get("/health", [this](const Request&, Response& res) {
    try {
      store.schema_version();
      send_json(res, 200, Json{{"status", "ok"}});
    } catch (const std::exception&) {
      send_json(res, 503,
                Json{{"status", "unavailable"}, {"detail", "the database cannot be read"}});
    }
  });
  http.Get("/metrics", guarded([this](const Request&, Response& res) {
             res.set_content(metrics.render(store.count_by_status(), config.workers),
                             "text/plain; version=0.0.4; charset=utf-8");
           }));
  http.Post("/jobs", [this](const Request& req, Response& res,
                            const httplib::ContentReader& reader) { post_job(req, res, reader); });
  http.Get("/jobs", guarded([this](const Request& req, Response& res) { list_jobs(req, res); }));
  const std::string job = std::string("/jobs/") + uuid_pattern;
  http.Get(job, guarded([this](const Request& req, Response& res) { get_job(req, res); }));
  http.Delete(job, guarded([this](const Request& req, Response& res) { dismiss_job(req, res); }));
  http.Get(job + "/spec", guarded([this](const Request& req, Response& res) {
             const auto found = store.find(req.matches[1]);
             if (!found)
               return send_not_found(res, "no job with id " + std::string(req.matches[1]));
             res.set_content(found->spec, "application/json");  // exactly the bytes submitted
           }));
  http.Get(job + "/results",
           guarded([this](const Request& req, Response& res) { get_manifest(req, res); }));
  http.Get(job + "/results/(.+)",
           guarded([this](const Request& req, Response& res) { get_result_file(req, res); }));
  http.Get(job + "/events",
           guarded([this](const Request& req, Response& res) { stream_events(req, res); }));

  // Anything else: 405 on a known path, 404 elsewhere.
  const auto fallback = [](const Request& req, Response& res) {
    if (!is_known_resource(req.path)) return send_not_found(res, "no such resource: " + req.path);
    res.set_header("Allow", req.path == "/jobs" ? "GET, POST" : "GET, DELETE");
    send_problem(res, 405, "method-not-allowed", "Method not allowed",
                 req.method + " is not supported on " + req.path);
  };
  http.Get(".*", fallback);
  http.Post(".*", fallback);
  http.Put(".*", fallback);
  http.Patch(".*", fallback);
  http.Delete(".*", fallback);
}

void Service::Impl::post_job(const Request& req, Response& res,
                             const httplib::ContentReader& reader) {
  std::string body;
  bool too_large = false;
  const bool complete = reader([&](const char* data, std::size_t n) {
    if (body.size() + n > config.max_body_bytes) {
      too_large = true;
      return false;
    }
    body.append(data, n);
    return true;
  });
  if (!complete) {
    if (too_large || res.status == 413) {
      return send_problem(
          res, 413, "payload-too-large", "Payload too large",
          "the job spec exceeds " + std::to_string(config.max_body_bytes) + " bytes");
    }
    return send_problem(res, 400, "bad-request", "Bad request",
                        "the request body could not be read");
  }
  if (!authorized(req)) return send_unauthorized(res);
  if (stopping) {
    res.set_header("Retry-After", "5");
    return send_problem(res, 503, "shutting-down", "Shutting down",
                        "the server is stopping; submit again once it is back");
  }
  const std::string key = req.get_header_value("Idempotency-Key");
  if (key.size() > 255) {
    return send_problem(res, 400, "bad-request", "Bad request",
                        "Idempotency-Key must be at most 255 characters");
  }

  const hmpm::api::ParseResult parsed = hmpm::api::parse_job(body, limits);
  if (!parsed.ok() || !parsed.job) {
    Json errors = Json::array();
    for (const auto& e : parsed.errors) {
      if (errors.size() == max_reported_errors) break;
      errors.push_back(Json{{"path", e.path}, {"message", e.message}});
    }
    const std::string detail = std::to_string(parsed.errors.size()) +
                               (parsed.errors.size() == 1 ? " problem" : " problems") +
                               " in the job spec; see errors";
    return send_problem(res, 400, "invalid-spec", "Invalid job spec", detail,
                        Json{{"errors", errors}});
  }

  NewJob job;
  job.id = new_uuid_v4();
  job.name = parsed.job->name;
  job.spec = body;
  job.cost = cost_of(parsed.job->cost);
  job.idempotency_key = key;
  if (!key.empty()) job.body_sha256 = sha256_hex(body);
  const SubmitResult submitted = store.submit(job, config.max_queue);
  // The 201 also carries the spec's warnings (runnable, but worth knowing);
  // the run's summary.json repeats them.
  const auto accepted_document = [&] {
    Json doc = status_document(submitted.job);
    if (!parsed.job->warnings.empty()) {
      Json warnings = Json::array();
      for (const auto& w : parsed.job->warnings)
        warnings.push_back(Json{{"path", w.path}, {"message", w.message}});
      doc["warnings"] = std::move(warnings);
    }
    return doc;
  };
  switch (submitted.outcome) {
    case SubmitOutcome::created:
      log_line({{"event", "job"}, {"job", job.id}, {"status", "accepted"}, {"name", job.name}});
      workers.notify();
      res.set_header("Location", "/jobs/" + job.id);
      return send_json(res, 201, accepted_document());
    case SubmitOutcome::replayed:
      res.set_header("Location", "/jobs/" + submitted.job.id);
      res.set_header("Idempotent-Replayed", "true");
      return send_json(res, 201, accepted_document());
    case SubmitOutcome::key_conflict:
      return send_problem(res, 422, "idempotency-key-reused", "Idempotency key reused",
                          "this Idempotency-Key was used for a different job spec",
                          Json{{"jobID", submitted.job.id}});
    case SubmitOutcome::queue_full:
      res.set_header("Retry-After", "30");
      return send_problem(
          res, 503, "queue-full", "Queue full",
          "the queue holds " + std::to_string(config.max_queue) + " jobs already; retry later");
  }
}

void Service::Impl::list_jobs(const Request& req, Response& res) {
  std::vector<JobStatus> statuses;
  for (std::size_t i = 0; i < req.get_param_value_count("status"); ++i) {
    std::string values = req.get_param_value("status", i);
    std::size_t start = 0;
    while (start <= values.size()) {
      const std::size_t comma = std::min(values.find(',', start), values.size());
      const std::string value = values.substr(start, comma - start);
      const auto status = parse_status(value);
      if (!status) {
        return send_problem(
            res, 400, "invalid-parameter", "Invalid parameter",
            "status must be accepted, running, successful, failed or dismissed",
            Json{{"errors", Json::array({Json{{"path", "status"},
                                              {"message", "unknown status '" + value + "'"}}})}});
      }
      statuses.push_back(*status);
      start = comma + 1;
    }
  }
  int limit = 100;
  if (req.has_param("limit")) {
    const std::string v = req.get_param_value("limit");
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), limit);
    if (ec != std::errc() || end != v.data() + v.size() || limit < 1 || limit > 1000) {
      return send_problem(
          res, 400, "invalid-parameter", "Invalid parameter",
          "limit must be an integer from 1 to 1000",
          Json{{"errors", Json::array({Json{{"path", "limit"}, {"message", "must be 1..1000"}}})}});
    }
  }
  Json jobs = Json::array();
  for (const JobRecord& job : store.list(statuses, limit)) jobs.push_back(status_document(job));
  const auto n = jobs.size();
  send_json(res, 200,
            Json{{"jobs", std::move(jobs)},
                 {"numberReturned", n},
                 {"links", Json::array({link("/jobs", "self", "application/json", "job list")})}});
}

void Service::Impl::get_job(const Request& req, Response& res) {
  const auto job = store.find(req.matches[1]);
  if (!job) return send_not_found(res, "no job with id " + std::string(req.matches[1]));
  send_json(res, 200, status_document(*job));
}

void Service::Impl::dismiss_job(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto before = store.dismiss(id);
  if (!before) return send_not_found(res, "no job with id " + id);
  if (before->status == JobStatus::running) {
    workers.cancel(id);  // the worker removes its partial files
  } else if (before->status == JobStatus::successful || before->status == JobStatus::failed) {
    std::error_code ec;
    std::filesystem::remove_all(workers.job_dir(id), ec);
  }
  if (before->status != JobStatus::dismissed) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", "dismissed"},
              {"from", status_name(before->status)}});
  }
  const auto after = store.find(id);
  if (!after) return send_not_found(res, "no job with id " + id);
  send_json(res, 200, status_document(*after));
}

std::optional<JobRecord> Service::Impl::finished_job(const std::string& id, Response& res) {
  auto job = store.find(id);
  if (!job) {
    send_not_found(res, "no job with id " + id);
    return std::nullopt;
  }
  if (job->status == JobStatus::dismissed) {
    send_problem(res, 410, "job-dismissed", "Job dismissed",
                 "the job was dismissed; its results are gone");
    return std::nullopt;
  }
  if (!is_terminal(job->status)) {
    send_problem(res, 404, "result-not-ready", "Result not ready",
                 std::string("the job is ") + status_name(job->status) +
                     "; its results appear when it has finished",
                 Json{{"jobID", id},
                      {"jobStatus", status_name(job->status)},
                      {"progress", whole_percent(job->progress)}});
    return std::nullopt;
  }
  return job;
}

void Service::Impl::get_manifest(const Request& req, Response& res) {
  const auto job = finished_job(req.matches[1], res);
  if (!job) return;
  Json files = Json::array();
  for (const ResultFile& f : store.results(job->id)) {
    files.push_back(Json{{"name", f.name},
                         {"size", f.size},
                         {"media_type", f.media_type},
                         {"sha256", f.sha256},
                         {"href", "/jobs/" + job->id + "/results/" + f.name}});
  }
  send_json(res, 200,
            Json{{"jobID", job->id}, {"status", status_name(job->status)}, {"files", files}});
}

void Service::Impl::get_result_file(const Request& req, Response& res) {
  const auto job = finished_job(req.matches[1], res);
  if (!job) return;
  const std::string name = req.matches[2];
  // Only names recorded in the manifest are served: no path is ever built
  // from anything else the client sent.
  std::optional<ResultFile> file;
  for (ResultFile& f : store.results(job->id)) {
    if (f.name == name) file = std::move(f);
  }
  if (!file)
    return send_not_found(res, "job " + job->id + " has no result file named '" + name + "'");
  const auto path = workers.job_dir(job->id) / file->name;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  auto in = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (ec || !*in || static_cast<std::int64_t>(size) != file->size) {
    log_line({{"event", "error"},
              {"job", job->id},
              {"detail", "result file missing or changed: " + file->name}});
    return send_problem(res, 500, "result-missing", "Result file missing",
                        "the result file is missing or was changed on the server");
  }
  const std::string etag = "\"" + file->sha256 + "\"";
  res.set_header("ETag", etag);
  if (req.get_header_value("If-None-Match") == etag) {
    res.status = 304;
    return;
  }
  res.set_header("Content-Disposition", "attachment; filename=\"" + file->name + "\"");
  res.set_content_provider(
      size, file->media_type,
      [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        std::array<char, 1 << 16> buffer{};
        in->seekg(static_cast<std::streamoff>(offset));
        in->read(buffer.data(), static_cast<std::streamsize>(std::min(length, buffer.size())));
        const auto n = in->gcount();
        if (n <= 0) return false;
        return sink.write(buffer.data(), static_cast<std::size_t>(n));
      });
}

void Service::Impl::stream_events(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  if (!store.find(id)) return send_not_found(res, "no job with id " + id);
  int open = metrics.open_streams.load();
  do {
    if (open >= config.max_event_streams) {
      res.set_header("Retry-After", "5");
      return send_problem(res, 503, "too-many-streams", "Too many event streams",
                          "the server's limit of " + std::to_string(config.max_event_streams) +
                              " concurrent event streams is reached; poll GET /jobs/{id} instead");
    }
  } while (!metrics.open_streams.compare_exchange_weak(open, open + 1));

  struct StreamState {
    std::string id;
    std::string last_status;
    int last_progress = -1;
    int sent = 0;
    SteadyClock::time_point last_write = SteadyClock::now();
  };
  auto state = std::make_shared<StreamState>();
  state->id = id;
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  // httplib calls the provider until it signals done (or a write fails); each
  // call sends what changed, or a heartbeat when quiet, then waits ~250 ms.
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, state](std::size_t, httplib::DataSink& sink) {
        try {
          const auto job = store.find(state->id);
          if (!job) {
            sink.done();
            return true;
          }
          const int progress = whole_percent(job->progress);
          const std::string status = status_name(job->status);
          std::string out;
          if (state->sent == 0) out += "retry: 2000\n\n";
          if (status != state->last_status || progress != state->last_progress) {
            state->last_status = status;
            state->last_progress = progress;
            out += "id: " + std::to_string(++state->sent) +
                   "\nevent: " + (is_terminal(job->status) ? "done" : "progress") + "\ndata: " +
                   status_document(*job).dump(-1, ' ', false, Json::error_handler_t::replace) +
                   "\n\n";
          } else if (SteadyClock::now() - state->last_write >=
                     std::chrono::duration<double>(config.heartbeat_interval_s)) {
            out += ": heartbeat\n\n";
          }
          if (!out.empty()) {
            if (!sink.write(out.data(), out.size())) return false;
            state->last_write = SteadyClock::now();
          }
          if (is_terminal(job->status)) {
            sink.done();
            return true;
          }
          const auto until = SteadyClock::now() + std::chrono::milliseconds(250);
          while (SteadyClock::now() < until && !stopping) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
          }
          if (stopping) sink.done();
          return true;
        } catch (const std::exception& e) {
          log_line({{"event", "error"}, {"job", state->id}, {"detail", e.what()}});
          return false;
        }
      },
      [this](bool) { --metrics.open_streams; });
}

Service::Service(ServiceConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {}

Service::~Service() {
  stop();
  impl_->workers.shutdown();
}

int Service::bind() {
  Impl& s = *impl_;
  if (s.config.port == 0) {
    s.port = s.http.bind_to_any_port(s.config.host);
  } else {
    s.port = s.http.bind_to_port(s.config.host, s.config.port) ? s.config.port : -1;
  }
  if (s.port <= 0) s.port = -1;
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
            {"db", s.config.db_path.string()},
            {"data_dir", s.config.data_dir.string()},
            {"auth", !s.config.token.empty()}});
  const bool ok = s.stopping || s.http.listen_after_bind();
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
  while (s.run_started && !s.run_finished && !s.http.is_running() && SteadyClock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  s.http.stop();
}

bool Service::is_running() const {
  return impl_->http.is_running();
}

const ServiceConfig& Service::config() const {
  return impl_->config;
}

}  // namespace hmpm::server
