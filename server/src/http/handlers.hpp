// handlers.hpp — the request handlers, by resource; routes.cpp maps them to paths.
//
// Path parameters arrive in `req.matches` (1: job id or id prefix, 2: result
// file name). Authentication, unknown query parameters, 404 and 405 are the
// router's business, not theirs.
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
void list_jobs(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job_spec(Context& c, const httplib::Request& req, httplib::Response& res);
void dismiss_job(Context& c, const httplib::Request& req, httplib::Response& res);
void cancel_job(Context& c, const httplib::Request& req, httplib::Response& res);
void get_job_log(Context& c, const httplib::Request& req, httplib::Response& res);
void validate_spec(Context& c, const httplib::Request& req, httplib::Response& res,
                   const std::string& body);

// results.cpp — the manifest and the files of a finished job.
void get_manifest(Context& c, const httplib::Request& req, httplib::Response& res);
void get_result_file(Context& c, const httplib::Request& req, httplib::Response& res);

// events.cpp — progress as Server-Sent Events.
void stream_events(Context& c, const httplib::Request& req, httplib::Response& res);

// ui.cpp — the dashboard's files, compiled in (server/ui).
void get_ui(Context& c, const httplib::Request& req, httplib::Response& res);

}  // namespace hmpm::server::http
