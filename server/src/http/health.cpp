// health.cpp — GET /health (no token: for load balancers) and GET /metrics.
#include "handlers.hpp"
#include "hmpm/server/options.hpp"
#include "problem.hpp"

namespace hmpm::server::http {
namespace {

// How the PostgreSQL store's write probe begins its reasons (postgres_store.cpp).
constexpr const char* pg_unwritable_prefix = "the database cannot be written (postgresql): ";

}  // namespace

// Ready means the database can be read and written (the store's probe);
// the answer names which failed but not the server's paths (no token here).
void get_health(Context& c, const httplib::Request&, httplib::Response& res) {
  try {
    c.store.probe();
    Json doc{{"status", "ok"}};
    if (c.config.token.empty() && !is_loopback_host(c.config.host)) {
      doc["warning"] =
          "no token on a non-loopback address (--allow-no-token): the API is open "
          "to anyone who can reach it";
    }
    send_json(res, 200, doc);
  } catch (const StoreFailure& e) {
    const std::string what = e.what();
    const bool unwritable = what.find("cannot be written") != std::string::npos;
    // PostgreSQL's write probe says why in words of its own (no paths):
    // "the database cannot be written: a lock on the jobs table was not
    // granted within 1 s".
    const auto reason = what.find(pg_unwritable_prefix);
    std::string detail = "the database cannot be read";
    if (e.no_space()) {
      detail = "no space left: the database cannot be written";
    } else if (reason != std::string::npos) {
      detail = "the database cannot be written: " +
               what.substr(reason + std::string_view(pg_unwritable_prefix).size());
    } else if (unwritable) {
      detail = "the database cannot be written";
    }
    res.set_header("Retry-After", std::to_string(store_retry_after_s));
    send_json(res, 503, Json{{"status", "unavailable"}, {"detail", detail}});
  } catch (const std::exception&) {
    res.set_header("Retry-After", std::to_string(store_retry_after_s));
    send_json(res, 503, Json{{"status", "unavailable"}, {"detail", "the database cannot be read"}});
  }
}

void get_metrics(Context& c, const httplib::Request&, httplib::Response& res) {
  res.set_content(c.metrics.render(c.store.count_by_status(), c.config.workers),
                  "text/plain; version=0.0.4; charset=utf-8");
}

}  // namespace hmpm::server::http
