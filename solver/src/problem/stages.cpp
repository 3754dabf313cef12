// problem/stages.cpp — a staged job's stages as Problems: what is in force
// in stage k, which bodies are in the run, and the ground before the first
// stage adds any.
#include <vector>

#include "hmpm/problem.hpp"
#include "hmpm/run.hpp"

namespace hmpm {

Problem stage_problem(const Problem& problem, std::size_t k) {
  Problem out = problem;
  out.stages.clear();
  for (std::size_t i = 1; i <= k && i <= problem.stages.size(); ++i) {
    const Stage& s = problem.stages[i - 1];
    const double previous_end = out.time.end;
    if (s.boundaries) out.boundaries = *s.boundaries;
    if (s.tractions) out.tractions = *s.tractions;
    if (s.fluxes) out.fluxes = *s.fluxes;
    if (s.gravity) out.gravity = *s.gravity;
    if (s.time) out.time = *s.time;
    if (s.local_damping) out.local_damping = *s.local_damping;
    for (const Stage::BodyMaterial& bm : s.body_materials)
      if (bm.body >= 0 && static_cast<std::size_t>(bm.body) < out.bodies.size())
        out.bodies[static_cast<std::size_t>(bm.body)].material = bm.material;
    out.time.start = previous_end;
    out.time.end = s.end;
  }
  return out;
}

std::vector<bool> stage_bodies(const Problem& problem, std::size_t k) {
  std::vector<bool> in(problem.bodies.size(), true);
  auto set = [&](const std::vector<int>& bodies, bool value) {
    for (int b : bodies)
      if (b >= 0 && static_cast<std::size_t>(b) < in.size())
        in[static_cast<std::size_t>(b)] = value;
  };
  for (const Stage& s : problem.stages) set(s.add_bodies, false);
  for (std::size_t i = 1; i <= k && i <= problem.stages.size(); ++i) {
    set(problem.stages[i - 1].add_bodies, true);
    set(problem.stages[i - 1].remove_bodies, false);
  }
  return in;
}

Problem initial_ground(const Problem& problem) {
  const std::vector<bool> in = stage_bodies(problem, 0);
  Problem out = problem;
  out.bodies.clear();
  for (std::size_t b = 0; b < problem.bodies.size(); ++b)
    if (in[b]) out.bodies.push_back(problem.bodies[b]);
  return out;
}

}  // namespace hmpm
