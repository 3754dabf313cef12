// documents.cpp — see documents.hpp.
#include "documents.hpp"

#include <algorithm>
#include <cmath>

namespace hmpm::server::http {
namespace {

Json timestamp_or_null(const std::string& t) {
  return t.empty() ? Json(nullptr) : Json(t);
}

}  // namespace

int whole_percent(double progress) {
  return static_cast<int>(std::clamp(std::floor(progress), 0.0, 100.0));
}

Json link(const std::string& href, const char* rel, const char* type, const char* title) {
  return Json{{"href", href}, {"rel", rel}, {"type", type}, {"title", title}};
}

Json cost_document(const JobCost& cost) {
  return Json{{"particles", cost.particles},
              {"nodes", cost.nodes},
              {"cells", cost.cells},
              {"steps", cost.steps},
              {"dt", cost.dt},
              {"particle_steps", cost.particle_steps},
              {"memory_bytes", cost.memory_bytes},
              {"output_bytes", cost.output_bytes}};
}

Json run_document(const RunProgress& run) {
  Json doc{{"simulated_time", run.time}, {"end_time", run.end_time}, {"steps", run.steps}};
  if (run.dt_max > 0) {
    doc["dt_min"] = run.dt_min;
    doc["dt_max"] = run.dt_max;
  }
  return doc;
}

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
  if (job.status == JobStatus::accepted && job.queue_position > 0)
    doc["queue_position"] = job.queue_position;
  doc["cost"] = cost_document(job.cost);
  if (job.run.end_time > 0) doc["run"] = run_document(job.run);
  if (job.run_seconds > 0) doc["run_seconds"] = job.run_seconds;
  doc["links"] = Json::array(
      {link(self, "self", "application/json", "this status document"),
       link(self + "/results", "results", "application/json", "manifest of the result files"),
       link(self + "/events", "events", "text/event-stream", "progress as Server-Sent Events"),
       link(self + "/log", "log", "text/plain", "the job's log")});
  if (!job.ensemble_id.empty()) {
    doc["ensemble"] = Json{{"ensembleID", job.ensemble_id}, {"index", job.ensemble_index}};
    doc["links"].push_back(link("/ensembles/" + job.ensemble_id, "up", "application/json",
                                "the ensemble this job is a sample of"));
  }
  return doc;
}

}  // namespace hmpm::server::http
