// job_limits.cpp — see job_limits.hpp.
#include "job_limits.hpp"

#include <unistd.h>

#include <algorithm>

namespace hmpm::server {

std::vector<LimitExceeded> exceeded_limits(const hmpm::api::CostEstimate& cost,
                                           const ServiceConfig& config) {
  std::vector<LimitExceeded> over;
  const auto check = [&](bool on, const char* limit, const char* option, const char* unit,
                         double value, double estimate) {
    if (on && estimate > value) over.push_back({limit, option, unit, value, estimate});
  };
  check(config.max_particle_steps > 0, "max_particle_steps", "--max-particle-steps",
        "particle-steps", static_cast<double>(config.max_particle_steps),
        static_cast<double>(cost.particle_steps));
  check(config.max_job_memory > 0, "max_job_memory", "--max-job-memory", "bytes",
        static_cast<double>(config.max_job_memory), static_cast<double>(cost.memory_bytes));
  return over;
}

std::int64_t default_job_memory(int workers) {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGE_SIZE);
  const double physical = pages > 0 && page > 0 ? static_cast<double>(pages) * page : 0.0;
  const double share = 0.5 * physical / std::max(workers, 1);
  return std::max<std::int64_t>(std::int64_t{64} << 20, static_cast<std::int64_t>(share));
}

}  // namespace hmpm::server
