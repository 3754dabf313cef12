// process_lock.cpp — see process_lock.hpp.
#include "process_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "hmpm/server/store.hpp"

namespace hmpm::server {

std::optional<ProcessLock> ProcessLock::acquire(const std::filesystem::path& path,
                                                std::string& holder) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    holder = "cannot open lock file " + path.string() + ": " + std::strerror(errno);
    return std::nullopt;
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    char buffer[32] = {};
    const auto n = ::pread(fd, buffer, sizeof buffer - 1, 0);
    std::string pid = n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : "";
    while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
    ::close(fd);
    holder = error == EWOULDBLOCK
                 ? "in use by another hmpm-server (pid " + (pid.empty() ? "unknown" : pid) +
                       ", lock file " + path.string() + ")"
                 : "cannot lock " + path.string() + ": " + std::strerror(error);
    return std::nullopt;
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 ||
      ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    holder = "cannot write lock file " + path.string() + ": " + std::strerror(errno);
    ::close(fd);
    return std::nullopt;
  }
  return ProcessLock(fd);
}

ProcessLock ProcessLock::hold(const std::filesystem::path& path, const std::string& what) {
  std::string holder;
  auto lock = acquire(path, holder);
  if (!lock) throw StoreFailure(what + " is " + holder);
  return std::move(*lock);
}

ProcessLock::ProcessLock(ProcessLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

ProcessLock::~ProcessLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the flock
}

}  // namespace hmpm::server
