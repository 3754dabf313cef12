// run_job.cpp — one job run from a parsed spec to its result files.
//
// Wraps hmpm::run: snapshots are written as the solver hands them over (the
// .pvd collection is rewritten after each, so partial results are usable),
// the series and the reactions after the loop, summary.json last and always — also when the
// run failed or a file could not be written (then the other files it wrote
// are removed, so the listed files are exactly the ones left). Checkpoints
// (options on_checkpoint) go to the caller as the solver takes them; a run
// resumed from one (options.resume) keeps the snapshots already in out_dir,
// lists them in the .pvd again and takes the series so far from the checkpoint.
#include <algorithm>
#include <stdexcept>

#include "hmpm/api/job.hpp"
#include "results/writers.hpp"

namespace hmpm::api {

namespace fs = std::filesystem;

JobOutcome run_job(const ParsedJob& job, const fs::path& out_dir, const hmpm::RunOptions& options) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw std::runtime_error("cannot create output directory " + out_dir.string() + ": " +
                             ec.message());

  JobOutcome outcome;
  std::vector<std::pair<double, std::string>> snapshots;
  std::string write_error;
  bool mechanism = false;  // mechanism.vtu written (strength reduction)
  if (options.resume) {
    try {  // the snapshots the interrupted run wrote before its checkpoint
      const CheckpointInfo info =
          inspect_checkpoint(job.problem, options.checkpoint_key, *options.resume);
      for (std::size_t i = 0; i < info.snapshot_times.size(); ++i)
        snapshots.emplace_back(info.snapshot_times[i], snapshot_file_name(static_cast<int>(i)));
    } catch (const std::invalid_argument&) {
      // hmpm::run refuses the checkpoint below, with the same message
    }
  }
  RunOptions opts = options;
  std::vector<std::string> material_names;
  for (const Material& m : job.problem.materials) material_names.push_back(m.name);
  opts.on_snapshot = [&](const Snapshot& s) {
    if (s.mechanism) {  // a strength reduction's failure mechanism, not in the .pvd
      try {
        write_snapshot_vtu(out_dir / "mechanism.vtu", s, material_names);
        mechanism = true;
      } catch (const std::exception& e) {
        write_error = e.what();
        throw;
      }
      if (options.on_snapshot) options.on_snapshot(s);
      return;
    }
    const std::string name = snapshot_file_name(s.index);
    try {
      write_snapshot_vtu(out_dir / name, s, material_names);
      snapshots.emplace_back(s.time, name);
      write_pvd(out_dir / "snapshots.pvd", snapshots);
    } catch (const std::exception& e) {
      write_error = e.what();
      throw;  // ends the run; reported below
    }
    if (options.on_snapshot) options.on_snapshot(s);
  };

  try {
    outcome.run = hmpm::run(job.problem, opts);
  } catch (const std::exception& e) {
    outcome.run.status = RunStatus::failed;
    outcome.run.message = write_error.empty()
                              ? std::string("the solver refused the problem: ") + e.what()
                              : "could not write results: " + write_error;
  }

  for (const auto& [time, name] : snapshots) outcome.files.push_back(name);
  if (!snapshots.empty()) outcome.files.push_back("snapshots.pvd");
  if (mechanism) outcome.files.push_back("mechanism.vtu");
  const OutputRequest& out = job.problem.output;
  const bool series_requested = !out.series_particles.empty() && !out.series_fields.empty();
  // A pair of files (`stem`.json and `stem`.csv) of a history kept in memory.
  auto write_history = [&](const std::string& stem, auto write_json, auto write_csv,
                           const auto& history) {
    if (!write_error.empty()) return;
    try {
      write_json(out_dir / (stem + ".json"), history);
      write_csv(out_dir / (stem + ".csv"), history);
      outcome.files.push_back(stem + ".json");
      outcome.files.push_back(stem + ".csv");
    } catch (const std::runtime_error& e) {
      write_error = e.what();
      outcome.run.status = RunStatus::failed;
      outcome.run.message = std::string("could not write results: ") + e.what();
    }
  };
  if (series_requested)
    write_history("series", write_series_json, write_series_csv, outcome.run.series);
  if (out.reactions_interval > 0)
    write_history("reactions", write_reactions_json, write_reactions_csv, outcome.run.reactions);
  if (!out.profiles.empty())
    write_history(
        "profiles",
        [&](const fs::path& p, const auto& h) { write_profiles_json(p, h, job.profiles); },
        [&](const fs::path& p, const auto& h) { write_profiles_csv(p, h, job.profiles); },
        outcome.run.profiles);
  if (out.consolidation.interval > 0)
    write_history(
        "consolidation",
        [&](const fs::path& p, const auto& h) {
          write_consolidation_json(p, h, out.consolidation.from);
        },
        write_consolidation_csv, outcome.run.consolidation);
  if (!write_error.empty()) {
    // Partial results are removed: they hold the space a full disk needs,
    // and a set of snapshots without the rest is no result.
    for (const std::string& name : outcome.files) fs::remove(out_dir / name, ec);
    outcome.run.message += "; the " + std::to_string(outcome.files.size()) +
                           " result files written before were removed";
    outcome.files.clear();
    outcome.write_error = write_error;
  }
  outcome.files.push_back("summary.json");
  std::sort(outcome.files.begin(), outcome.files.end());
  try {
    write_summary(out_dir / "summary.json", job.name, outcome.run, job.cost, outcome.files);
  } catch (const std::runtime_error& e) {
    if (outcome.write_error.empty()) {
      for (const std::string& name : outcome.files) fs::remove(out_dir / name, ec);
      outcome.write_error = e.what();
      outcome.run.status = RunStatus::failed;
      outcome.run.message = std::string("could not write results: ") + e.what();
    }
    fs::remove(out_dir / "summary.json", ec);
    outcome.files.clear();
  }
  return outcome;
}

std::string media_type_for(std::string_view name) {
  auto ends = [&](std::string_view s) {
    return name.size() >= s.size() && name.substr(name.size() - s.size()) == s;
  };
  if (ends(".json")) return "application/json";
  if (ends(".csv")) return "text/csv";
  if (ends(".pvd") || ends(".vtu")) return "application/xml";
  return "application/octet-stream";
}

}  // namespace hmpm::api
