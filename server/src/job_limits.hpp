// job_limits.hpp — what one job may cost on this server, checked at submit
// from the cost estimate: particle-steps and memory (threads and series
// counted, api/src/cost.cpp). Each limit is an hmpm-server option; a job
// over one is refused with 422 limit-exceeded naming the limit, its value,
// the job's estimate and the option (docs/api.md, "Limits"). The particle
// count is bounded earlier, by the parser (hmpm::api::Limits::max_particles,
// from --max-particles), before anything is allocated per particle. The
// wall-time limit (--job-wall-time) is not checked against the estimate,
// which depends on the calibration: it stops the run itself, set-up
// included (RunOptions::wall_time_limit_s).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/server/service.hpp"

namespace hmpm::server {

/// One limit a job's estimate is over.
struct LimitExceeded {
  std::string limit;    ///< "max_particle_steps", "max_job_memory"
  std::string option;   ///< the hmpm-server option that sets it
  std::string unit;     ///< "particle-steps", "bytes"
  double value = 0;     ///< the limit
  double estimate = 0;  ///< the job's
};

/// Every limit of `config` that `cost` (estimated with this server's
/// threads per job and calibration) is over; empty: the job may run.
std::vector<LimitExceeded> exceeded_limits(const hmpm::api::CostEstimate& cost,
                                           const ServiceConfig& config);

/// The default of --max-job-memory: half the physical memory shared by the
/// workers (each may run a job at the same time), at least 64 MiB.
std::int64_t default_job_memory(int workers);

}  // namespace hmpm::server
