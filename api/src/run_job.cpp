// run_job.cpp — placeholder while the writers are written.
#include "hmpm/api/job.hpp"

namespace hmpm::api {

JobOutcome run_job(const ParsedJob& job, const std::filesystem::path&, const hmpm::RunOptions& options) {
  JobOutcome out;
  out.run = hmpm::run(job.problem, options);
  return out;
}

std::string media_type_for(std::string_view name) {
  auto ends = [&](std::string_view s) { return name.size() >= s.size() && name.substr(name.size() - s.size()) == s; };
  if (ends(".json")) return "application/json";
  if (ends(".csv")) return "text/csv";
  if (ends(".pvd") || ends(".vtu")) return "application/xml";
  return "application/octet-stream";
}

}  // namespace hmpm::api
