// job.hpp — the job spec at the edge: JSON in, typed hmpm::Problem out, and
// the result files out again.
//
// `parse_job` is the only place a job spec is read. It collects every problem
// (not just the first), each with its JSON pointer and a message that says
// what was expected, and converts a valid spec into the solver's typed
// Problem with expressions compiled once (muParser). `run_job` runs a parsed
// job and writes the contract's result files (summary.json, series.json,
// series.csv, snapshots.pvd + .vtu) into a directory; the command line and
// the service both use it, so their files are identical.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm::api {

/// One problem in a job spec: `path` is an RFC 6901 JSON pointer ("" is the
/// whole document), `message` says what is wrong and what was expected.
struct SpecError {
  std::string path;
  std::string message;
};

/// Limits that protect a shared server. Exceeding one is a SpecError whose
/// message gives the computed figure and the limit.
struct Limits {
  std::int64_t max_particles = 2'000'000;
  std::int64_t max_cells = 4'000'000;
  std::int64_t max_steps = 20'000'000;
  std::int64_t max_series_rows = 1'000'000;
  std::int64_t max_snapshots = 1'000;
  std::int64_t max_output_bytes = std::int64_t{4} << 30;  ///< estimated result size
  std::int64_t max_body_bytes = std::int64_t{16} << 20;   ///< size of the spec text
  int max_json_depth = 64;
  std::int64_t max_series_particles = 10'000;  ///< entries of output.series.particles
  /// Formulas (strings in x, y, z or t) in one spec, and their characters
  /// in all: compiling and checking them is validation work done before a
  /// job is accepted, so it is bounded (each formula is at most 4096
  /// characters besides).
  std::int64_t max_formulas = 1000;
  std::int64_t max_formula_characters = 65'536;
};

/// The machine speed the wall-time estimate scales with (docs/performance.md,
/// "Wall-time estimate"): the seconds one particle-step of the reference
/// particle (2D, linear shape functions, elastic) takes on one thread.
/// hmpm-server measures it at start-up (`calibrate`); without a measurement
/// the default is the value measured on the development machine.
struct Calibration {
  double seconds_per_particle_step = 1.0e-7;
  int threads = 1;        ///< solver threads a job runs with
  bool measured = false;  ///< false: the built-in default
};

/// Runs a fixed small explicit problem (about 0.2 s) a few times and returns
/// the median seconds per reference particle-step; `threads` is stored for
/// the estimate (the problem itself is small enough to run on one).
Calibration calibrate(int threads);

/// Steps and expected wall time of one scheme for the same Problem.
struct SchemeCost {
  hmpm::Scheme scheme = hmpm::Scheme::explicit_scheme;
  std::int64_t steps = 0;
  double dt = 0.0;  ///< the (first) step, s
  /// false when the step varies (quasi_static growth or automatic).
  bool fixed = true;
  double wall_seconds = 0.0;
};

/// What a job will cost, computed before it runs.
struct CostEstimate {
  std::int64_t particles = 0;
  std::int64_t nodes = 0;
  std::int64_t cells = 0;
  std::int64_t steps = 0;
  double dt = 0.0;
  std::int64_t particle_steps = 0;
  /// Peak memory of the run: particle and grid state, the grid buffers of
  /// every solver thread (Calibration::threads), the series kept in memory
  /// until the end, one snapshot's arrays and set-up's temporaries
  /// (docs/performance.md, "Memory estimate").
  std::int64_t memory_bytes = 0;
  int threads = 1;                ///< solver threads the estimate assumes
  std::int64_t output_bytes = 0;  ///< result files estimate
  std::int64_t series_rows = 0;
  std::int64_t reaction_rows = 0;  ///< samples of output.reactions (0: none asked for)
  std::int64_t snapshots = 0;
  hmpm::Scheme scheme = hmpm::Scheme::explicit_scheme;  ///< time.scheme
  double wall_seconds = 0.0;  ///< expected wall time of the run with its scheme
  Calibration calibration;    ///< what wall_seconds was computed with
  /// Every scheme for the same problem (explicit, semi_implicit,
  /// quasi_static), each with its automatic step except the run's own.
  std::vector<SchemeCost> schemes;
};

