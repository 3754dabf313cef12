// recovery.cpp — see recovery.hpp.
#include "store/recovery.hpp"

#include <cstdio>

#include "hmpm/server/store.hpp"

namespace hmpm::server {
namespace {

// "30 s", "1.5 s".
std::string short_duration(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", seconds);
  return text;
}

}  // namespace

RecoveryDecision decide_recovery(const LapsedAttempt& job, int max_attempts,
                                 double charge_after_s) {
  RecoveryDecision decision;
  decision.charged = job.charged + (job.ran_s >= charge_after_s ? 1 : 0);
  if (decision.charged >= max_attempts) {
    decision.failure = "the server stopped " + std::to_string(decision.charged) +
                       " times while this job ran (each time after at least " +
                       short_duration(charge_after_s) + " of its attempt; limit " +
                       std::to_string(max_attempts) + " attempts); not retried";
  } else if (job.attempts >= std::int64_t{uncharged_start_factor} * max_attempts) {
    decision.failure = "this job was started " + std::to_string(job.attempts) +
                       " times and the server stopped every time, mostly within " +
                       short_duration(charge_after_s) + " of the start (limit " +
                       std::to_string(uncharged_start_factor * max_attempts) +
                       " starts); not retried";
  }
  return decision;
}

}  // namespace hmpm::server
