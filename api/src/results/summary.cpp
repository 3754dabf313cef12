// results/summary.cpp — summary.json (results/writers.hpp), built as
// nlohmann's ordered_json: keys in the order a reader meets them.
#include <nlohmann/json.hpp>

#include "results/writers.hpp"

namespace hmpm::api {

void write_summary(const std::filesystem::path& path, const std::string& job_name,
                   const RunResult& run, const CostEstimate& cost,
                   const std::vector<std::string>& files) {
  nlohmann::ordered_json o;
  o["status"] = status_name(run.status);
  o["message"] = run.message;
  o["steps"] = run.steps;
  o["end_time"] = run.end_time;  // nlohmann writes a non-finite number as null
  o["dt"] = run.dt;
  // How the steps were chosen and their range (RunResult::dt_rule).
  o["time_step"] = {{"rule", run.dt_rule}, {"min", run.dt_min}, {"max", run.dt_max}};
  o["scheme"] = run.scheme;
  if (run.reports_iterations) {
    const RunResult::Iterations& it = run.iterations;
    o["iterations"] = {{"nonlinear", it.nonlinear},
                       {"linear", it.linear},
                       {"solves", it.solves},
                       {"cutbacks", it.cutbacks},
                       {"max_nonlinear", it.max_nonlinear},
                       {"worst_residuals", it.worst_residuals}};
  }
  if (run.collapse.found) {
    const RunResult::Collapse& k = run.collapse;
    o["collapse"] = {{"time", k.time},
                     {"criterion", k.criterion},
                     {"load", k.load},
                     {"max_displacement", k.max_displacement},
                     {"yielding_particles", k.yielding},
                     {"yielding_min", k.yield_min},
                     {"yielding_max", k.yield_max},
                     {"stopped", k.stopped},
                     {"message", k.message}};
  }
  if (run.strength_reduction.done) {
    const RunResult::StrengthReductionResult& sr = run.strength_reduction;
    o["strength_reduction"] = {{"factor_of_safety", sr.factor},
                               {"failed_at", sr.failed_at},  // null: not failed by max_factor
                               {"factors", sr.factors},
                               {"max_displacement", sr.max_displacement},
                               {"attempts", sr.attempts},
                               {"line_search_halvings", sr.backtracks},
                               {"trials_that_lost_a_particle", sr.lost_particle},
                               {"displacement_limit", sr.displacement_limit},
                               {"trials_past_the_displacement_limit", sr.past_displacement_limit},
                               {"message", sr.message}};
  }
  o["particles"] = run.particles;
  o["nodes"] = run.nodes;
  o["solve_seconds"] = run.solve_seconds;
  o["particle_steps_per_second"] = run.particle_steps_per_second;
  o["warnings"] = run.warnings;
  o["name"] = job_name;
  o["hmpm_version"] = version();
  o["state_bytes"] = run.state_bytes;
  o["cost"] = {{"particles", cost.particles},
               {"nodes", cost.nodes},
               {"cells", cost.cells},
               {"steps", cost.steps},
               {"dt", cost.dt},
               {"particle_steps", cost.particle_steps},
               {"memory_bytes", cost.memory_bytes},
               {"output_bytes", cost.output_bytes},
               {"series_rows", cost.series_rows},
               {"snapshots", cost.snapshots}};
  o["files"] = files;
  AtomicFile file(path);
  // Replaced, not thrown on: a message may quote bytes that are not UTF-8.
  file.stream() << o.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
  file.commit();
}

}  // namespace hmpm::api
