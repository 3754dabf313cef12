// options.cpp — see options.hpp.
#include "hmpm/server/options.hpp"

#include <arpa/inet.h>
#include "hmpm/server/store.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>

namespace hmpm::server {
namespace {

bool parse_int(const std::string& text, long lo, long hi, long& out) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi)
    return false;
  out = value;
  return true;
}

bool parse_seconds(const std::string& text, double& out) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(value) || value < 0) return false;
    out = value;
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

// The secret in `path`, without trailing white space; "" and `error` set
// when it cannot be read or is empty.
std::string read_token_file(const std::string& path, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot be read";
    return {};
  }
  std::ostringstream text;
  text << in.rdbuf();
  std::string token = text.str();
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back()))) token.pop_back();
  if (token.empty()) error = "is empty";
  if (token.find_first_of("\r\n") != std::string::npos) error = "must hold one line";
  return error.empty() ? token : std::string();
}

}  // namespace

bool is_loopback_host(const std::string& host) {
  if (host == "localhost") return true;
  std::string bare = host;
  if (bare.size() > 2 && bare.front() == '[' && bare.back() == ']')
    bare = bare.substr(1, bare.size() - 2);
  in_addr v4{};
  if (inet_pton(AF_INET, bare.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, bare.c_str(), &v6) == 1) return IN6_IS_ADDR_LOOPBACK(&v6);
  return false;
}

std::string usage() {
  return "usage: hmpm-server [--host H] [--port P] --db PATH|URI [--workers N] [--data-dir DIR]\n"
         "                   [--threads-per-job N] [--token-file F | --token T] [--max-queue N]\n"
         "                   [--job-wall-time S] [--max-particles N] [--max-particle-steps N]\n"
         "                   [--max-job-memory B] [--max-attempts N] [--charge-after S]\n"
         "                   [--max-body-bytes N]\n"
         "                   [--max-event-streams N] [--http-threads N] [--retain-days N]\n"
         "                   [--checkpoint-interval S] [--lease-seconds S]\n"
         "                   [--max-connections N] [--request-head-timeout S]\n"
         "                   [--request-body-timeout S] [--send-stall-timeout S]\n"
         "                   [--event-stream-max-seconds S]\n"
         "                   [--allow-no-token] [--allowed-host NAME[:PORT]]...\n"
         "                   [--allowed-origin ORIGIN]...\n"
         "  --host H              address to listen on (default 127.0.0.1); any address but\n"
         "                        loopback needs a token (or --allow-no-token)\n"
         "  --port P              port; 0 picks a free one (default 8080)\n"
         "  --db PATH             SQLite database, created if missing, for this process alone\n"
         "  --db postgresql://USER@HOST:PORT/DBNAME\n"
         "                        PostgreSQL database (a libpq URI) that any number of servers\n"
         "                        share; then --data-dir is required (one folder all of them\n"
         "                        read and write)\n"
         "  --data-dir DIR        result files (default with SQLite: <db dir>/results)\n"
         "  --workers N           jobs run at the same time (default 2: a short job runs\n"
         "                        beside a long one; workers x threads = cores)\n"
         "  --threads-per-job N   solver threads per job (default: cores / workers)\n"
         "  --token-file F        require 'Authorization: Bearer T', T the first line of F\n"
         "  --token T             the same with T given here (visible in the process list;\n"
         "                        prefer --token-file or $HMPM_TOKEN, the default)\n"
         "  --allow-no-token      start on a non-loopback --host without a token (warns)\n"
         "  --allowed-host NAME[:PORT]  a Host header accepted besides the listening address\n"
         "                        (and localhost on loopback); repeatable. Others get 421\n"
         "  --allowed-origin ORIGIN  a web origin (http(s)://HOST[:PORT]) whose pages may\n"
         "                        write (POST, DELETE) and get CORS headers; repeatable.\n"
         "                        Other origins' writes get 403\n"
         "  --max-queue N         queued jobs before POST /jobs answers 503 (default 1000)\n"
         "  --job-wall-time S     fail a job running (set-up included) longer than S seconds;\n"
         "                        0: none (default 86400)\n"
         "  --max-particles N     particles per job, refused beyond (default 2000000)\n"
         "  --max-particle-steps N  particles x steps per job, refused beyond; 0: none\n"
         "                        (default 1000000000000)\n"
         "  --max-job-memory B    estimated memory per job in bytes, refused beyond; 0: none\n"
         "                        (default: half the physical memory / workers)\n"
         "  --max-attempts N      crashes charged to a job before recovery fails it (default 3)\n"
         "  --charge-after S      a crash is charged to a running job only if its attempt ran\n"
         "                        at least S seconds (default 30)\n"
         "  --max-body-bytes N    request body limit, 413 beyond (default 16777216)\n"
         "  --max-event-streams N concurrent event streams, 503 beyond (default 8)\n"
         "  --http-threads N      HTTP threads kept ready, more made on demand (default 24)\n"
         "  --max-connections N   connections served at once, 503 beyond (default 256)\n"
         "  --request-head-timeout S  a request's line and headers must arrive in S s (10)\n"
         "  --request-body-timeout S  a request's body must arrive in S s (60)\n"
         "  --send-stall-timeout S  an answer (a download, an event stream) whose client\n"
         "                        has taken no byte for S s is ended: slower readers are\n"
         "                        served at any rate (default 120)\n"
         "  --event-stream-max-seconds S  an event stream ends after S s; the client\n"
         "                        reconnects (default 300)\n"
         "  --retain-days N       purge jobs that ended (successful, failed, dismissed) more than\n"
         "                        N days ago, with their files, at start-up and hourly; queued\n"
         "                        and running jobs are never purged; 0 keeps all (default 30)\n"
         "  --checkpoint-interval S  checkpoint a running job every S seconds of wall time; a\n"
         "                        job interrupted by a crash resumes from its last checkpoint;\n"
         "                        0 turns checkpoints off (default 60)\n"
         "  --lease-seconds S     a running job's claim lapses S s after its server's last\n"
         "                        heartbeat (every S/3 s); then another server takes it over\n"
         "                        (default 30)\n"
         "The first line on stdout is 'listening on http://HOST:PORT'. SIGTERM or SIGINT\n"
         "stops accepting, puts running jobs back in the queue and exits 0.\n";
}

