// jobs.cpp — POST/GET /jobs, POST /validate, GET/DELETE /jobs/{id},
// POST /jobs/{id}/cancel, GET /jobs/{id}/spec and /log.
#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "digest.hpp"
#include "documents.hpp"
#include "handlers.hpp"
#include "hmpm/format.hpp"
#include "job_limits.hpp"
#include "job_log.hpp"
#include "problem.hpp"
#include "run_log.hpp"
#include "submission.hpp"

namespace hmpm::server::http {
namespace {

constexpr std::size_t max_reported_errors = 200;

}  // namespace

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

// A spec is parsed with this server's calibration, so the one estimate of a
// request (ParsedJob::cost) is what the limits are checked against and what
// the 201, /validate and GET /jobs/{id} show.
hmpm::api::Calibration server_calibration(const Context& c) {
  hmpm::api::Calibration calibration;
  if (c.config.seconds_per_particle_step > 0) {
    calibration.seconds_per_particle_step = c.config.seconds_per_particle_step;
    calibration.measured = true;
  }
  calibration.threads = std::max(c.config.threads_per_job, 1);
  return calibration;
}

Json cost_with_estimate(const hmpm::api::CostEstimate& cost) {
  const hmpm::api::Calibration& calibration = cost.calibration;
  Json doc = cost_document(cost_of(cost));
  doc["threads"] = cost.threads;
  doc["scheme"] = hmpm::scheme_name(cost.scheme);
  doc["wall_seconds"] = cost.wall_seconds;
  Json schemes = Json::array();
  for (const hmpm::api::SchemeCost& s : cost.schemes)
    schemes.push_back(Json{{"scheme", hmpm::scheme_name(s.scheme)},
                           {"steps", s.steps},
                           {"dt", s.dt},
                           {"fixed_dt", s.fixed},
                           {"wall_seconds", s.wall_seconds}});
  doc["schemes"] = std::move(schemes);
  doc["seconds_per_particle_step"] = calibration.seconds_per_particle_step;
  doc["calibrated"] = calibration.measured;
  return doc;
}

Json spec_issues(const std::vector<hmpm::api::SpecError>& issues) {
  Json out = Json::array();
  for (const auto& e : issues) {
    if (out.size() == max_reported_errors) break;
    out.push_back(Json{{"path", e.path}, {"message", e.message}});
  }
  return out;
}

namespace {

constexpr int max_candidates = 20;
constexpr std::size_t full_id_length = 36;

// How long POST /jobs/{id}/cancel waits for the worker to record the files.
constexpr double cancel_wait_s = 5.0;

}  // namespace

void send_invalid_spec(httplib::Response& res, const std::vector<hmpm::api::SpecError>& errors,
                       const std::string& what) {
  const std::string detail = std::to_string(errors.size()) +
                             (errors.size() == 1 ? " problem" : " problems") + " in the " + what +
                             "; see errors";
  send_problem(res, 400, "invalid-spec", "Invalid " + what, detail,
               Json{{"errors", spec_issues(errors)}});
}

bool refuse_over_limits(const Context& c, httplib::Response& res,
                        const hmpm::api::CostEstimate& cost, const std::string& prefix) {
  const std::vector<LimitExceeded> over = exceeded_limits(cost, c.config);
  if (over.empty()) return false;
  Json limits = Json::array();
  std::string detail = prefix;
  for (const LimitExceeded& l : over) {
    limits.push_back(Json{{"limit", l.limit},
                          {"value", l.value},
                          {"estimate", l.estimate},
                          {"unit", l.unit},
                          {"option", l.option}});
    detail += (detail.size() == prefix.size() ? "" : "; ") + l.limit + ": the job's estimate is " +
              hmpm::format_significant(l.estimate, 3) + " " + l.unit + ", the limit " +
              hmpm::format_significant(l.value, 3) + " (hmpm-server " + l.option + ")";
  }
  send_problem(res, 422, "limit-exceeded", "Job over this server's limits", detail,
               Json{{"limits", std::move(limits)}});
  return true;
}

void send_validation_busy(const Context& c, httplib::Response& res) {
  res.set_header("Retry-After", "2");
  send_problem(res, 503, "validation-busy", "Too many specs being validated",
               "the server is validating " + std::to_string(c.validation.admitted_max()) +
                   " job specs already; retry in a moment");
}

namespace {

void log_dismissal(const std::string& id, JobStatus from, const char* how) {
  log_line({{"event", "job"},
            {"job", id},
            {"status", status_name(JobStatus::dismissed)},
            {"from", status_name(from)},
            {"by", how}});
}

}  // namespace

std::optional<JobRecord> find_job(Context& c, const std::string& ref, httplib::Response& res) {
  if (ref.size() == full_id_length) {
    auto job = c.store.find(ref);
    if (!job) send_no_such_job(res, ref);
    return job;
  }
  const std::vector<std::string> ids = c.store.ids_with_prefix(ref, max_candidates + 1);
  if (ids.empty()) {
    send_no_such_job(res, ref);
    return std::nullopt;
  }
  if (ids.size() > 1) {
    Json candidates = Json::array();
    for (std::size_t i = 0; i < ids.size() && i < max_candidates; ++i) candidates.push_back(ids[i]);
    send_problem(res, 409, "ambiguous-id", "Ambiguous job id",
                 "'" + ref + "' is the start of " +
                     (ids.size() > max_candidates ? "more than " + std::to_string(max_candidates)
                                                  : std::to_string(ids.size())) +
                     " job ids; give more of the id",
                 Json{{"candidates", candidates}});
    return std::nullopt;
  }
  auto job = c.store.find(ids.front());
  if (!job) send_no_such_job(res, ref);  // deleted in between
  return job;
}

std::int64_t queued_jobs(Context& c) {
  const StatusCounts counts = c.store.count_by_status();
  const auto it = counts.find(JobStatus::accepted);
  return it == counts.end() ? 0 : it->second;
}

void send_queue_full(const Context& c, httplib::Response& res) {
  res.set_header("Retry-After", "30");
  send_problem(
      res, 503, "queue-full", "Queue full",
      "the queue holds " + std::to_string(c.config.max_queue) + " jobs already; retry later");
}

std::optional<std::string> admit_submission(const Context& c, const httplib::Request& req,
                                            httplib::Response& res) {
  if (c.stopping) {
    res.set_header("Retry-After", "5");
    send_problem(res, 503, "shutting-down", "Shutting down",
                 "the server is stopping; submit again once it is back");
    return std::nullopt;
  }
  std::string key = req.get_header_value("Idempotency-Key");
  if (key.size() > 255) {
    send_problem(res, 400, "bad-request", "Bad request",
                 "Idempotency-Key must be at most 255 characters");
    return std::nullopt;
  }
  return key;
}

void post_job(Context& c, const httplib::Request& req, httplib::Response& res,
              const std::string& body) {
  submit_job(c, req, res, body, body);
}

void submit_job(Context& c, const httplib::Request& req, httplib::Response& res,
                const std::string& spec, const std::string& body) {
  const auto admitted = admit_submission(c, req, res);
  if (!admitted) return;
  const std::string& key = *admitted;

  // A full queue is answered before any validation work: a count, not a parse.
  if (queued_jobs(c) >= c.config.max_queue) return send_queue_full(c, res);
  hmpm::api::ParseResult parsed;
  {
    const ValidationGate::Turn turn = c.validation.enter();
    if (!turn) return send_validation_busy(c, res);
    parsed = hmpm::api::parse_job(spec, c.limits, server_calibration(c));
  }
  if (!parsed.ok() || !parsed.job) return send_invalid_spec(res, parsed.errors);
  const hmpm::api::CostEstimate& estimate = parsed.job->cost;
  if (refuse_over_limits(c, res, estimate)) return;

  NewJob job;
  job.id = new_uuid_v4();
  job.name = parsed.job->name;
  job.spec = spec;
  job.cost = cost_of(estimate);
  job.idempotency_key = key;
  if (!key.empty()) job.body_sha256 = sha256_hex(body);
  const SubmitResult submitted = c.store.submit(job, c.config.max_queue);
  // The 201 also carries the spec's warnings (runnable, but worth knowing);
  // the run's summary.json repeats them.
  const auto accepted_document = [&] {
    Json doc = status_document(submitted.job);
    doc["cost"] = cost_with_estimate(estimate);
    if (!parsed.job->warnings.empty()) doc["warnings"] = spec_issues(parsed.job->warnings);
    return doc;
  };
  switch (submitted.outcome) {
    case SubmitOutcome::created:
      log_line({{"event", "job"},
                {"job", job.id},
                {"status", status_name(JobStatus::accepted)},
                {"name", job.name}});
      c.workers.notify();
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
      return send_queue_full(c, res);
  }
}

namespace {

// Every value of a query parameter given as comma-separated lists, possibly
// repeated: ?status=a,b&status=c -> a, b, c.
std::vector<std::string> param_values(const httplib::Request& req, const char* param) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < req.get_param_value_count(param); ++i) {
    const std::string values = req.get_param_value(param, i);
    std::size_t start = 0;
    while (start <= values.size()) {
      const std::size_t comma = std::min(values.find(',', start), values.size());
      out.push_back(values.substr(start, comma - start));
      start = comma + 1;
    }
  }
  return out;
}

}  // namespace

