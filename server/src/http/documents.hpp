// documents.hpp — the JSON documents that describe a job.
//
// The status document (OGC API – Processes `statusInfo` plus hmpm's extras:
// name, attempts, cost, run time) is built here and nowhere else; the job
// list, the 201 of a submission, the event stream and dismissal all send it.
#pragma once

#include <string>

#include "hmpm/server/store.hpp"
#include "problem.hpp"

namespace hmpm::server::http {

/// `progress` as the whole percent the documents show (0..100).
int whole_percent(double progress);

/// A link object {href, rel, type, title}.
Json link(const std::string& href, const char* rel, const char* type, const char* title);

/// The `cost` member of the status document (and of POST /validate).
Json cost_document(const JobCost& cost);

/// The `run` member of the status document: what the run reached (the
/// solver's simulated time and end time, steps, the time-step range).
Json run_document(const RunProgress& run);

/// The status document of `job`.
Json status_document(const JobRecord& job);

}  // namespace hmpm::server::http
