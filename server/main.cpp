// main.cpp — the hmpm-server executable: arguments, signals, one Service.
//
// SIGTERM and SIGINT are blocked in every thread and taken by a dedicated
// thread with sigwait(), which asks the service to stop: no job is claimed
// from then on, running jobs are cancelled and put back in the queue (they
// resume on the next start), the listener closes, open connections get a
// bounded drain (ServiceConfig::shutdown_drain_s) before their sockets are
// shut down, and run() returns, so the process exits 0 with its store
// closed. Exit 2 for bad arguments, 1 when the database cannot be opened or
// the port cannot be bound.
#include <pthread.h>
#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "hmpm/api/exit_codes.hpp"
#include "hmpm/api/job.hpp"
#include "hmpm/server/options.hpp"
#include "hmpm/server/service.hpp"
#include "hmpm/server/store.hpp"

int main(int argc, char** argv) {
  using hmpm::api::exit_status;
  using hmpm::api::ExitCode;
  const std::vector<std::string> args(argv + 1, argv + argc);
  const auto parsed = hmpm::server::parse_options(args, std::getenv("HMPM_TOKEN"));
  if (parsed.help) {
    std::cout << hmpm::server::usage();
    return exit_status(ExitCode::ok);
  }
  if (!parsed.config) {
    std::cerr << "hmpm-server: " << parsed.error << "\n" << hmpm::server::usage();
    return exit_status(ExitCode::server_usage);
  }

  const hmpm::server::ServiceConfig& given = *parsed.config;
  if (given.token.empty() && !hmpm::server::is_loopback_host(given.host)) {
    std::cerr << "hmpm-server: WARNING: listening on " << given.host
              << " without a token (--allow-no-token): anyone who can reach this address can "
                 "submit, read and delete jobs\n";
  }

  // Block the stop signals before any thread exists, so all threads inherit
  // the mask and only the signal thread below receives them.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a client hanging up must not kill the server
  // A file-size limit (RLIMIT_FSIZE) must not kill it either: ignored, the
  // write fails with EFBIG like a full disk, and is handled as one.
  signal(SIGXFSZ, SIG_IGN);

  try {
    // The machine speed behind the wall-time estimates of POST /validate
    // and the 201 of POST /jobs: a fixed small run, well under a second.
    hmpm::server::ServiceConfig config = *parsed.config;
    if (config.seconds_per_particle_step <= 0)
      config.seconds_per_particle_step = hmpm::api::calibrate(1).seconds_per_particle_step;
    hmpm::server::Service service(config);
    const int port = service.bind();
    if (port < 0) {
      std::cerr << "hmpm-server: cannot listen on " << parsed.config->host << ":"
                << parsed.config->port << "\n";
      return exit_status(ExitCode::failure);
    }
    std::thread signal_thread([&service, stop_signals] {
      int signal_number = 0;
      sigwait(&stop_signals, &signal_number);
      service.stop();
    });
    signal_thread.detach();  // still waiting if run() ends by itself; exit ends it
    std::cout << "listening on http://" << parsed.config->host << ":" << port << std::endl;
    return exit_status(service.run() ? ExitCode::ok : ExitCode::failure);
  } catch (const hmpm::server::StoreFailure& e) {
    std::cerr << "hmpm-server: " << e.what() << "\n";
    return exit_status(ExitCode::failure);
  } catch (const std::exception& e) {
    std::cerr << "hmpm-server: " << e.what() << "\n";
    return exit_status(ExitCode::failure);
  }
}
