// context.hpp — what a request handler may use: the service's parts, by reference.
//
// Handlers are free functions of (Context&, request, response); they read
// and write the store and nudge the workers, never run solver work.
#pragma once

#include <atomic>

#include "hmpm/api/job.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"
#include "job_files.hpp"
#include "metrics.hpp"
#include "validation_gate.hpp"
#include "workers/pool.hpp"

namespace hmpm::server::http {

struct Context {
  const ServiceConfig& config;
  const hmpm::api::Limits& limits;
  JobStore& store;
  Metrics& metrics;
  WorkerPool& workers;
  const JobFiles& files;              ///< the jobs' folders (log, results)
  const std::atomic<bool>& stopping;  ///< set by Service::stop()
  ValidationGate& validation;         ///< turns to parse a spec (POST /jobs, /validate)
};

}  // namespace hmpm::server::http