/// Where a profile's points lie (output.profiles.lines[i]): `points`
/// equally spaced from `from` to `to`, ends included; problem.output.
/// profiles[i] holds the particle nearest to each.
struct ProfileGeometry {
  hmpm::Vec3 from{0, 0, 0};
  hmpm::Vec3 to{0, 0, 0};
  std::vector<hmpm::Vec3> points;
};

struct ParsedJob {
  std::string name;
  hmpm::Problem problem;
  std::vector<ProfileGeometry> profiles;  ///< one per problem.output.profiles line
  /// The estimate the limits were checked against, with parse_job's
  /// calibration (the one estimate of a parse).
  CostEstimate cost;
  /// Runnable, but worth knowing before running (hmpm::problem_warnings),
  /// with JSON pointers like errors; the run's summary repeats them.
  std::vector<SpecError> warnings;
};

struct ParseResult {
  std::optional<ParsedJob> job;   ///< set when errors is empty
  std::vector<SpecError> errors;  ///< every problem found, in document order
  bool ok() const { return errors.empty(); }
};

/// Parses, validates and converts a job spec. Never throws. The cost is
/// estimated once, with `calibration` (ParsedJob::cost).
ParseResult parse_job(std::string_view json_text, const Limits& limits = {},
                      const Calibration& calibration = {});

/// The result files of one run, as written into a directory.
struct JobOutcome {
  hmpm::RunResult run;
  std::vector<std::string> files;  ///< names relative to the output directory
  /// Why a result file could not be written (disk full, ...); empty if all were.
  std::string write_error;
};

/// Runs `job` and writes every result file into `out_dir` (created if needed):
/// summary.json always (also on failure), series.json and series.csv when a
/// series was requested, snapshots.pvd and snapshot_NNNN.vtu when snapshots
/// were requested. When a file cannot be written, the run fails
/// (`write_error`, run.status failed), every other result file it wrote is
/// removed (a full disk is not left fuller, and no file is left that the
/// list does not name) and summary.json says why; `files` then lists
/// summary.json alone, or nothing if even that could not be written. Throws
/// std::runtime_error only when `out_dir` cannot be created.
JobOutcome run_job(const ParsedJob& job, const std::filesystem::path& out_dir,
                   const hmpm::RunOptions& options = {});

/// Cost of `problem` as `parse_job` computes it (particles, nodes, steps
/// from the chosen dt, memory and output estimates). `problem` must have
/// passed `hmpm::check_problem`.
CostEstimate estimate_cost(const hmpm::Problem& problem, const Calibration& calibration = {});

/// The keys `parse_job` accepts in each object of a spec. `location` is a
/// JSON pointer pattern where "*" stands for any array index or material
/// name (e.g. "/materials/*/hydraulic"). Used to keep the JSON Schema honest.
struct SpecObjectKeys {
  std::string location;
  std::vector<std::string> keys;
};
const std::vector<SpecObjectKeys>& spec_object_keys();

/// The parser's tables as JSON text (what `hmpm spec-keys` prints):
/// {"objects": {location: [keys]}, "values": {location: [allowed values]},
///  "fields": [{"name", "kind"}], "models": [{"name", "parameters": [{"key",
///  "required", "default", "range": {JSON Schema bounds}}]}]}.
/// The JSON Schema test compares the schema with it.
std::string spec_tables_json();

/// The hmpm version ("0.1.0"), as written into summary.json.
const char* version();

/// Media type of a result file by name ("application/json", "text/csv",
/// "application/xml" for .pvd/.vtu, "application/octet-stream" otherwise).
std::string media_type_for(std::string_view file_name);

}  // namespace hmpm::api
