// results.cpp — GET /jobs/{id}/results (manifest) and /jobs/{id}/results/{name}.
//
// Only names recorded in the manifest are served: no path is ever built from
// anything else the client sent.
#include <array>
#include <fstream>
#include <memory>

#include "documents.hpp"
#include "handlers.hpp"
#include "job_log.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

// A job whose results are asked for: nullopt (and the answer set) unless
// finished. A cancelled job has finished with whatever it wrote; a deleted
// one has none.
std::optional<JobRecord> finished_job(Context& c, const std::string& ref, httplib::Response& res) {
  auto job = find_job(c, ref, res);
  if (!job) return std::nullopt;
  const std::string& id = job->id;
  if (job->results_deleted) {
    send_problem(res, 410, "job-dismissed", "Job dismissed",
                 "the job was deleted; its results are gone");
    return std::nullopt;
  }
  if (!is_terminal(job->status)) {
    send_problem(res, 404, "result-not-ready", "Result not ready",
                 std::string("the job is ") + status_name(job->status) +
                     "; its results appear when it has finished",
                 Json{{"jobID", id},
                      {"jobStatus", status_name(job->status)},
                      {"progress", whole_percent(job->progress)}});
    return std::nullopt;
  }
  return job;
}

}  // namespace

void get_manifest(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = finished_job(c, req.matches[1], res);
  if (!job) return;
  Json files = Json::array();
  for (const ResultFile& f : c.store.results(job->id)) {
    files.push_back(Json{{"name", f.name},
                         {"size", f.size},
                         {"media_type", f.media_type},
                         {"sha256", f.sha256},
                         {"href", "/jobs/" + job->id + "/results/" + f.name}});
  }
  send_json(res, 200,
            Json{{"jobID", job->id}, {"status", status_name(job->status)}, {"files", files}});
}

void get_result_file(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto job = finished_job(c, req.matches[1], res);
  if (!job) return;
  const std::string name = req.matches[2];
  std::optional<ResultFile> file;
  for (ResultFile& f : c.store.results(job->id)) {
    if (f.name == name) file = std::move(f);
  }
  if (!file)
    return send_not_found(res, "job " + job->id + " has no result file named '" + name + "'");
  const auto path = c.workers.job_dir(job->id) / file->name;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  auto in = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (ec || !*in || static_cast<std::int64_t>(size) != file->size) {
    log_line({{"event", "error"},
              {"job", job->id},
              {"detail", "result file missing or changed: " + file->name}});
    return send_problem(res, 500, "result-missing", "Result file missing",
                        "the result file is missing or was changed on the server");
  }
  const std::string etag = "\"" + file->sha256 + "\"";
  res.set_header("ETag", etag);
  if (req.get_header_value("If-None-Match") == etag) {
    res.status = 304;
    return;
  }
  res.set_header("Content-Disposition", "attachment; filename=\"" + file->name + "\"");
  res.set_content_provider(
      size, file->media_type,
      [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        std::array<char, 1 << 16> buffer{};
        in->seekg(static_cast<std::streamoff>(offset));
        in->read(buffer.data(), static_cast<std::streamsize>(std::min(length, buffer.size())));
        const auto n = in->gcount();
        if (n <= 0) return false;
        return sink.write(buffer.data(), static_cast<std::size_t>(n));
      });
}

}  // namespace hmpm::server::http
