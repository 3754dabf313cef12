// recovery.hpp — the recovery policy of every store, written once.
//
// JobStore::recover (store.hpp) finds the running jobs whose lease has
// lapsed; what happens to each is decided here, from what the backend read
// of its row, so the SQLite and the PostgreSQL stores cannot drift apart.
// The crash is charged to the job only if its attempt had run for at least
// `charge_after_s` (a job claimed just before an unrelated crash is
// innocent); the job fails once `max_attempts` crashes were charged to it,
// or, as a backstop, once it was started uncharged_start_factor *
// max_attempts times.
#pragma once

#include <cstdint>
#include <string>

namespace hmpm::server {

/// The message of a job put back in the queue because its server stopped
/// (a shutdown's requeue or recovery after a crash).
inline constexpr const char* requeued_message = "queued again: the server stopped while it ran";

/// What a backend read of a lapsed job's row.
struct LapsedAttempt {
  std::int64_t attempts = 0;  ///< starts so far
  std::int64_t charged = 0;   ///< crashes charged before this one
  double ran_s = 0.0;         ///< claim to the attempt's last proof of life
};

/// What recovery does with it: requeue (`failure` empty) or fail with
/// `failure` as the reason; `charged` is the row's new count either way.
struct RecoveryDecision {
  std::int64_t charged = 0;
  std::string failure;
};

RecoveryDecision decide_recovery(const LapsedAttempt& job, int max_attempts, double charge_after_s);

}  // namespace hmpm::server
