// retention.hpp — how long ended jobs and their files are kept.
//
// `hmpm-server --retain-days N` (ServiceConfig::retain_days, default 30; 0
// keeps everything): a job that ended (successful, failed, dismissed) more
// than N days ago is forgotten by the store and its folder
// `<data-dir>/<job id>/` (result files and log) is removed. Accepted and
// running jobs are never purged. The Service purges at start-up and every
// hour; the time is a parameter, so tests age jobs without waiting.
#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "hmpm/server/store.hpp"
#include "job_files.hpp"

namespace hmpm::server {

/// Purges the jobs that ended before `now` - `retain_days` days from `store`
/// and removes their folders (`files`); logs one line per job.
/// Returns the purged ids. `retain_days` <= 0: purges nothing.
std::vector<std::string> purge_expired(JobStore& store, const JobFiles& files, int retain_days,
                                       std::chrono::system_clock::time_point now);

}  // namespace hmpm::server
