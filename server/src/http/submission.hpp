// submission.hpp — what the routes that submit and list jobs share (jobs.cpp
// defines it): POST /jobs and POST /ensembles answer the same 503s, 400
// invalid-spec, 422 limit-exceeded and idempotency outcomes; GET /jobs and
// GET /ensembles read the same `status` and `limit` parameters.
#pragma once

#include <httplib.h>

#include <optional>
#include <string>
#include <vector>

#include "context.hpp"
#include "problem.hpp"

namespace hmpm::server::http {

/// The store's copy of parse_job's estimate.
JobCost cost_of(const hmpm::api::CostEstimate& c);

/// This server's calibration and threads per job, to parse a spec with.
hmpm::api::Calibration server_calibration(const Context& c);

/// The cost document with every scheme's wall-time estimate (the 201 of a
/// submission, POST /validate).
Json cost_with_estimate(const hmpm::api::CostEstimate& cost);

/// Spec errors or warnings as [{path, message}] (at most 200).
Json spec_issues(const std::vector<hmpm::api::SpecError>& issues);

/// 400 invalid-spec listing `errors`; `what` names the document ("job spec").
void send_invalid_spec(httplib::Response& res, const std::vector<hmpm::api::SpecError>& errors,
                       const std::string& what = "job spec");

/// 422 limit-exceeded when the estimate is over a limit of this server;
/// returns whether it answered. `prefix` opens the detail ("sample 3: ").
bool refuse_over_limits(const Context& c, httplib::Response& res,
                        const hmpm::api::CostEstimate& cost, const std::string& prefix = "");

/// 503 validation-busy (every validation turn is taken).
void send_validation_busy(const Context& c, httplib::Response& res);

/// 503 queue-full with Retry-After.
void send_queue_full(const Context& c, httplib::Response& res);

/// Jobs waiting to run (status accepted).
std::int64_t queued_jobs(Context& c);

/// The checks every submission starts with: 503 shutting-down while the
/// server stops, 400 for an Idempotency-Key over 255 characters. Returns the
/// key ("" for none), or nullopt when it answered.
std::optional<std::string> admit_submission(const Context& c, const httplib::Request& req,
                                            httplib::Response& res);

/// The `status` (comma-separated, repeatable) and `limit` (1..1000, default
/// 100) parameters of a list; false when it answered 400 invalid-parameter.
bool read_list_parameters(const httplib::Request& req, httplib::Response& res,
                          std::vector<JobStatus>& statuses, int& limit);

/// POST /jobs/{id}/cancel for one job already found: the store's cancel, the
/// job's run log and log line, and a moment for this server's worker to
/// record the files written so far. The row as it was before (nullopt: gone).
std::optional<JobRecord> cancel_one(Context& c, const std::string& id);

/// DELETE /jobs/{id} for one job already found: the store's dismissal, its
/// files removed (by this server's worker if it runs the job), the log
/// line. The row as it was before (nullopt: gone).
std::optional<JobRecord> delete_one(Context& c, const std::string& id);

}  // namespace hmpm::server::http