bool read_list_parameters(const httplib::Request& req, httplib::Response& res,
                          std::vector<JobStatus>& statuses, int& limit) {
  for (const std::string& value : param_values(req, "status")) {
    const auto status = parse_status(value);
    if (!status) {
      send_invalid_parameter(res, "status must be " + status_names_text(), "status",
                             "unknown status '" + value + "'");
      return false;
    }
    statuses.push_back(*status);
  }
  limit = 100;
  if (req.has_param("limit")) {
    const std::string v = req.get_param_value("limit");
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), limit);
    if (ec != std::errc() || end != v.data() + v.size() || limit < 1 || limit > 1000) {
      send_invalid_parameter(res, "limit must be an integer from 1 to 1000", "limit",
                             "must be 1..1000");
      return false;
    }
  }
  return true;
}

void list_jobs(Context& c, const httplib::Request& req, httplib::Response& res) {
  std::vector<JobStatus> statuses;
  int limit = 100;
  if (!read_list_parameters(req, res, statuses, limit)) return;
  const std::string name = req.get_param_value("name");
  // OGC API – Processes job-list filters: every job here is of process
  // "hmpm" and of type "process", so they keep all jobs or none.
  bool none = false;
  for (const auto& [param, only] : {std::pair<const char*, const char*>{"processID", "hmpm"},
                                    std::pair<const char*, const char*>{"type", "process"}}) {
    if (!req.has_param(param)) continue;
    const std::vector<std::string> values = param_values(req, param);
    if (std::find(values.begin(), values.end(), only) == values.end()) none = true;
  }
  Json jobs = Json::array();
  if (!none) {
    for (const JobRecord& job : c.store.list(statuses, name, limit))
      jobs.push_back(status_document(job));
  }
  const auto n = jobs.size();
  send_json(res, 200,
            Json{{"jobs", std::move(jobs)},
                 {"numberReturned", n},
                 {"links", Json::array({link("/jobs", "self", "application/json", "job list")})}});
}

