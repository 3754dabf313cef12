// checkpoint.hpp — the binary format of a run's checkpoint (internal).
//
// A checkpoint is the whole state the time loop carries from one step to
// the next, so that a run resumed from it ends with the results of an
// uninterrupted run, bit for bit at the same thread count. Layout, all in
// the host's byte order (little-endian on every platform built today):
//
//   header   magic "HMPMCKPT", u32 version, u32 dimension, u32 shape
//            function, u32 scheme, i64 particles, u64 fingerprint (hash of
//            RunOptions::checkpoint_key and the problem's set-up figures),
//            i32 threads, i64 step, f64 time
//   loop     i64 total steps (estimate), f64 next series time, f64 next
//            snapshot time, f64 next reaction time, f64 loop wall seconds so
//            far, array of the snapshot times taken
//   series   array of sample times, u64 field count, one array per field
//   reactions  array of sample times, u64 boundary count (0 when none are
//            asked for), one array per boundary
//   profiles f64 next profile time, u64 line count, per line its sample
//            times and one array per field
//   consolidation  f64 next sample time, arrays of its sample times, excess
//            and volume
//   stages   u64 the stage in force (0: the first), the iteration counts of
//            the stages before it (i64 nonlinear, linear, solves, cutbacks,
//            i32 most in a step, array of that step's residuals)
//   particles  every array of ParticleState::for_each_array, in its order
//            (those of the stage in force: a resumed run first replays the
//            stages' moves of bodies)
//   absorbing  u64 the absorbing boundaries of the stage in force, per
//            boundary u8 whether its forces at rest are taken, their array
//            and the array of its dashpots (from the particles where the
//            stage began; boundary/constraints.hpp)
//   scheme   TimeScheme::save (e.g. the semi-implicit solver's initial
//            guess, the quasi-static step plan and counters)
//   trailer  u64 FNV-1a hash of everything before it
//
// An array is a u64 element count and the elements' bytes. The reader
// checks every count against the simulation it restores into and throws
// std::invalid_argument naming what does not match.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm::checkpoint {

inline constexpr char magic[8] = {'H', 'M', 'P', 'M', 'C', 'K', 'P', 'T'};
/// 2: reactions; 3: plastic strain, profiles; 4: stages (the stage in
/// force, the iterations of those before, particle ids); 5: consolidation;
/// 6: absorbing boundaries' forces at rest; 7: GIMP particles' box inverse
inline constexpr std::uint32_t version = 7;

/// FNV-1a, 64 bits, continuing from `h`.
inline std::uint64_t fnv1a(const char* data, std::size_t n,
                           std::uint64_t h = 14695981039346656037ull) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

/// Appends values and arrays to a byte buffer.
class Writer {
 public:
  explicit Writer(std::string& out) : out_(out) {}
  template <class T>
  void pod(const T& v) {
    raw(&v, sizeof v);
  }
  template <class T>
  void array(const std::vector<T>& a) {
    pod(static_cast<std::uint64_t>(a.size()));
    if (!a.empty()) raw(a.data(), sizeof(T) * a.size());
  }
  std::string& buffer() { return out_; }

 private:
  void raw(const void* p, std::size_t n) {
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, p, n);
  }
  std::string& out_;
};

/// Reads what a Writer wrote, refusing to read past the end.
class Reader {
 public:
  /// Reads in[0, end).
  Reader(const std::string& in, std::size_t end) : in_(in), end_(end) {}
  template <class T>
  T pod() {
    T v{};
    need(sizeof v, "a value");
    std::memcpy(&v, in_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  /// An array into `a`; when `expected` >= 0 its count must be that.
  template <class T>
  void array(std::vector<T>& a, std::int64_t expected = -1, const char* what = "an array") {
    const auto n = pod<std::uint64_t>();
    if (expected >= 0 && n != static_cast<std::uint64_t>(expected))
      throw std::invalid_argument(std::string("the checkpoint's ") + what + " has " +
                                  std::to_string(n) + " entries where this run has " +
                                  std::to_string(expected));
    if (n > (end_ - at_) / sizeof(T)) need(end_ - at_ + 1, what);
    a.resize(n);
    if (n) std::memcpy(static_cast<void*>(a.data()), in_.data() + at_, sizeof(T) * n);
    at_ += sizeof(T) * n;
  }
  std::size_t position() const { return at_; }

 private:
  void need(std::size_t n, const char* what) const {
    if (n > end_ - at_)
      throw std::invalid_argument(std::string("the checkpoint is truncated (") + what +
                                  " runs past its end at byte " + std::to_string(end_) + ")");
  }
  const std::string& in_;
  std::size_t end_;
  std::size_t at_ = 0;
};

/// The fixed part of a checkpoint and the time loop's output bookkeeping.
struct Header {
  std::uint32_t dimension = 0, shape = 0, scheme = 0;
  std::int64_t particles = 0;
  std::uint64_t fingerprint = 0;
  std::int32_t threads = 1;
  std::int64_t step = 0;
  double time = 0.0;
  std::int64_t total = 0;
  double next_series = 0.0, next_snapshot = 0.0, next_reaction = 0.0;
  double seconds = 0.0;  ///< loop wall time of the runs so far
  std::vector<double> snapshot_times;
};

/// Hash of the key and of the problem's figures a checkpoint must share.
std::uint64_t fingerprint(const Problem& problem, const std::string& key);

void write_header(Writer& w, const Header& h);

/// Checks the trailer's hash and reads the header (the reader then stands
/// at the series); throws std::invalid_argument when `bytes` is not a
/// checkpoint of this format, is truncated or corrupt, or belongs to
/// another problem or key.
Header read_header(Reader& r, const std::string& bytes, const Problem& problem,
                   const std::string& key);

/// Appends the trailer (the hash of the buffer so far).
inline void finish(Writer& w) {
  w.pod(fnv1a(w.buffer().data(), w.buffer().size()));
}

/// Where a checkpoint's body ends (before the trailer); throws when the
/// buffer is shorter than a trailer.
inline std::size_t body_end(const std::string& bytes) {
  if (bytes.size() < sizeof(magic) + sizeof(std::uint64_t))
    throw std::invalid_argument("the checkpoint is truncated (" + std::to_string(bytes.size()) +
                                " bytes)");
  return bytes.size() - sizeof(std::uint64_t);
}

}  // namespace hmpm::checkpoint
