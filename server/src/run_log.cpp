// run_log.cpp — see run_log.hpp.
#include "run_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <system_error>

#include "clock.hpp"

namespace hmpm::server {

void append_run_log(const std::filesystem::path& job_dir, const std::string& text) {
  std::error_code ec;
  std::filesystem::create_directories(job_dir, ec);
  const std::string line = now_rfc3339() + " " + text + "\n";
  const int fd =
      ::open((job_dir / run_log_name).c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return;
  [[maybe_unused]] const auto written = ::write(fd, line.data(), line.size());
  ::close(fd);
}

bool ProgressLogPacer::due(double fraction, std::chrono::steady_clock::time_point now) {
  const bool first = !started_;  // a line soon after the start
  started_ = true;
  const bool tenth = fraction * 10.0 >= next_tenth_ - 1e-9;
  const bool quiet_too_long = now - last_ >= std::chrono::seconds(10);
  if (!first && !tenth && !quiet_too_long) return false;
  while (next_tenth_ <= 10 && fraction * 10.0 >= next_tenth_ - 1e-9) ++next_tenth_;
  last_ = now;
  return true;
}

}  // namespace hmpm::server
