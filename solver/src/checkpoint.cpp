// checkpoint.cpp — the checkpoint header (checkpoint.hpp) and inspect_checkpoint.
#include "checkpoint.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "hmpm/run.hpp"

namespace hmpm::checkpoint {

std::uint64_t fingerprint(const Problem& problem, const std::string& key) {
  std::uint64_t h = fnv1a(key.data(), key.size());
  auto mix = [&](const auto& v) { h = fnv1a(reinterpret_cast<const char*>(&v), sizeof v, h); };
  mix(problem.dimension);
  mix(static_cast<int>(problem.shape_function));
  mix(static_cast<int>(problem.time.scheme));
  mix(problem.time.end);
  mix(problem.time.dt.value_or(0.0));
  mix(count_particles(problem));
  mix(problem.output.series_interval);
  mix(problem.output.snapshot_interval);
  mix(problem.output.reactions_interval);
  mix(problem.output.profile_interval);
  mix(problem.output.profiles.size());
  for (double tk : problem.output.profile_times) mix(tk);  // none: the fingerprint as before
  mix(problem.output.consolidation.interval);
  mix(problem.output.consolidation.from);
  mix(problem.stages.size());
  for (const Stage& s : problem.stages) mix(s.end);
  return h;
}

void write_header(Writer& w, const Header& h) {
  for (char c : magic) w.pod(c);
  w.pod(version);
  w.pod(h.dimension);
  w.pod(h.shape);
  w.pod(h.scheme);
  w.pod(h.particles);
  w.pod(h.fingerprint);
  w.pod(h.threads);
  w.pod(h.step);
  w.pod(h.time);
  w.pod(h.total);
  w.pod(h.next_series);
  w.pod(h.next_snapshot);
  w.pod(h.next_reaction);
  w.pod(h.seconds);
  w.array(h.snapshot_times);
}

Header read_header(Reader& r, const std::string& bytes, const Problem& problem,
                   const std::string& key) {
  const std::size_t end = body_end(bytes);
  for (char c : magic)
    if (r.pod<char>() != c)
      throw std::invalid_argument("not an hmpm checkpoint (its first bytes are not \"HMPMCKPT\")");
  const auto v = r.pod<std::uint32_t>();
  if (v != version)
    throw std::invalid_argument("checkpoint format version " + std::to_string(v) +
                                ", this solver reads version " + std::to_string(version));
  std::uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + end, sizeof stored);
  if (stored != fnv1a(bytes.data(), end))
    throw std::invalid_argument("the checkpoint is corrupt or truncated (its checksum of " +
                                std::to_string(end) + " bytes does not match)");
  Header h;
  h.dimension = r.pod<std::uint32_t>();
  h.shape = r.pod<std::uint32_t>();
  h.scheme = r.pod<std::uint32_t>();
  h.particles = r.pod<std::int64_t>();
  h.fingerprint = r.pod<std::uint64_t>();
  h.threads = r.pod<std::int32_t>();
  h.step = r.pod<std::int64_t>();
  h.time = r.pod<double>();
  h.total = r.pod<std::int64_t>();
  h.next_series = r.pod<double>();
  h.next_snapshot = r.pod<double>();
  h.next_reaction = r.pod<double>();
  h.seconds = r.pod<double>();
  r.array(h.snapshot_times, -1, "snapshot list");
  auto refuse = [](const std::string& what) {
    throw std::invalid_argument("the checkpoint belongs to another problem: " + what);
  };
  if (h.dimension != static_cast<std::uint32_t>(problem.dimension))
    refuse("dimension " + std::to_string(h.dimension) + ", this problem's is " +
           std::to_string(problem.dimension));
  if (h.shape != static_cast<std::uint32_t>(problem.shape_function))
    refuse("another shape function");
  if (h.scheme != static_cast<std::uint32_t>(problem.time.scheme)) refuse("another time scheme");
  const std::int64_t particles = count_particles(problem);
  if (h.particles != particles)
    refuse(std::to_string(h.particles) + " particles, this problem has " +
           std::to_string(particles));
  if (h.fingerprint != fingerprint(problem, key))
    refuse("it was written for another job spec (the hash of its key and set-up differs)");
  return h;
}

}  // namespace hmpm::checkpoint

namespace hmpm {

CheckpointInfo inspect_checkpoint(const Problem& problem, const std::string& checkpoint_key,
                                  const std::string& bytes) {
  checkpoint::Reader r(bytes, checkpoint::body_end(bytes));
  const checkpoint::Header h = checkpoint::read_header(r, bytes, problem, checkpoint_key);
  CheckpointInfo info;
  info.version = static_cast<int>(checkpoint::version);
  info.step = h.step;
  info.time = h.time;
  info.particles = h.particles;
  info.threads = h.threads;
  info.snapshot_times = h.snapshot_times;
  return info;
}

}  // namespace hmpm
