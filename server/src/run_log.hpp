// run_log.hpp — each job's own log: `<data-dir>/<job id>/job.log`, plain text.
//
// The worker that runs a job writes it (start, progress about every 10 % or
// 10 s, the spec's warnings, the end with its reason); the HTTP handlers
// append the client's actions (cancel) and serve it at GET /jobs/{id}/log
// while the job runs. One line per event, "<RFC 3339 time> <text>", each
// line one append (O_APPEND), so lines from two writers never interleave.
// The file lives in the job's folder and goes with it when the job is
// deleted; it is not a result file (the manifest does not list it).
#pragma once

#include <chrono>
#include <filesystem>
#include <string>

namespace hmpm::server {

/// The log file's name inside the job's folder.
inline constexpr const char* run_log_name = "job.log";

/// Appends "<now> <text>\n" to `<job_dir>/job.log`, creating the folder and
/// the file if needed. Never throws: a log line is not worth a failed job.
void append_run_log(const std::filesystem::path& job_dir, const std::string& text);

/// When a running job's progress deserves a log line: every 10 % of the
/// simulated time or every 10 s of wall time, whichever comes first.
class ProgressLogPacer {
 public:
  /// True (and the pace restarts) on the first call, when `fraction` (0..1)
  /// crossed the next tenth, or when 10 s passed since the last line.
  bool due(double fraction, std::chrono::steady_clock::time_point now);

 private:
  int next_tenth_ = 1;
  std::chrono::steady_clock::time_point last_{};
  bool started_ = false;
};

}  // namespace hmpm::server
