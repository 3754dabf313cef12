// ensembles.cpp — the ensemble routes of contract v3: POST and GET
// /ensembles, GET and DELETE /ensembles/{id}, POST /ensembles/{id}/cancel,
// GET /ensembles/{id}/results and /results/{samples.json, statistics.json}.
//
// An ensemble is stored with all its samples, each an ordinary job, in one
// store transaction (JobStore::submit_ensemble): a crash before the commit
// leaves nothing, one after it the whole ensemble, which every server then
// runs like any other jobs. Every sample's spec is parsed before anything
// is stored, so a sample the spec's checks refuse (a drawn value out of
// range) refuses the ensemble with its JSON path. The status and progress
// are derived from the samples' on every read (ensembles::summarise);
// samples.json and statistics.json are computed from the samples' own
// records and series.json files when asked for, so they always agree with
// them. Cancel and delete reuse what the job routes do to one job.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>

#include "digest.hpp"
#include "documents.hpp"
#include "ensembles/ensemble.hpp"
#include "handlers.hpp"
#include "job_log.hpp"
#include "problem.hpp"
#include "submission.hpp"

namespace hmpm::server::http {
namespace {

namespace ens = hmpm::server::ensembles;

const char* const what = "ensemble request";

// Lists with a status filter read this many ensembles before filtering.
constexpr int filtered_list_scan = 10'000;

std::optional<EnsembleRecord> find_ensemble(Context& c, const std::string& id,
                                            httplib::Response& res) {
  auto e = c.store.find_ensemble(id);
  if (!e) send_not_found(res, "no ensemble with id " + id);
  return e;
}

ens::Summary summary_of(const EnsembleRecord& e) {
  std::vector<ens::SampleState> states;
  states.reserve(e.jobs.size());
  for (const EnsembleSample& s : e.jobs) states.push_back({s.status, s.progress});
  return ens::summarise(states);
}

Json ensemble_document(const EnsembleRecord& e) {
  const ens::Summary s = summary_of(e);
  const std::string self = "/ensembles/" + e.id;
  Json jobs = Json::array();
  for (const EnsembleSample& sample : e.jobs) jobs.push_back(sample.job_id);
  return Json{{"ensembleID", e.id},
              {"status", status_name(s.status)},
              {"progress", whole_percent(s.progress)},
              {"samples", e.samples},
              {"seed", e.seed},
              {"state", ensemble_state_name(e.state)},
              {"created", e.created},
              {"updated", e.updated},
              {"counts", Json(s.counts)},
              {"jobs", std::move(jobs)},
              {"links", Json::array({link(self, "self", "application/json", "this ensemble"),
                                     link(self + "/results", "results", "application/json",
                                          "manifest of samples.json and statistics.json")})}};
}

// The request as stored (validated when it was submitted).
std::optional<ens::Request> stored_request(const EnsembleRecord& e) {
  std::vector<hmpm::api::SpecError> errors;
  return ens::read_request(nlohmann::json::parse(e.request, nullptr, false), errors);
}

// 422 limit-exceeded: more samples than the queue may ever hold.
void send_too_many_samples(const Context& c, httplib::Response& res, int samples) {
  send_problem(res, 422, "limit-exceeded", "Ensemble over this server's limits",
               "max_queue: the ensemble has " + std::to_string(samples) +
                   " samples, the queue holds at most " + std::to_string(c.config.max_queue) +
                   " jobs (hmpm-server --max-queue)",
               Json{{"limits", Json::array({Json{{"limit", "max_queue"},
                                                 {"value", c.config.max_queue},
                                                 {"estimate", samples},
                                                 {"unit", "jobs"},
                                                 {"option", "--max-queue"}}})}});
}

// Errors or warnings of sample k's spec as paths into the request body.
std::vector<hmpm::api::SpecError> in_request(const std::vector<hmpm::api::SpecError>& issues,
                                             int k) {
  std::vector<hmpm::api::SpecError> out;
  out.reserve(issues.size());
  for (const auto& e : issues)
    out.push_back({"/spec" + e.path, "sample " + std::to_string(k) + ": " + e.message});
  return out;
}

}  // namespace

void post_ensemble(Context& c, const httplib::Request& req, httplib::Response& res,
                   const std::string& body) {
  const auto key = admit_submission(c, req, res);
  if (!key) return;
  const nlohmann::json document = nlohmann::json::parse(body, nullptr, false);
  if (document.is_discarded()) return send_invalid_spec(res, {{"", "the body is not JSON"}}, what);
  std::vector<hmpm::api::SpecError> errors;
  const auto request = ens::read_request(document, errors);
  if (!request) return send_invalid_spec(res, errors, what);
  if (request->samples > c.config.max_queue) return send_too_many_samples(c, res, request->samples);
  if (queued_jobs(c) + request->samples > c.config.max_queue) return send_queue_full(c, res);

  NewEnsemble ensemble;
  ensemble.id = new_uuid_v4();
  ensemble.request = document.dump();
  ensemble.seed = static_cast<std::int64_t>(request->seed);
  ensemble.idempotency_key = *key;
  if (!key->empty()) ensemble.body_sha256 = sha256_hex(body);
  std::vector<hmpm::api::SpecError> warnings;
  Json cost;
  {
    const ValidationGate::Turn turn = c.validation.enter();
    if (!turn) return send_validation_busy(c, res);
    const hmpm::api::Calibration calibration = server_calibration(c);
    for (int k = 0; k < request->samples; ++k) {
      std::string spec = ens::sample_spec(*request, k).dump(2);
      const hmpm::api::ParseResult parsed = hmpm::api::parse_job(spec, c.limits, calibration);
      if (!parsed.ok() || !parsed.job)
        return send_invalid_spec(res, in_request(parsed.errors, k), what);
      if (refuse_over_limits(c, res, parsed.job->cost, "sample " + std::to_string(k) + ": "))
        return;
      if (k == 0) {
        warnings = in_request(parsed.job->warnings, k);
        cost = cost_with_estimate(parsed.job->cost);
      }
      NewJob job;
      job.id = new_uuid_v4();
      job.name = parsed.job->name;
      job.spec = std::move(spec);
      job.cost = cost_of(parsed.job->cost);
      ensemble.samples.push_back(std::move(job));
    }
  }
  const EnsembleSubmitResult submitted = c.store.submit_ensemble(ensemble, c.config.max_queue);
  const auto accepted_document = [&] {
    Json doc = ensemble_document(submitted.ensemble);
    doc["cost"] = cost;  // of sample 0
    if (!warnings.empty()) doc["warnings"] = spec_issues(warnings);
    return doc;
  };
  switch (submitted.outcome) {
    case SubmitOutcome::created:
      log_line({{"event", "ensemble"},
                {"ensemble", ensemble.id},
                {"status", status_name(JobStatus::accepted)},
                {"samples", request->samples}});
      c.workers.notify();
      res.set_header("Location", "/ensembles/" + ensemble.id);
      return send_json(res, 201, accepted_document());
    case SubmitOutcome::replayed:
      res.set_header("Location", "/ensembles/" + submitted.ensemble.id);
      res.set_header("Idempotent-Replayed", "true");
      return send_json(res, 201, accepted_document());
    case SubmitOutcome::key_conflict:
      return send_problem(res, 422, "idempotency-key-reused", "Idempotency key reused",
                          "this Idempotency-Key was used for a different ensemble request",
                          Json{{"ensembleID", submitted.ensemble.id}});
    case SubmitOutcome::queue_full:
      return send_queue_full(c, res);
  }
}

void list_ensembles(Context& c, const httplib::Request& req, httplib::Response& res) {
  std::vector<JobStatus> statuses;
  int limit = 100;
  if (!read_list_parameters(req, res, statuses, limit)) return;
  Json out = Json::array();
  for (const EnsembleRecord& e :
       c.store.list_ensembles(statuses.empty() ? limit : filtered_list_scan)) {
    if (std::ssize(out) == limit) break;
    const JobStatus status = summary_of(e).status;
    if (!statuses.empty() && std::find(statuses.begin(), statuses.end(), status) == statuses.end())
      continue;
    out.push_back(ensemble_document(e));
  }
  const auto n = out.size();
  send_json(res, 200,
            Json{{"ensembles", std::move(out)},
                 {"numberReturned", n},
                 {"links",
                  Json::array({link("/ensembles", "self", "application/json", "ensemble list")})}});
}

void get_ensemble(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto e = find_ensemble(c, req.matches[1], res);
  if (e) send_json(res, 200, ensemble_document(*e));
}

void cancel_ensemble(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto e = find_ensemble(c, req.matches[1], res);
  if (!e) return;
  const JobStatus status = summary_of(*e).status;
  if (is_terminal(status)) {
    return send_problem(res, 409, "ensemble-finished", "Ensemble already ended",
                        std::string("every sample has already ended (the ensemble is ") +
                            status_name(status) + "); nothing was changed",
                        Json{{"ensembleID", e->id}, {"status", status_name(status)}});
  }
  // The state first: a cancel cut short (a crash) is finished by repeating it.
  c.store.set_ensemble_state(e->id, EnsembleState::cancelled);
  for (const EnsembleSample& sample : e->jobs)
    if (!is_terminal(sample.status)) cancel_one(c, sample.job_id);
  log_line({{"event", "ensemble"}, {"ensemble", e->id}, {"by", "cancel"}});
  const auto after = find_ensemble(c, e->id, res);
  if (after) send_json(res, 202, ensemble_document(*after));
}

void delete_ensemble(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto e = find_ensemble(c, req.matches[1], res);
  if (!e) return;
  c.store.set_ensemble_state(e->id, EnsembleState::deleted);
  for (const EnsembleSample& sample : e->jobs)
    if (!sample.results_deleted) delete_one(c, sample.job_id);
  if (e->state != EnsembleState::deleted)
    log_line({{"event", "ensemble"}, {"ensemble", e->id}, {"by", "delete"}});
  const auto after = find_ensemble(c, e->id, res);
  if (after) send_json(res, 200, ensemble_document(*after));
}

namespace {

// An ensemble whose results are asked for: nullopt (and the answer set)
// unless every sample has ended. A deleted one has none.
std::optional<EnsembleRecord> ended_ensemble(Context& c, const std::string& id,
                                             httplib::Response& res) {
  auto e = find_ensemble(c, id, res);
  if (!e) return std::nullopt;
  if (e->state == EnsembleState::deleted) {
    send_problem(res, 410, "ensemble-dismissed", "Ensemble dismissed",
                 "the ensemble was deleted; its samples' results are gone");
    return std::nullopt;
  }
  const ens::Summary s = summary_of(*e);
  if (!is_terminal(s.status)) {
    send_problem(res, 404, "result-not-ready", "Result not ready",
                 std::string("the ensemble is ") + status_name(s.status) +
                     "; its results appear when every sample has ended",
                 Json{{"ensembleID", e->id},
                      {"status", status_name(s.status)},
                      {"progress", whole_percent(s.progress)}});
    return std::nullopt;
  }
  return e;
}

// samples.json: each sample's index, job, status, attempts and the values
// it took, by JSON pointer into the spec.
Json samples_document(const EnsembleRecord& e) {
  const auto request = stored_request(e);
  Json samples = Json::array();
  Json vary = Json::array();
  if (request)
    for (const ens::Vary& v : request->vary) vary.push_back(v.path);
  for (const EnsembleSample& s : e.jobs) {
    Json values = Json::object();
    if (request) {
      const std::vector<nlohmann::json> drawn = ens::sample_values(*request, s.index);
      for (std::size_t j = 0; j < drawn.size(); ++j) values[request->vary[j].path] = drawn[j];
    }
    samples.push_back(Json{{"index", s.index},
                           {"jobID", s.job_id},
                           {"status", status_name(s.status)},
                           {"attempts", s.attempts},
                           {"values", std::move(values)}});
  }
  return Json{{"ensembleID", e.id},
              {"seed", e.seed},
              {"vary", std::move(vary)},
              {"samples", std::move(samples)}};
}

// statistics.json: ensembles::statistics over the series.json of every
// successful sample, read from the sample's own result files; `used` lists
// the samples in it, `missing` any successful one without a readable series.
Json statistics_document(Context& c, const EnsembleRecord& e) {
  std::vector<nlohmann::json> series;
  Json used = Json::array();
  Json missing = Json::array();
  for (const EnsembleSample& s : e.jobs) {
    if (s.status != JobStatus::successful) continue;
    const auto job = c.store.find(s.job_id);
    bool listed = false;
    if (job) {
      for (const ResultFile& f : c.store.results(s.job_id)) listed |= f.name == "series.json";
    }
    nlohmann::json parsed;
    if (listed) {
      std::ifstream in(c.files.results_dir(*job) / "series.json", std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      parsed = nlohmann::json::parse(text.str(), nullptr, false);
    }
    if (!listed || parsed.is_discarded() || !parsed.is_object()) {
      missing.push_back(s.index);
      continue;
    }
    series.push_back(std::move(parsed));
    used.push_back(s.index);
  }
  Json doc{{"ensembleID", e.id}};
  const nlohmann::json figures = ens::statistics(series);
  for (const auto& [k, v] : figures.items()) doc[k] = Json(v);
  doc["sample_indices"] = std::move(used);
  doc["missing"] = std::move(missing);
  return doc;
}

// The files of an ended ensemble's results, by name, as served.
std::vector<std::pair<std::string, std::string>> result_files(Context& c, const EnsembleRecord& e) {
  return {{"samples.json", dump(samples_document(e))},
          {"statistics.json", dump(statistics_document(c, e))}};
}

}  // namespace

void get_ensemble_manifest(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto e = ended_ensemble(c, req.matches[1], res);
  if (!e) return;
  Json files = Json::array();
  for (const auto& [name, text] : result_files(c, *e)) {
    files.push_back(Json{{"name", name},
                         {"size", text.size()},
                         {"media_type", "application/json"},
                         {"sha256", sha256_hex(text)},
                         {"href", "/ensembles/" + e->id + "/results/" + name}});
  }
  send_json(res, 200,
            Json{{"ensembleID", e->id},
                 {"status", status_name(summary_of(*e).status)},
                 {"files", std::move(files)}});
}

void get_ensemble_file(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto e = ended_ensemble(c, req.matches[1], res);
  if (!e) return;
  const std::string name = req.matches[2];
  if (name == "samples.json")
    return res.set_content(dump(samples_document(*e)), "application/json");
  if (name == "statistics.json")
    return res.set_content(dump(statistics_document(c, *e)), "application/json");
  send_not_found(res, "ensemble " + e->id + " has no result file named '" + name + "'");
}

}  // namespace hmpm::server::http
