// job_files.cpp — see job_files.hpp.
#include "job_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "digest.hpp"
#include "hmpm/api/job.hpp"
#include "run_log.hpp"

namespace hmpm::server {
namespace {

// Checkpoint files: "checkpoint-<claim token>-<step>.hmpmck" (never a result file).
constexpr const char* checkpoint_prefix = "checkpoint-";
constexpr const char* checkpoint_suffix = ".hmpmck";

bool is_checkpoint_file(const std::string& name) {
  return name.rfind(checkpoint_prefix, 0) == 0;
}

}  // namespace

std::filesystem::path JobFiles::log_file(const std::string& id) const {
  return job_dir(id) / run_log_name;
}

std::filesystem::path JobFiles::attempt_dir(const Claim& claim) const {
  return job_dir(claim.job_id) / attempt_name(claim.token);
}

std::filesystem::path JobFiles::results_dir(const JobRecord& job) const {
  std::filesystem::path dir = job_dir(job.id) / attempt_name(job.lease_token);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) dir = job_dir(job.id);  // an older server's layout
  return dir;
}

bool JobFiles::remove(const std::string& id) const {
  std::error_code ec;
  std::filesystem::remove_all(job_dir(id), ec);
  return !ec;
}

std::string attempt_name(std::int64_t token) {
  return "attempt-" + std::to_string(token);
}

std::string checkpoint_path(const Claim& claim, std::int64_t step) {
  return attempt_name(claim.token) + "/" + checkpoint_prefix + std::to_string(claim.token) + "-" +
         std::to_string(step) + checkpoint_suffix;
}

void remove_all_but_log(const std::filesystem::path& dir, const std::string& keep) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != run_log_name && (keep.empty() || name != keep))
      std::filesystem::remove_all(entry.path(), ec);
  }
}

void remove_unlisted(const std::filesystem::path& dir, const std::vector<ResultFile>& listed) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const bool kept =
        name == run_log_name || std::any_of(listed.begin(), listed.end(),
                                            [&](const ResultFile& f) { return f.name == name; });
    if (!kept) std::filesystem::remove_all(entry.path(), ec);
  }
}

void carry_over(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::filesystem::create_directories(to);
  for (const auto& entry : std::filesystem::directory_iterator(from)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || name == run_log_name || is_checkpoint_file(name) ||
        entry.path().extension() == ".tmp")
      continue;
    std::filesystem::copy_file(entry.path(), to / name,
                               std::filesystem::copy_options::overwrite_existing);
  }
}

void remove_checkpoints_but(const std::filesystem::path& dir, const std::string& keep) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (is_checkpoint_file(name) && name != keep) std::filesystem::remove(entry.path(), ec);
  }
}

void write_durably(const std::filesystem::path& path, const std::string& bytes) {
  const std::string tmp = path.string() + ".tmp";
  auto fail = [&](const char* what) {
    const std::string message = std::string(what) + " " + tmp + ": " + std::strerror(errno);
    ::unlink(tmp.c_str());
    throw std::runtime_error(message);
  };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("cannot create");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      fail("cannot write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("cannot sync");
  }
  if (::close(fd) != 0) fail("cannot close");
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("cannot rename");
  const int dir = ::open(path.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

std::string read_checkpoint_file(const std::filesystem::path& path, std::int64_t expected_size) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) {
    throw std::runtime_error(errno == ENOENT
                                 ? std::string("is missing")
                                 : std::string("cannot be opened: ") + std::strerror(errno));
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw std::runtime_error(std::string("cannot be examined: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) {
    const char* kind = S_ISDIR(st.st_mode)    ? "a directory"
                       : S_ISFIFO(st.st_mode) ? "a FIFO"
                       : S_ISCHR(st.st_mode)  ? "a character device"
                       : S_ISBLK(st.st_mode)  ? "a block device"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw std::runtime_error(std::string("is ") + kind + ", not a regular file");
  }
  if (st.st_size != expected_size) {
    throw std::runtime_error("has " + std::to_string(st.st_size) + " bytes, " +
                             std::to_string(expected_size) + " recorded");
  }
  std::string bytes(static_cast<std::size_t>(expected_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) throw std::runtime_error(std::string("cannot be read: ") + std::strerror(errno));
    if (n == 0) throw std::runtime_error("ended after " + std::to_string(done) + " bytes");
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

std::optional<std::string> record_files(const std::filesystem::path& dir,
                                        const std::vector<std::string>& names,
                                        std::vector<ResultFile>& files) {
  std::optional<std::string> unreadable;
  for (const std::string& name : names) {
    const auto path = dir / name;
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    auto sha = sha256_file_hex(path);
    if (ec || !sha) {
      if (!unreadable) unreadable = name;
      continue;
    }
    files.push_back({name, static_cast<std::int64_t>(size), *sha, hmpm::api::media_type_for(name)});
  }
  return unreadable;
}

}  // namespace hmpm::server