ParsedOptions parse_options(const std::vector<std::string>& args, const char* env_token) {
  ParsedOptions result;
  ServiceConfig config;
  std::set<std::string> given;

  auto integer = [](long lo, long hi, auto apply) {
    return [=](const std::string& v) {
      long n = 0;
      if (!parse_int(v, lo, hi, n)) {
        return "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
      }
      apply(n);
      return std::string();
    };
  };
  auto positive_seconds = [](double& target) {
    return [&target](const std::string& v) {
      double s = 0;
      if (!parse_seconds(v, s) || s <= 0) return std::string("must be seconds > 0");
      target = s;
      return std::string();
    };
  };
  // Each flag takes one value; the handler returns "" or what is wrong.
  const std::map<std::string, std::function<std::string(const std::string&)>> flags{
      {"--host",
       [&](const std::string& v) {
         config.host = v;
         return std::string();
       }},
      {"--port", integer(0, 65535, [&](long n) { config.port = static_cast<int>(n); })},
      {"--db",
       [&](const std::string& v) {
         config.db_path = v;
         return std::string();
       }},
      {"--data-dir",
       [&](const std::string& v) {
         config.data_dir = v;
         return std::string();
       }},
      {"--workers", integer(1, 1024, [&](long n) { config.workers = static_cast<int>(n); })},
      {"--threads-per-job",
       integer(1, 4096, [&](long n) { config.threads_per_job = static_cast<int>(n); })},
      {"--token",
       [&](const std::string& v) {
         config.token = v;
         return v.empty() ? std::string("must not be empty (leave --token out for no token)")
                          : std::string();
       }},
      {"--token-file",
       [&](const std::string& v) {
         std::string error;
         config.token = read_token_file(v, error);
         return error;
       }},
      {"--max-queue", integer(0, 100'000'000, [&](long n) { config.max_queue = n; })},
      {"--job-wall-time",
       [&](const std::string& v) {
         return parse_seconds(v, config.job_wall_time_s) ? std::string()
                                                         : std::string("must be seconds >= 0");
       }},
      {"--max-particles", integer(1, 1'000'000'000, [&](long n) { config.max_particles = n; })},
      {"--max-particle-steps", integer(0, std::numeric_limits<long>::max(),
                                       [&](long n) { config.max_particle_steps = n; })},
      {"--max-job-memory", integer(0, std::numeric_limits<long>::max(),
                                   [&](long n) { config.max_job_memory = n > 0 ? n : -1; })},
      {"--max-attempts",
       integer(1, 1000, [&](long n) { config.max_attempts = static_cast<int>(n); })},
      {"--charge-after",
       [&](const std::string& v) {
         return parse_seconds(v, config.charge_after_s) ? std::string()
                                                        : std::string("must be seconds >= 0");
       }},
      {"--max-body-bytes",
       integer(1024, long{1} << 40,
               [&](long n) { config.max_body_bytes = static_cast<std::size_t>(n); })},
      {"--max-event-streams",
       integer(0, 1000, [&](long n) { config.max_event_streams = static_cast<int>(n); })},
      {"--http-threads",
       integer(2, 1024, [&](long n) { config.http_threads = static_cast<int>(n); })},
      {"--checkpoint-interval",
       [&](const std::string& v) {
         return parse_seconds(v, config.checkpoint_interval_s)
                    ? std::string()
                    : std::string("must be seconds >= 0");
       }},
      {"--retain-days",
       integer(0, 100'000, [&](long n) { config.retain_days = static_cast<int>(n); })},
      {"--lease-seconds",
       [&](const std::string& v) {
         // At least 1 s: the heartbeat renews every third of it and a
         // database round trip must fit in between.
         return parse_seconds(v, config.lease_s) && config.lease_s >= 1.0
                    ? std::string()
                    : std::string("must be seconds >= 1");
       }},
      {"--max-connections",
       integer(2, 100'000, [&](long n) { config.max_connections = static_cast<int>(n); })},
      {"--request-head-timeout", positive_seconds(config.head_timeout_s)},
      {"--request-body-timeout", positive_seconds(config.body_timeout_s)},
      {"--send-stall-timeout", positive_seconds(config.send_stall_s)},
      {"--event-stream-max-seconds", positive_seconds(config.event_stream_max_s)},
      {"--allowed-host",
       [&](const std::string& v) {
         const bool ok = !v.empty() && v.find_first_of(" \t/,@") == std::string::npos;
         if (ok) config.allowed_hosts.push_back(v);
         return ok ? std::string() : std::string("must be a host name, NAME or NAME:PORT");
       }},
      {"--allowed-origin",
       [&](const std::string& v) {
         const bool ok = (v.rfind("http://", 0) == 0 || v.rfind("https://", 0) == 0) &&
                         v.find('/', v.find("://") + 3) == std::string::npos &&
                         v.size() > v.find("://") + 3;
         if (ok) config.allowed_origins.push_back(v);
         return ok ? std::string()
                   : std::string("must be an origin, http(s)://HOST[:PORT] without a path");
       }},
  };
  // Flags without a value.
  const std::map<std::string, std::function<void()>> switches{
      {"--allow-no-token", [&] { config.allow_no_token = true; }},
  };

  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string flag = args[i];
    std::string value;
    bool has_value = false;
    if (flag == "-h" || flag == "--help") {
      result.help = true;
      return result;
    }
    if (const auto eq = flag.find('='); flag.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = flag.substr(eq + 1);
      flag = flag.substr(0, eq);
      has_value = true;
    }
    if (const auto sw = switches.find(flag); sw != switches.end() && !has_value) {
      sw->second();
      continue;
    }
    const auto it = flags.find(flag);
    if (it == flags.end()) {
      result.error = "unknown option " + flag;
      return result;
    }
    if (!has_value) {
      if (i + 1 >= args.size()) {
        result.error = flag + " needs a value";
        return result;
      }
      value = args[++i];
    }
    if (const std::string problem = it->second(value); !problem.empty()) {
      result.error = flag;
      // Never echo a secret.
      result.error.append(" ")
          .append(flag == "--token" ? "''" : value)
          .append(": ")
          .append(problem);
      return result;
    }
    given.insert(flag);
  }
  if (given.count("--token") && given.count("--token-file")) {
    result.error = "--token and --token-file: give one of them";
    return result;
  }
  if (!given.count("--token") && !given.count("--token-file") && env_token) {
    config.token = env_token;
    if (config.token.empty()) {
      result.error = "HMPM_TOKEN is set but empty (unset it for no token)";
      return result;
    }
  }
  if (config.db_path.empty()) {
    result.error = "--db PATH is required";
    return result;
  }
  if (const std::string db = config.db_path.string();
      !is_postgres_uri(db) && db.find("://") != std::string::npos) {
    // Not a file name anybody means: it would become a SQLite file in a
    // folder named after the scheme ("postgresql:/user@host/db").
    result.error = "--db " + db +
                   " is a URI of a kind hmpm-server does not know: give a "
                   "postgresql://USER@HOST:PORT/DBNAME URI or the path of a SQLite file";
    return result;
  }
  if (is_postgres_uri(config.db_path.string()) && config.data_dir.empty()) {
    result.error =
        "--data-dir DIR is required with a PostgreSQL --db (the folder every server "
        "sharing the database reads and writes)";
    return result;
  }
  if (config.host.empty()) {
    result.error = "--host must not be empty";
    return result;
  }
  if (config.token.empty() && !config.allow_no_token && !is_loopback_host(config.host)) {
    result.error = "--host " + config.host +
                   " is reachable from other machines and no token is set: give --token-file "
                   "(or HMPM_TOKEN), or --allow-no-token to serve everyone";
    return result;
  }
  if (config.max_event_streams >= config.http_threads) {
    result.error = "--max-event-streams " + std::to_string(config.max_event_streams) +
                   " must be below --http-threads " + std::to_string(config.http_threads) +
                   ": each stream holds an HTTP thread";
    return result;
  }
  result.config = std::move(config);
  return result;
}

}  // namespace hmpm::server
