// health.cpp — GET /health (no token: for load balancers) and GET /metrics.
#include "handlers.hpp"
#include "hmpm/server/options.hpp"
#include "problem.hpp"

namespace hmpm::server::http {

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
  } catch (const std::exception&) {
    send_json(res, 503, Json{{"status", "unavailable"}, {"detail", "the database cannot be read"}});
  }
}

void get_metrics(Context& c, const httplib::Request&, httplib::Response& res) {
  res.set_content(c.metrics.render(c.store.count_by_status(), c.config.workers),
                  "text/plain; version=0.0.4; charset=utf-8");
}

}  // namespace hmpm::server::http
