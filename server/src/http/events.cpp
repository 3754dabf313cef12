// events.cpp — GET /jobs/{id}/events: progress as Server-Sent Events.
//
// Each stream holds an HTTP thread for its life, so streams are capped
// (`max_event_streams`, 503 beyond; below the HTTP thread count, options.cpp),
// end promptly when the service stops, and end after `event_stream_max_s`
// (the client reconnects after `retry` and gets the current state), so a
// client that never reads cannot hold a slot for a job's whole life; a write
// that cannot go out within httplib's write timeout ends it sooner.
#include <chrono>
#include <memory>
#include <thread>

#include "documents.hpp"
#include "handlers.hpp"
#include "job_log.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

using SteadyClock = std::chrono::steady_clock;

struct StreamState {
  std::string id;
  std::string last_status;
  int last_progress = -1;
  int sent = 0;
  SteadyClock::time_point last_write = SteadyClock::now();
  SteadyClock::time_point ends;
};

// Takes a stream slot; false when the cap is reached.
bool take_slot(Context& c) {
  int open = c.metrics.open_streams.load();
  do {
    if (open >= c.config.max_event_streams) return false;
  } while (!c.metrics.open_streams.compare_exchange_weak(open, open + 1));
  return true;
}

}  // namespace

void stream_events(Context& c, const httplib::Request& req, httplib::Response& res) {
  const auto found = find_job(c, req.matches[1], res);
  if (!found) return;
  const std::string id = found->id;
  if (!take_slot(c)) {
    res.set_header("Retry-After", "5");
    return send_problem(res, 503, "too-many-streams", "Too many event streams",
                        "the server's limit of " + std::to_string(c.config.max_event_streams) +
                            " concurrent event streams is reached; poll GET /jobs/{id} instead");
  }
  auto state = std::make_shared<StreamState>();
  state->id = id;
  state->ends =
      SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                               std::chrono::duration<double>(c.config.event_stream_max_s));
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  // httplib calls the provider until it signals done (or a write fails); each
  // call sends what changed, or a heartbeat when quiet, then waits ~250 ms.
  res.set_chunked_content_provider(
      "text/event-stream",
      [&c, state](std::size_t, httplib::DataSink& sink) {
        try {
          const auto job = c.store.find(state->id);
          if (!job) {
            sink.done();
            return true;
          }
          const int progress = whole_percent(job->progress);
          const std::string status = status_name(job->status);
          std::string out;
          if (state->sent == 0) out += "retry: 2000\n\n";
          if (status != state->last_status || progress != state->last_progress) {
            state->last_status = status;
            state->last_progress = progress;
            std::string data = dump(status_document(*job));
            data.pop_back();  // dump's newline; the event ends with a blank line
            out += "id: " + std::to_string(++state->sent) +
                   "\nevent: " + (is_terminal(job->status) ? "done" : "progress") +
                   "\ndata: " + data + "\n\n";
          } else if (SteadyClock::now() - state->last_write >=
                     std::chrono::duration<double>(c.config.heartbeat_interval_s)) {
            out += ": heartbeat\n\n";
          }
          if (!out.empty()) {
            if (!sink.write(out.data(), out.size())) return false;
            state->last_write = SteadyClock::now();
          }
          if (is_terminal(job->status)) {
            sink.done();
            return true;
          }
          const auto until = SteadyClock::now() + std::chrono::milliseconds(250);
          while (SteadyClock::now() < until && !c.stopping) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
          }
          if (c.stopping || SteadyClock::now() >= state->ends) sink.done();
          return true;
        } catch (const std::exception& e) {
          log_line({{"event", "error"}, {"job", state->id}, {"detail", e.what()}});
          return false;
        }
      },
      [&c](bool) { --c.metrics.open_streams; });
}

}  // namespace hmpm::server::http
