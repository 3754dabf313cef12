// job_status.hpp — the one table of job states (OGC API – Processes status codes).
//
// Everything in server/ that names, parses, counts or tests a job state
// derives from `job_statuses` below: the store's SQL, /metrics, the
// `?status=` parameter's error message, terminal-state checks. Adding a state
// means adding one row here (and a migration if the store constrains the
// column; the SQLite store's CHECK constraint is tested against this table).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace hmpm::server {

/// The contract's job states, in the order of `job_statuses`.
enum class JobStatus { accepted, running, successful, failed, dismissed };

/// One row of the table: the wire name and whether the state is final.
struct JobStatusInfo {
  JobStatus status;
  std::string_view name;  ///< as in the status document and the database
  bool terminal;          ///< the job never runs again (only dismissal changes it)
};

/// Every state, indexed by the enum's value.
inline constexpr std::array<JobStatusInfo, 5> job_statuses{{
    {JobStatus::accepted, "accepted", false},
    {JobStatus::running, "running", false},
    {JobStatus::successful, "successful", true},
    {JobStatus::failed, "failed", true},
    {JobStatus::dismissed, "dismissed", true},
}};

/// The row of `status`.
constexpr const JobStatusInfo& info(JobStatus status) {
  return job_statuses[static_cast<std::size_t>(status)];
}

/// "accepted", "running", ... (NUL-terminated: the names are literals).
inline const char* status_name(JobStatus status) {
  return info(status).name.data();
}

/// Inverse of status_name; nullopt for anything else.
inline std::optional<JobStatus> parse_status(std::string_view text) {
  for (const auto& row : job_statuses) {
    if (row.name == text) return row.status;
  }
  return std::nullopt;
}

/// successful, failed and dismissed never change again (except dismissal).
constexpr bool is_terminal(JobStatus status) {
  return info(status).terminal;
}

/// "accepted, running, successful, failed or dismissed", for messages.
inline std::string status_names_text() {
  std::string text;
  for (std::size_t i = 0; i < job_statuses.size(); ++i) {
    if (i > 0) text += i + 1 == job_statuses.size() ? " or " : ", ";
    text += job_statuses[i].name;
  }
  return text;
}

}  // namespace hmpm::server
