// results.cpp — GET /jobs/{id}/results (manifest) and /jobs/{id}/results/{name}.
//
// Only names recorded in the manifest are served: no path is ever built from
// anything else the client sent.
#include <sys/stat.h>

#include <array>
#include <fstream>
#include <memory>
#include <sstream>
#include <string_view>

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

// The ETag: the manifest's SHA-256 and the file's identity on disk (inode,
// modification time), so a file rewritten in place, even with the same
// size, gets a new one.
std::string etag_of(const ResultFile& file, const struct stat& st) {
  std::ostringstream tag;
  tag << '"' << file.sha256 << '-' << std::hex << st.st_ino << '-'
      << (static_cast<long long>(st.st_mtim.tv_sec) * 1'000'000'000LL + st.st_mtim.tv_nsec) << '"';
  return tag.str();
}

// If-None-Match with the weak comparison RFC 9110 asks for: a list of
// entity tags, each possibly W/-prefixed, or "*".
bool none_match(const std::string& header, const std::string& etag) {
  std::string_view rest = header;
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (item == "*") return true;
    if (item.substr(0, 2) == "W/") item.remove_prefix(2);
    if (item == etag) return true;
  }
  return false;
}

struct Span {
  std::size_t offset = 0;
  std::size_t length = 0;
};

// The part of a `size`-byte file to send for the request's Range (parsed by
// httplib into req.ranges): the whole file for none, or for several ranges
// (answered 200 with everything, which RFC 9110 allows); nullopt when the one
// range lies past the end (416).
std::optional<Span> requested_span(const httplib::Request& req, std::size_t size, bool& partial) {
  partial = false;
  if (req.ranges.size() != 1) return Span{0, size};
  const auto [first, last] = req.ranges.front();
  std::size_t from = 0;
  std::size_t to = 0;  // inclusive
  if (first < 0) {     // bytes=-N: the last N bytes
    if (last <= 0 || size == 0) return std::nullopt;
    from = size - std::min(size, static_cast<std::size_t>(last));
    to = size - 1;
  } else {
    from = static_cast<std::size_t>(first);
    if (from >= size) return std::nullopt;
    to = last < 0 ? size - 1 : std::min(size - 1, static_cast<std::size_t>(last));
  }
  partial = true;
  return Span{from, to - from + 1};
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
  const auto path = c.files.results_dir(*job) / file->name;
  struct stat st {};
  auto in = std::make_shared<std::ifstream>(path, std::ios::binary);
  if (::stat(path.c_str(), &st) != 0 || !*in ||
      static_cast<std::int64_t>(st.st_size) != file->size) {
    log_line({{"event", "error"},
              {"job", job->id},
              {"detail", "result file missing or changed: " + file->name}});
    return send_problem(res, 500, "result-missing", "Result file missing",
                        "the result file is missing or was changed on the server");
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  const std::string etag = etag_of(*file, st);
  res.set_header("ETag", etag);
  res.set_header("Accept-Ranges", "bytes");
  if (req.has_header("If-None-Match") && none_match(req.get_header_value("If-None-Match"), etag)) {
    res.status = 304;
    return;
  }
  // If-Range: the range only if the client's copy is this one (a strong
  // comparison: a weak tag or a date never matches, as no Last-Modified is
  // sent); otherwise the whole file.
  if (req.has_header("If-Range") && req.get_header_value("If-Range") != etag)
    const_cast<httplib::Request&>(req).ranges.clear();
  bool partial = false;
  const auto span = requested_span(req, size, partial);
  // httplib applies req.ranges to the response itself, without checking them
  // against the size (a range past the end gave 206 and a broken body): the
  // range is served here, so it is cleared. The Request is a non-const local
  // of httplib's process_request, so the cast is safe.
  const_cast<httplib::Request&>(req).ranges.clear();
  if (!span) {
    res.set_header("Content-Range", "bytes */" + std::to_string(size));
    return send_problem(res, 416, "range-not-satisfiable", "Range not satisfiable",
                        "the file has " + std::to_string(size) + " bytes");
  }
  if (partial) {
    res.status = 206;
    res.set_header("Content-Range", "bytes " + std::to_string(span->offset) + "-" +
                                        std::to_string(span->offset + span->length - 1) + "/" +
                                        std::to_string(size));
  }
  res.set_header("Content-Disposition", "attachment; filename=\"" + file->name + "\"");
  res.set_content_provider(
      span->length, file->media_type,
      [in, base = span->offset](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        std::array<char, 1 << 16> buffer{};
        in->seekg(static_cast<std::streamoff>(base + offset));
        in->read(buffer.data(), static_cast<std::streamsize>(std::min(length, buffer.size())));
        const auto n = in->gcount();
        if (n <= 0) return false;
        return sink.write(buffer.data(), static_cast<std::size_t>(n));
      });
}

}  // namespace hmpm::server::http
