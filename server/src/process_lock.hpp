// process_lock.hpp — an exclusive lock on a file, held for a process's life.
//
// hmpm-server locks its SQLite database (a `.lock` file beside it) and its
// data folder before it touches either, so a second server started on the
// same `--db` or `--data-dir` refuses to start instead of rerunning and
// deleting the first one's jobs. The lock is flock(2) on a file that holds
// the owner's pid: the kernel drops it when the process dies (even by
// SIGKILL), so a stale file never blocks a restart.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace hmpm::server {

class ProcessLock {
 public:
  /// Takes the lock on `path` (created if missing) or returns nullopt and
  /// sets `holder` to a sentence naming the process that has it.
  static std::optional<ProcessLock> acquire(const std::filesystem::path& path, std::string& holder);
  /// Takes the lock on `path` for `what` ("database x"), or throws
  /// StoreFailure("<what> is in use by another hmpm-server (pid N, ...)").
  static ProcessLock hold(const std::filesystem::path& path, const std::string& what);
  ~ProcessLock();
  ProcessLock(ProcessLock&& other) noexcept;
  ProcessLock& operator=(ProcessLock&&) = delete;
  ProcessLock(const ProcessLock&) = delete;
  ProcessLock& operator=(const ProcessLock&) = delete;

 private:
  explicit ProcessLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace hmpm::server
