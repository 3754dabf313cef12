// ensembles/ensemble.hpp — an ensemble request (contract v3, POST
// /ensembles), its samples' specs, and the statistics over their results.
//
// An ensemble is a job spec, a sample count, a seed and a list of varied
// parameters, each a JSON pointer into the spec with either a distribution
// (lognormal, normal, uniform: as a random field's, hmpm/random_field.hpp)
// or a list of values (a sweep). Sample k's spec is the base spec with each
// pointer set to its k-th draw (or value); everything about a sample is a
// function of (seed, k), so the same request gives the same samples on any
// server. The samples then run as ordinary jobs. statistics.json is the
// mean, standard deviation and 5th, 50th and 95th percentiles (linear
// interpolation between order statistics, numpy's default) of every series
// field of every series particle at every time, over the successful samples.
// Pure functions of JSON: no store, no HTTP (server/src/http/ensembles.cpp
// and the stores hold those).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hmpm/api/job.hpp"
#include "hmpm/random_field.hpp"
#include "hmpm/server/job_status.hpp"

namespace hmpm::server::ensembles {

using nlohmann::json;

/// One varied parameter: a distribution, or the values of a sweep.
struct Vary {
  std::string path;  ///< JSON pointer into the spec
  std::optional<RandomField> distribution;
  std::vector<json> values;  ///< a sweep: sample k takes values[k]
};

// NOLINTNEXTLINE(bugprone-exception-escape): json's defaulted members (never throw for null)
struct Request {
  json spec;
  int samples = 0;
  std::uint64_t seed = 0;
  std::vector<Vary> vary;
};

/// The largest ensemble one request may ask for.
inline constexpr int max_samples = 10'000;

/// Reads a POST /ensembles body. Every problem comes back with its JSON
/// pointer into the body (the spec's own validity is checked per sample by
/// parse_job). A sweep's length must equal `samples` (or `samples` is
/// absent and taken from it); a pointer must name a number in the spec.
std::optional<Request> read_request(const json& body, std::vector<api::SpecError>& errors);

/// The value the k-th sample gives each varied parameter, in `vary` order.
std::vector<json> sample_values(const Request& request, int k);

/// The k-th sample's spec: the base spec with the sample's values set, and
/// its name "<name>-<k>" (the base spec's name, or "ensemble").
json sample_spec(const Request& request, int k);

/// Reads a distribution object ({"lognormal": {"mean", "cov"}}, {"normal":
/// {"mean", "std"}}, {"uniform": {"min", "max"}}) at `path`; nullopt with
/// errors appended when it is not one.
std::optional<RandomField> read_distribution(const json& d, const std::string& path,
                                             std::vector<api::SpecError>& errors);

/// The statistics of the series of the successful samples (each the parsed
/// series.json): the first sample's times and particles; a time enters a
/// sample's figures when that sample has a row within 1e-9 s of it.
json statistics(const std::vector<json>& series);

/// q-quantile (0..1) of `values` (sorted in place), linear interpolation.
double quantile(std::vector<double>& values, double q);

/// One sample as the ensemble's status needs it.
struct SampleState {
  JobStatus status = JobStatus::accepted;
  double progress = 0.0;  ///< percent
};

/// An ensemble's status and progress, derived from its samples'.
// NOLINTNEXTLINE(bugprone-exception-escape): json's defaulted members (never throw for null)
struct Summary {
  JobStatus status = JobStatus::accepted;
  double progress = 0.0;  ///< percent, 0..100
  /// How many samples are in each status (every status present, 0 or more).
  json counts;
};

/// The status derived from the samples': accepted while none has started
/// or ended; running while some have and others wait or run; once all have
/// ended, dismissed if any was dismissed (the ensemble was cancelled or
/// deleted), else failed if any failed, else successful. Progress is the
/// mean of the samples' progress, an ended sample counting 100 (a failed
/// or cancelled sample is done too). No samples (retention purged them
/// all): successful at 100.
Summary summarise(const std::vector<SampleState>& samples);

}  // namespace hmpm::server::ensembles
