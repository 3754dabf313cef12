// retention.cpp — see retention.hpp.
#include "retention.hpp"

#include <system_error>

#include "clock.hpp"
#include "job_log.hpp"

namespace hmpm::server {
namespace {

// A job id as the service makes them: a UUID, 36 lowercase hex digits and dashes.
bool looks_like_job_id(const std::string& name) {
  if (name.size() != 36) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? c != '-' : !((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

// Folders of jobs the store no longer knows (a crash between forgetting the
// rows and removing the folders), untouched since before `cutoff`: a folder
// is only made for a stored job, so an unknown one belongs to no one.
void remove_orphans(JobStore& store, const std::filesystem::path& data_dir,
                    std::filesystem::file_time_type cutoff) {
  std::error_code ec;
  std::vector<std::filesystem::path> orphans;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::error_code time_ec;
    const auto written = std::filesystem::last_write_time(entry.path(), time_ec);
    if (!entry.is_directory(time_ec) || !looks_like_job_id(name) || time_ec || written >= cutoff)
      continue;
    if (!store.find(name)) orphans.push_back(entry.path());
  }
  for (const auto& path : orphans) {
    std::filesystem::remove_all(path, ec);
    log_line({{"event", "purge"}, {"folder", path.string()}, {"orphan", true}});
  }
}

}  // namespace

std::vector<std::string> purge_expired(JobStore& store, const JobFiles& files, int retain_days,
                                       std::chrono::system_clock::time_point now) {
  if (retain_days <= 0) return {};
  const auto cutoff = now - std::chrono::hours(24) * retain_days;
  // The rows go first: once a job is unknown nothing serves its files, and a
  // folder left by a crash in between holds no job anyone can ask for.
  std::vector<std::string> ids = store.purge_ended(cutoff);
  for (const std::string& id : ids) {
    const bool removed = files.remove(id);
    log_line({{"event", "purge"},
              {"job", id},
              {"ended_before", format_rfc3339(cutoff)},
              {"files_removed", removed}});
  }
  // file_time_type's clock is not system_clock: carry the age over.
  const auto age = std::chrono::system_clock::now() - cutoff;
  remove_orphans(store, files.data_dir(),
                 std::filesystem::file_time_type::clock::now() -
                     std::chrono::duration_cast<std::filesystem::file_time_type::duration>(age));
  return ids;
}

}  // namespace hmpm::server
