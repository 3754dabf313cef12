// jobs.cpp — POST/GET /jobs, GET/DELETE /jobs/{id}, GET /jobs/{id}/spec.
#include <charconv>
#include <filesystem>

#include "digest.hpp"
#include "documents.hpp"
#include "handlers.hpp"
#include "job_log.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

constexpr std::size_t max_reported_errors = 200;

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

Json spec_issues(const std::vector<hmpm::api::SpecError>& issues) {
  Json out = Json::array();
  for (const auto& e : issues) {
    if (out.size() == max_reported_errors) break;
    out.push_back(Json{{"path", e.path}, {"message", e.message}});
  }
  return out;
}

}  // namespace

void post_job(Context& c, const httplib::Request& req, httplib::Response& res,
              const std::string& body) {
  submit_job(c, req, res, body, body);
}

void submit_job(Context& c, const httplib::Request& req, httplib::Response& res,
                const std::string& spec, const std::string& body) {
  if (c.stopping) {
    res.set_header("Retry-After", "5");
    return send_problem(res, 503, "shutting-down", "Shutting down",
                        "the server is stopping; submit again once it is back");
  }
  const std::string key = req.get_header_value("Idempotency-Key");
  if (key.size() > 255) {
    return send_problem(res, 400, "bad-request", "Bad request",
                        "Idempotency-Key must be at most 255 characters");
  }

  const hmpm::api::ParseResult parsed = hmpm::api::parse_job(spec, c.limits);
  if (!parsed.ok() || !parsed.job) {
    const std::string detail = std::to_string(parsed.errors.size()) +
                               (parsed.errors.size() == 1 ? " problem" : " problems") +
                               " in the job spec; see errors";
    return send_problem(res, 400, "invalid-spec", "Invalid job spec", detail,
                        Json{{"errors", spec_issues(parsed.errors)}});
  }

  NewJob job;
  job.id = new_uuid_v4();
  job.name = parsed.job->name;
  job.spec = spec;
  job.cost = cost_of(parsed.job->cost);
  job.idempotency_key = key;
  if (!key.empty()) job.body_sha256 = sha256_hex(body);
  const SubmitResult submitted = c.store.submit(job, c.config.max_queue);
  // The 201 also carries the spec's warnings (runnable, but worth knowing);
  // the run's summary.json repeats them.
  const auto accepted_document = [&] {
    Json doc = status_document(submitted.job);
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
      res.set_header("Retry-After", "30");
      return send_problem(
          res, 503, "queue-full", "Queue full",
          "the queue holds " + std::to_string(c.config.max_queue) + " jobs already; retry later");
  }
}

void list_jobs(Context& c, const httplib::Request& req, httplib::Response& res) {
  std::vector<JobStatus> statuses;
  for (std::size_t i = 0; i < req.get_param_value_count("status"); ++i) {
    std::string values = req.get_param_value("status", i);
    std::size_t start = 0;
    while (start <= values.size()) {
      const std::size_t comma = std::min(values.find(',', start), values.size());
      const std::string value = values.substr(start, comma - start);
      const auto status = parse_status(value);
      if (!status) {
        return send_invalid_parameter(res, "status must be " + status_names_text(), "status",
                                      "unknown status '" + value + "'");
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
      return send_invalid_parameter(res, "limit must be an integer from 1 to 1000", "limit",
                                    "must be 1..1000");
    }
  }
  Json jobs = Json::array();
  for (const JobRecord& job : c.store.list(statuses, limit)) jobs.push_back(status_document(job));
  const auto n = jobs.size();
  send_json(res, 200,
            Json{{"jobs", std::move(jobs)},
                 {"numberReturned", n},
                 {"links", Json::array({link("/jobs", "self", "application/json", "job list")})}});
}

void get_job(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = c.store.find(req.matches[1]);
  if (!job) return send_no_such_job(res, req.matches[1]);
  send_json(res, 200, status_document(*job));
}

void get_job_spec(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = c.store.find(req.matches[1]);
  if (!job) return send_no_such_job(res, req.matches[1]);
  res.set_content(job->spec, "application/json");  // exactly the bytes submitted
}

void dismiss_job(Context& c, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  const auto before = c.store.dismiss(id);
  if (!before) return send_no_such_job(res, id);
  if (before->status == JobStatus::running) {
    c.workers.cancel(id);  // the worker removes its partial files
  } else if (is_terminal(before->status) && before->status != JobStatus::dismissed) {
    std::error_code ec;
    std::filesystem::remove_all(c.workers.job_dir(id), ec);
  }
  if (before->status != JobStatus::dismissed) {
    log_line({{"event", "job"},
              {"job", id},
              {"status", status_name(JobStatus::dismissed)},
              {"from", status_name(before->status)}});
  }
  const auto after = c.store.find(id);
  if (!after) return send_no_such_job(res, id);
  send_json(res, 200, status_document(*after));
}

}  // namespace hmpm::server::http
