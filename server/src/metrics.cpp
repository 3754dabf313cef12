// metrics.cpp — see metrics.hpp.
#include "metrics.hpp"

#include <sstream>

namespace hmpm::server {

void Metrics::count_request(int status) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++requests_by_status_[status];
}

void Metrics::observe_job(double seconds, JobStatus outcome) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t i = 0; i < bucket_bounds.size(); ++i) {
    if (seconds <= bucket_bounds[i]) ++duration_buckets_[i];
  }
  ++duration_count_;
  duration_sum_ += seconds;
  ++finished_by_outcome_[outcome];
}

std::string Metrics::render(const StatusCounts& counts, int workers) const {
  std::ostringstream out;
  out << "# HELP hmpm_instance_info This server's instance id (the owner of its claims).\n"
         "# TYPE hmpm_instance_info gauge\nhmpm_instance_info{instance=\""
      << instance << "\"} 1\n";
  out << "# HELP hmpm_jobs Jobs in the store by status.\n# TYPE hmpm_jobs gauge\n";
  for (const auto& row : job_statuses) {
    const auto it = counts.find(row.status);
    out << "hmpm_jobs{status=\"" << row.name << "\"} " << (it == counts.end() ? 0 : it->second)
        << "\n";
  }
  const auto queued = counts.find(JobStatus::accepted);
  out << "# HELP hmpm_queue_length Jobs waiting for a worker.\n# TYPE hmpm_queue_length gauge\n"
      << "hmpm_queue_length " << (queued == counts.end() ? 0 : queued->second) << "\n";
  out << "# HELP hmpm_workers Worker threads.\n# TYPE hmpm_workers gauge\nhmpm_workers " << workers
      << "\n";
  out << "# HELP hmpm_workers_busy Workers running a job.\n# TYPE hmpm_workers_busy gauge\n"
      << "hmpm_workers_busy " << busy_workers.load() << "\n";
  out << "# HELP hmpm_event_streams Open Server-Sent Events streams.\n"
         "# TYPE hmpm_event_streams gauge\nhmpm_event_streams "
      << open_streams.load() << "\n";

  out << "# HELP hmpm_claims_lost_total Writes refused because another server took the job "
         "over.\n# TYPE hmpm_claims_lost_total counter\nhmpm_claims_lost_total "
      << claims_lost.load() << "\n";
  out << "# HELP hmpm_jobs_recovered_total Jobs with a lapsed lease this server took back.\n"
         "# TYPE hmpm_jobs_recovered_total counter\nhmpm_jobs_recovered_total "
      << recovered_jobs.load() << "\n";

  std::lock_guard<std::mutex> lock(mutex_);
  out << "# HELP hmpm_job_duration_seconds Wall time of finished job attempts.\n"
         "# TYPE hmpm_job_duration_seconds histogram\n";
  for (std::size_t i = 0; i < bucket_bounds.size(); ++i) {
    out << "hmpm_job_duration_seconds_bucket{le=\"" << bucket_bounds[i] << "\"} "
        << duration_buckets_[i] << "\n";
  }
  out << "hmpm_job_duration_seconds_bucket{le=\"+Inf\"} " << duration_count_ << "\n"
      << "hmpm_job_duration_seconds_sum " << duration_sum_ << "\n"
      << "hmpm_job_duration_seconds_count " << duration_count_ << "\n";
  out << "# HELP hmpm_jobs_finished_total Job attempts finished since start, by outcome.\n"
         "# TYPE hmpm_jobs_finished_total counter\n";
  for (const auto& [status, n] : finished_by_outcome_) {
    out << "hmpm_jobs_finished_total{status=\"" << status_name(status) << "\"} " << n << "\n";
  }
  out << "# HELP hmpm_http_requests_total HTTP requests answered, by status code.\n"
         "# TYPE hmpm_http_requests_total counter\n";
  for (const auto& [code, n] : requests_by_status_) {
    out << "hmpm_http_requests_total{code=\"" << code << "\"} " << n << "\n";
  }
  return out.str();
}

}  // namespace hmpm::server
