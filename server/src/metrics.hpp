// metrics.hpp — counters for GET /metrics in the Prometheus text format.
//
// Request and job counters live in memory (they describe this process, as
// Prometheus expects; a restart resets them). Job counts by status and the
// queue length come from the database at scrape time, so they survive
// restarts, never drift, and are the same on every server sharing one
// PostgreSQL database (hmpm_instance_info tells the servers apart).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "hmpm/server/store.hpp"

namespace hmpm::server {

class Metrics {
 public:
  /// Counts one answered HTTP request by status code.
  void count_request(int status);
  /// Records how long a finished attempt ran and how it ended.
  void observe_job(double seconds, JobStatus outcome);
  /// Server-Sent Events streams now open (gauge maintained by the caller).
  std::atomic<int> open_streams{0};
  /// Jobs a worker is running right now.
  std::atomic<int> busy_workers{0};
  /// Writes of this server refused because another claim replaced its own
  /// (a takeover after its lease lapsed): the fencing at work.
  std::atomic<int> claims_lost{0};
  /// Jobs whose lapsed lease this server's recovery took back (requeued or failed).
  std::atomic<int> recovered_jobs{0};
  /// This server's instance id (claims carry it), set once at start-up.
  std::string instance;

  /// The exposition text: `counts` are the jobs per status in the store.
  std::string render(const StatusCounts& counts, int workers) const;

 private:
  static constexpr std::array<double, 10> bucket_bounds{0.1, 0.5, 1, 2, 5, 10, 30, 60, 300, 3600};
  mutable std::mutex mutex_;
  std::map<int, std::uint64_t> requests_by_status_;
  std::array<std::uint64_t, bucket_bounds.size()> duration_buckets_{};
  std::uint64_t duration_count_ = 0;
  double duration_sum_ = 0.0;
  std::map<JobStatus, std::uint64_t> finished_by_outcome_;
};

}  // namespace hmpm::server