void validate_spec(Context& c, const httplib::Request&, httplib::Response& res,
                   const std::string& body) {
  hmpm::api::ParseResult parsed;
  {
    const ValidationGate::Turn turn = c.validation.enter();
    if (!turn) return send_validation_busy(c, res);
    parsed = hmpm::api::parse_job(body, c.limits, server_calibration(c));
  }
  if (!parsed.ok() || !parsed.job) return send_invalid_spec(res, parsed.errors);
  // A spec over a limit of this server is valid but would be refused: said
  // here as POST /jobs would say it.
  if (refuse_over_limits(c, res, parsed.job->cost)) return;
  send_json(res, 200,
            Json{{"valid", true},
                 {"warnings", spec_issues(parsed.job->warnings)},
                 {"cost", cost_with_estimate(parsed.job->cost)}});
}

void get_job(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = find_job(c, req.matches[1], res);
  if (!job) return;
  Json doc = status_document(*job);
  // The spec's warnings, as in the 201: the stored spec parsed again (the
  // same bytes give the same warnings), so the store keeps no copy of them.
  const hmpm::api::ParseResult parsed =
      hmpm::api::parse_job(job->spec, c.limits, server_calibration(c));
  doc["warnings"] = parsed.job ? spec_issues(parsed.job->warnings) : Json::array();
  if (parsed.job) doc["cost"] = cost_with_estimate(parsed.job->cost);
  send_json(res, 200, doc);
}

void get_job_spec(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = find_job(c, req.matches[1], res);
  if (!job) return;
  res.set_content(job->spec, "application/json");  // exactly the bytes submitted
}

void get_job_log(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = find_job(c, req.matches[1], res);
  if (!job) return;
  if (job->results_deleted) {
    return send_problem(res, 410, "job-dismissed", "Job dismissed",
                        "the job was deleted; its log went with its results");
  }
  std::ifstream in(c.files.log_file(job->id), std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();  // no file yet: the job has not started
  res.set_content(text.str(), "text/plain; charset=utf-8");
}

std::optional<JobRecord> cancel_one(Context& c, const std::string& id) {
  auto before = c.store.cancel(id);
  if (!before || is_terminal(before->status)) return before;
  append_run_log(c.files.job_dir(id),
                 std::string("cancelled by the client while ") + status_name(before->status));
  log_dismissal(id, before->status, "cancel");
  // A worker of this process records the files written so far; give it a
  // moment so the manifest is complete when the client reads it.
  if (before->status == JobStatus::running) c.workers.cancel(id, cancel_wait_s);
  return before;
}

void cancel_job(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = find_job(c, req.matches[1], res);
  if (!job) return;
  const std::string& id = job->id;
  const auto before = cancel_one(c, id);
  if (!before) return send_no_such_job(res, id);
  if (is_terminal(before->status)) {
    return send_problem(res, 409, "job-finished", "Job already ended",
                        std::string("the job has already ended (") + status_name(before->status) +
                            "); nothing was changed",
                        Json{{"jobID", id}, {"jobStatus", status_name(before->status)}});
  }
  const auto after = c.store.find(id);
  if (!after) return send_no_such_job(res, id);
  send_json(res, 202, status_document(*after));
}

std::optional<JobRecord> delete_one(Context& c, const std::string& id) {
  auto before = c.store.dismiss(id);
  if (!before) return before;
  // A worker of this process removes the files itself once it has stopped.
  if (!c.workers.cancel(id) && !before->results_deleted) c.files.remove(id);
  if (before->status != JobStatus::dismissed) log_dismissal(id, before->status, "delete");
  return before;
}

void dismiss_job(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = find_job(c, req.matches[1], res);
  if (!job) return;
  const std::string& id = job->id;
  const auto before = delete_one(c, id);
  if (!before) return send_no_such_job(res, id);
  const auto after = c.store.find(id);
  if (!after) return send_no_such_job(res, id);
  send_json(res, 200, status_document(*after));
}

}  // namespace hmpm::server::http
