// validation_gate.hpp — bounds the HTTP threads that parse and validate job
// specs (POST /jobs, POST /validate, OGC execution). Validation is CPU work
// (JSON, formulas, particle layout); without a bound, a burst of heavy
// specs occupied every HTTP thread and /health waited for tens of seconds.
//
// At most `running` validations run at once; at most `admitted` requests
// (running and waiting for a turn) hold an HTTP thread for it. A request
// beyond `admitted`, or one that waited `wait_s` without a turn, is
// answered 503 validation-busy with Retry-After, so the other HTTP threads
// stay free for /health and status reads.
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>

namespace hmpm::server::http {

class ValidationGate {
 public:
  ValidationGate(int running, int admitted, double wait_s)
      : running_max_(std::max(running, 1)),
        admitted_max_(std::max(admitted, running_max_)),
        wait_s_(wait_s) {}

  /// Holds one turn while alive (see enter()).
  class Turn {
   public:
    explicit Turn(ValidationGate* gate) : gate_(gate) {}
    Turn(Turn&& other) noexcept : gate_(other.gate_) { other.gate_ = nullptr; }
    Turn(const Turn&) = delete;
    Turn& operator=(const Turn&) = delete;
    Turn& operator=(Turn&&) = delete;
    ~Turn() {
      if (gate_) gate_->leave();
    }
    explicit operator bool() const { return gate_ != nullptr; }

   private:
    ValidationGate* gate_;
  };

  /// A turn to validate, or an empty Turn when the gate is full (answer 503).
  Turn enter() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (admitted_ >= admitted_max_) return Turn(nullptr);
    ++admitted_;
    if (!turn_.wait_for(lock, std::chrono::duration<double>(wait_s_),
                        [&] { return running_ < running_max_; })) {
      --admitted_;
      return Turn(nullptr);
    }
    ++running_;
    return Turn(this);
  }

  int running_max() const { return running_max_; }
  int admitted_max() const { return admitted_max_; }

 private:
  void leave() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --running_;
      --admitted_;
    }
    turn_.notify_one();
  }

  std::mutex mutex_;
  std::condition_variable turn_;
  const int running_max_;
  const int admitted_max_;
  const double wait_s_;
  int running_ = 0;
  int admitted_ = 0;
};

}  // namespace hmpm::server::http
