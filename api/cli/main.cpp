// main.cpp — the `hmpm` command line: validate a job spec or run it locally.
//
//   hmpm run SPEC.json --out DIR [--threads N] [--quiet]
//   hmpm validate SPEC.json
// SPEC may be "-" for standard input. Exit codes (hmpm/api/exit_codes.hpp)
// follow the contract: 0 success, 2 invalid spec (every error on stderr as
// "/pointer: message"), 3 run failed (reason on stderr and in
// DIR/summary.json); 1 for a bad command line or an unreadable file.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hmpm/api/exit_codes.hpp"
#include "hmpm/api/job.hpp"
#include "hmpm/format.hpp"

namespace {

using hmpm::api::exit_status;
using hmpm::api::ExitCode;
constexpr int exit_ok = exit_status(ExitCode::ok);
constexpr int exit_usage = exit_status(ExitCode::usage);
constexpr int exit_invalid = exit_status(ExitCode::invalid_spec);
constexpr int exit_run_failed = exit_status(ExitCode::run_failed);

std::atomic<bool> g_cancel{false};

extern "C" void on_interrupt(int) {
  g_cancel.store(true);
}

const char* const usage_text =
    "usage:\n"
    "  hmpm run SPEC.json --out DIR [--threads N]   run a job locally, write results into DIR\n"
    "  hmpm validate SPEC.json [--calibrate] [--threads N]\n"
    "                                               check a job spec, print its cost estimate\n"
    "                                               (--calibrate: measure this machine first)\n"
    "  hmpm spec-keys                               print the parser's tables (JSON)\n"
    "  hmpm --help | --version\n"
    "SPEC may be '-' for standard input.\n"
    "Exit codes: 0 success; 2 invalid spec (one '/json/pointer: message' line per problem\n"
    "on stderr); 3 the run failed (reason on stderr and in DIR/summary.json); 1 bad usage.\n"
    "--threads N: solver threads (default: every core). Ctrl-C stops a run cleanly.\n";

int usage_error(const std::string& what) {
  std::cerr << "hmpm: " << what << "\n" << usage_text;
  return exit_usage;
}

bool read_spec(const std::string& path, std::string& text) {
  if (path == "-") {
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
    return true;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  text = s.str();
  return true;
}

// Reads and parses; prints errors and returns the exit code when not valid.
int load(const std::string& path, hmpm::api::ParseResult& result) {
  std::string text;
  if (!read_spec(path, text)) {
    std::cerr << "hmpm: cannot read " << path << "\n";
    return exit_usage;
  }
  result = hmpm::api::parse_job(text);
  if (result.ok()) return exit_ok;
  for (const auto& e : result.errors) std::cerr << e.path << ": " << e.message << "\n";
  return exit_invalid;
}

void print_cost(const hmpm::api::CostEstimate& c) {
  std::cout << "particles " << c.particles << ", nodes " << c.nodes << ", steps " << c.steps
            << " (dt " << c.dt << " s), particle-steps " << c.particle_steps << ", memory ~"
            << c.memory_bytes / 1024 / 1024 << " MiB, output ~" << c.output_bytes / 1024
            << " KiB, series rows " << c.series_rows << ", snapshots " << c.snapshots << "\n";
}

std::string format_seconds(double s) {
  char buf[32];
  if (s < 0 || s > 1e7) return "?";
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600,
                  static_cast<int>(s) / 60 % 60);
  return buf;
}

// One line per scheme: steps and expected wall time (the run's own first).
void print_schemes(const hmpm::api::CostEstimate& c) {
  const auto line = [&](const hmpm::api::SchemeCost& s, const char* what) {
    std::cout << what << " " << hmpm::scheme_name(s.scheme) << ": " << s.steps << " steps ("
              << (s.fixed ? "dt " : "first dt ") << s.dt << " s), expected wall time "
              << hmpm::format_significant(s.wall_seconds, 3) << " s\n";
  };
  for (const auto& s : c.schemes)
    if (s.scheme == c.scheme) line(s, "scheme");
  for (const auto& s : c.schemes)
    if (s.scheme != c.scheme) line(s, "  with");
  std::cout << "calibration: "
            << hmpm::format_significant(c.calibration.seconds_per_particle_step, 3)
            << " s per particle-step, "
            << (c.calibration.measured ? "measured on this machine" : "the built-in default")
            << ", " << c.calibration.threads << " thread(s)\n";
}

int command_validate(const std::vector<std::string>& args) {
  std::string spec;
  bool measure = false;
  int threads = static_cast<int>(std::thread::hardware_concurrency());
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--calibrate") {
      measure = true;
    } else if (args[i] == "--threads" && i + 1 < args.size()) {
      try {
        std::size_t used = 0;
        threads = std::stoi(args[++i], &used);
        if (used != args[i].size() || threads < 1) throw std::invalid_argument("");
      } catch (const std::exception&) {
        return usage_error("--threads needs a positive integer, got '" + args[i] + "'");
      }
    } else if (spec.empty() && (args[i] == "-" || args[i].rfind("--", 0) != 0)) {
      spec = args[i];
    } else {
      return usage_error("validate takes one SPEC and optionally --calibrate, --threads N");
    }
  }
  if (spec.empty()) return usage_error("validate takes exactly one SPEC");
  hmpm::api::ParseResult result;
  if (const int rc = load(spec, result); rc != exit_ok) return rc;
  std::cout << "valid: " << result.job->name << "\n";
  hmpm::api::Calibration calibration;
  calibration.threads = std::max(threads, 1);
  if (measure) calibration = hmpm::api::calibrate(threads);
  result.job->cost = hmpm::api::estimate_cost(result.job->problem, calibration);
  print_cost(result.job->cost);
  print_schemes(result.job->cost);
  for (const auto& w : result.job->warnings)
    std::cerr << "hmpm: warning: " << w.path << ": " << w.message << "\n";
  return exit_ok;
}

