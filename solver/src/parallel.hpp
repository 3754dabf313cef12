// parallel.hpp — a fixed set of threads that split index ranges (internal).
//
// The time step runs each particle or node phase as `for_ranges(n, f)`: the
// range [0, n) is cut into one contiguous chunk per thread, always the same
// way, and f(thread, begin, end) runs on each chunk; the caller's thread takes
// chunk 0 and the call returns when every chunk is done. Fixed chunks and a
// fixed reduction order (see Simulation) make results reproducible for a
// given thread count. Dispatch costs a few microseconds per phase and
// allocates nothing; the job is passed as a function pointer and a context
// pointer, not a std::function.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <vector>

namespace hmpm {

class ThreadPool {
 public:
  /// `threads` >= 1 in total, including the caller's thread.
  explicit ThreadPool(int threads) : size_(threads < 1 ? 1 : threads) {
    for (int t = 1; t < size_; ++t) workers_.emplace_back([this, t] { work(t); });
  }
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  ~ThreadPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      ++generation_;
    }
    wake_.notify_all();
    for (std::thread& w : workers_) w.join();
  }

  int size() const { return size_; }

  /// Chunk t of [0, n) for `size()` threads.
  std::size_t chunk_begin(std::size_t n, int t) const { return n * static_cast<std::size_t>(t) / size_; }

  /// Runs f(thread, begin, end) on every chunk of [0, n); returns when all are done.
  template <class F>
  void for_ranges(std::size_t n, F& f) {
    if (size_ == 1) {
      f(0, std::size_t{0}, n);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &trampoline<F>;
      context_ = &f;
      n_ = n;
      pending_ = size_ - 1;
      ++generation_;
    }
    wake_.notify_all();
    f(0, std::size_t{0}, chunk_begin(n, 1));
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
  }

 private:
  template <class F>
  static void trampoline(void* context, int t, std::size_t begin, std::size_t end) {
    (*static_cast<F*>(context))(t, begin, end);
  }

  void work(int t) {
    std::size_t seen = 0;
    for (;;) {
      void (*job)(void*, int, std::size_t, std::size_t);
      void* context;
      std::size_t n;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return generation_ != seen; });
        seen = generation_;
        if (stop_) return;
        job = job_;
        context = context_;
        n = n_;
      }
      job(context, t, chunk_begin(n, t), chunk_begin(n, t + 1));
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (--pending_ == 0) done_.notify_one();
      }
    }
  }

  int size_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::size_t generation_ = 0;
  bool stop_ = false;
  void (*job_)(void*, int, std::size_t, std::size_t) = nullptr;
  void* context_ = nullptr;
  std::size_t n_ = 0;
  int pending_ = 0;
};

}  // namespace hmpm
