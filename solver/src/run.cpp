// run.cpp — placeholder until the time loop lands (this commit only wires the build).
#include <stdexcept>

#include "hmpm/run.hpp"

namespace hmpm {

RunResult run(const Problem& problem, const RunOptions&) {
  RunResult r;
  r.status = RunStatus::failed;
  r.message = "solver time loop not implemented yet";
  r.particles = count_particles(problem);
  return r;
}

}  // namespace hmpm