int command_run(const std::vector<std::string>& args) {
  std::string spec, out;
  int threads = static_cast<int>(std::thread::hardware_concurrency());
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--out" && i + 1 < args.size()) {
      out = args[++i];
    } else if (a == "--threads" && i + 1 < args.size()) {
      try {
        std::size_t used = 0;
        threads = std::stoi(args[++i], &used);
        if (used != args[i].size() || threads < 1) throw std::invalid_argument("");
      } catch (const std::exception&) {
        return usage_error("--threads needs a positive integer, got '" + args[i] + "'");
      }
    } else if (spec.empty() && (a == "-" || a.rfind("--", 0) != 0)) {
      spec = a;
    } else {
      return usage_error("unexpected argument '" + a + "'");
    }
  }
  if (spec.empty() || out.empty()) return usage_error("run needs SPEC and --out DIR");
  hmpm::api::ParseResult result;
  if (const int rc = load(spec, result); rc != exit_ok) return rc;

  hmpm::RunOptions options;
  options.threads = threads < 1 ? 1 : threads;
  options.cancel = &g_cancel;
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  const bool tty = isatty(STDERR_FILENO) == 1;
  const auto start = std::chrono::steady_clock::now();
  if (tty) {
    options.on_progress = [start](const hmpm::Progress& p) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double f = std::clamp(p.fraction, 0.0, 1.0);
      const int width = 30, filled = static_cast<int>(f * width);
      const double eta = f > 1e-6 ? elapsed * (1 - f) / f : -1;
      std::fprintf(stderr, "\r[%s%s] %5.1f%%  t = %.4g / %.4g s  ETA %s   ",
                   std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - filled), ' ').c_str(), 100 * f,
                   p.time, p.end_time, format_seconds(eta).c_str());
      std::fflush(stderr);
    };
  }
  hmpm::api::JobOutcome outcome;
  try {
    outcome = hmpm::api::run_job(*result.job, out, options);
  } catch (const std::exception& e) {
    if (tty) std::fputs("\n", stderr);
    std::cerr << "hmpm: " << e.what() << "\n";
    return exit_run_failed;
  }
  if (tty) std::fputs("\n", stderr);
  if (!outcome.write_error.empty()) {
    std::cerr << "hmpm: could not write results: " << outcome.write_error << "\n";
    return exit_run_failed;
  }
  const hmpm::RunResult& r = outcome.run;
  for (const auto& w : r.warnings) std::cerr << "hmpm: warning: " << w << "\n";
  if (r.status != hmpm::RunStatus::successful) {
    std::cerr << "hmpm: run " << hmpm::status_name(r.status) << ": " << r.message << "\n";
    return exit_run_failed;
  }
  std::cout << "successful: " << r.message << " (" << r.steps << " steps, first dt " << r.dt
            << " s), " << r.particles << " particles, " << r.solve_seconds << " s ("
            << r.particle_steps_per_second << " particle-steps/s); results in " << out << "\n";
  return exit_ok;
}

int command_spec_keys() {
  std::cout << hmpm::api::spec_tables_json();
  return exit_ok;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) return usage_error("no command");
  const std::string command = args[0];
  args.erase(args.begin());
  if (command == "--help" || command == "-h" || command == "help") {
    std::cout << "hmpm " << hmpm::api::version() << " — hydro-mechanical MPM for saturated soils\n"
              << usage_text;
    return exit_ok;
  }
  if (command == "--version") {
    std::cout << "hmpm " << hmpm::api::version() << "\n";
    return exit_ok;
  }
  if (command == "validate") return command_validate(args);
  if (command == "run") return command_run(args);
  if (command == "spec-keys") return command_spec_keys();
  return usage_error("unknown command '" + command + "'");
}
