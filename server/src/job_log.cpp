// job_log.cpp — see job_log.hpp.
#include "job_log.hpp"

#include <atomic>
#include <cstdio>
#include <mutex>

#include "clock.hpp"

namespace hmpm::server {
namespace {
std::mutex log_mutex;
std::atomic<bool> logging_enabled{true};
}  // namespace

void set_logging_enabled(bool enabled) {
  logging_enabled = enabled;
}

void log_line(nlohmann::ordered_json fields) {
  if (!logging_enabled) return;
  try {
    nlohmann::ordered_json line;
    line["ts"] = now_rfc3339();
    for (auto& [key, value] : fields.items()) line[key] = std::move(value);
    // `replace` keeps a line valid JSON even if a message carries bad UTF-8.
    const std::string text =
        line.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
    std::lock_guard<std::mutex> lock(log_mutex);
    std::fwrite(text.data(), 1, text.size(), stderr);
    std::fflush(stderr);
  } catch (...) {
    // Logging must never take a request or a worker down.
  }
}

}  // namespace hmpm::server
