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
//
// Phases whose result does not depend on which thread handles which index
// (no sums across particles) use `for_blocks(n, block, f)` instead: the
// threads take blocks of `block` indices from a shared counter until none is
// left, so a thread on a slower (shared, virtual) CPU takes fewer blocks
// instead of making the other one wait.
#pragma once

#include <algorithm>
#include <atomic>
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
  std::size_t chunk_begin(std::size_t n, int t) const {
    return n * static_cast<std::size_t>(t) / size_;
  }

  /// Runs f(thread, begin, end) on every chunk of [0, n); returns when all are done.
  template <class F>
  void for_ranges(std::size_t n, F& f) {
    dispatch(n, 0, f);
  }

  /// Runs f(thread, begin, end) on blocks [k block, (k + 1) block) of [0, n),
  /// each block once, on whichever thread is free; returns when all are done.
  template <class F>
  void for_blocks(std::size_t n, std::size_t block, F& f) {
    dispatch(n, std::max<std::size_t>(block, 1), f);
  }

 private:
  /// block == 0: one fixed chunk per thread; otherwise blocks from next_.
  template <class F>
  void dispatch(std::size_t n, std::size_t block, F& f) {
    if (size_ == 1) {
      f(0, std::size_t{0}, n);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &trampoline<F>;
      context_ = &f;
      n_ = n;
      block_ = block;
      next_.store(0, std::memory_order_relaxed);  // published by the mutex
      pending_ = size_ - 1;
      ++generation_;
    }
    wake_.notify_all();
    run(0, &trampoline<F>, &f, n, block);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
  }

  void run(int t, void (*job)(void*, int, std::size_t, std::size_t), void* context, std::size_t n,
           std::size_t block) {
    if (block == 0) {
      job(context, t, chunk_begin(n, t), chunk_begin(n, t + 1));
      return;
    }
    for (;;) {
      const std::size_t begin = next_.fetch_add(block, std::memory_order_relaxed);
      if (begin >= n) return;
      job(context, t, begin, std::min(n, begin + block));
    }
  }

  template <class F>
  static void trampoline(void* context, int t, std::size_t begin, std::size_t end) {
    (*static_cast<F*>(context))(t, begin, end);
  }

  void work(int t) {
    std::size_t seen = 0;
    for (;;) {
      void (*job)(void*, int, std::size_t, std::size_t);
      void* context;
      std::size_t n, block;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return generation_ != seen; });
        seen = generation_;
        if (stop_) return;
        job = job_;
        context = context_;
        n = n_;
        block = block_;
      }
      run(t, job, context, n, block);
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
  std::size_t block_ = 0;
  std::atomic<std::size_t> next_{0};  ///< first index of the next free block (for_blocks)
  int pending_ = 0;
};

}  // namespace hmpm
