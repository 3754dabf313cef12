// handlers.hpp — the request handlers, by resource; routes.cpp maps them to paths.
//
// Path parameters arrive in `req.matches` (1: job id, id prefix or process
// id, 2: result file name). Authentication, unknown query parameters, 404
// and 405 are the router's business, not theirs.
#pragma once

#include <httplib.h>

#include <optional>
#include <string>

#include "context.hpp"

namespace hmpm::server::http {

/// The job `ref` names: its full id, or a prefix of at least 4 hex digits
/// that only one job's id starts with. Otherwise answers 404 (no such job)
/// or 409 ambiguous-id (with the candidates) and returns nullopt.
std::optional<JobRecord> find_job(Context& c, const std::string& ref, httplib::Response& res);

// health.cpp — service state.
void get_health(Context& c, const httplib::Request& req, httplib::Response& res);
void get_metrics(Context& c, const httplib::Request& req, httplib::Response& res);

// jobs.cpp — the job collection and one job.
void post_job(Context& c, const httplib::Request& req, httplib::Response& res,
              const std::string& body);
/// What POST /jobs does with `spec` (parse, store, queue; idempotency, 503s,
/// the 201 or 400 answer), for every route that submits a job. `body` is the
/// request body, the bytes an Idempotency-Key's replay is compared on.
void submit_job(Context& c, const httplib::Request& req, httplib::Response& res,
                const std::string& spec, const std::string& body);
void list_jobs(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job_spec(Context& c, const httplib::Request& req, httplib::Response& res);
void dismiss_job(Context& c, const httplib::Request& req, httplib::Response& res);
void cancel_job(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job_log(Context& c, const httplib::Request& req, httplib::Response& res);
void validate_spec(Context& c, const httplib::Request& req, httplib::Response& res,
                   const std::string& body);

// ensembles.cpp — ensembles of jobs (contract v3); path parameter 1 is the
// ensemble id, 2 a result file name.
void post_ensemble(Context& c, const httplib::Request& req, httplib::Response& res,
                   const std::string& body);
void list_ensembles(Context& c, const httplib::Request& req, httplib::Response& res);
void get_ensemble(Context& c, const httplib::Request& req, httplib::Response& res);
void cancel_ensemble(Context& c, const httplib::Request& req, httplib::Response& res);
void delete_ensemble(Context& c, const httplib::Request& req, httplib::Response& res);
void get_ensemble_manifest(Context& c, const httplib::Request& req, httplib::Response& res);
void get_ensemble_file(Context& c, const httplib::Request& req, httplib::Response& res);

// results.cpp — the manifest and the files of a finished job.
void get_manifest(Context& c, const httplib::Request& req, httplib::Response& res);
void get_result_file(Context& c, const httplib::Request& req, httplib::Response& res);

// events.cpp — progress as Server-Sent Events.
void stream_events(Context& c, const httplib::Request& req, httplib::Response& res);

// ogc.cpp — OGC API – Processes: landing page, conformance, the hmpm process.
// (Job list, status, results and dismissal are the /jobs routes.)
void get_landing_page(Context& c, const httplib::Request& req, httplib::Response& res);
void get_conformance(Context& c, const httplib::Request& req, httplib::Response& res);
void list_processes(Context& c, const httplib::Request& req, httplib::Response& res);
void get_process(Context& c, const httplib::Request& req, httplib::Response& res);
void execute_process(Context& c, const httplib::Request& req, httplib::Response& res,
                     const std::string& body);

// fields.cpp — the output fields with their kinds and units (no token).
void get_fields(Context& c, const httplib::Request& req, httplib::Response& res);

// ui.cpp — the dashboard's files, compiled in (server/ui).
void get_ui(Context& c, const httplib::Request& req, httplib::Response& res);

}  // namespace hmpm::server::http
