// Checkpoints (RunOptions::on_checkpoint / resume, solver/src/checkpoint.hpp):
// for each time scheme, a run resumed in a fresh run from the checkpoint of
// step k ends with the outputs of the uninterrupted run bit for bit (every
// snapshot array, the series, the reactions, the step count and the
// scheme's counters), at two solver threads; checkpoints of another problem, another key, truncated
// or corrupt ones are refused with a message saying why.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

/// A saturated Mohr-Coulomb block settling under gravity, drained at the top
/// (as in test_threads.cpp), with series and snapshots of every field; a
/// consolidating clay column for the implicit schemes.
hmpm::Problem block(hmpm::Scheme scheme) {
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.max = {1.0, 1.2, 0};
  p.grid.cells = {10, 12, 1};
  hmpm::Material m;
  m.name = "soil";
  m.density = 2000;
  m.youngs_modulus = 5e6;
  m.poisson_ratio = 0.3;
  m.plasticity = hmpm::MohrCoulomb{25.0, 0.0, 1e3, 0.0};
  m.hydraulic = hmpm::Hydraulic{0.35, 1e-4, 1e8, 1000.0, std::numeric_limits<double>::infinity()};
  p.materials.push_back(m);
  hmpm::Body b;
  b.box.max = {1.0, 1.0, 0};
  b.particles_per_cell = 2;
  b.initial.pore_pressure = [](const hmpm::Vec3& x) { return 1e3 * (1.0 - x[1]); };
  p.bodies.push_back(b);
  p.gravity = {0, -9.81, 0};
  hmpm::Boundary bottom = problems::fixed_velocity(problems::plane(p, 1, 0.0), 1);
  bottom.velocity[0] = problems::constant(0.0);
  p.boundaries.push_back(bottom);
  p.boundaries.push_back(problems::fixed_pressure(problems::plane(p, 1, 1.0), 0.0));
  p.time.scheme = scheme;
  p.time.end = 0.02;
  p.output.series_particles = {0, 7, 100};
  p.output.series_fields = {hmpm::Field::position, hmpm::Field::pore_pressure,
                            hmpm::Field::effective_stress};
  p.output.series_interval = 0.001;
  p.output.snapshot_interval = 0.004;
  if (scheme != hmpm::Scheme::explicit_scheme) {
    // Consolidation of a loaded clay column (as in test_quasi_static.cpp).
    p = problems::column(2, 1, 1.0, 10, 2);
    p.materials.push_back(problems::saturated_elastic(2650, 1e7, 0.3, 0.4, 1e-6, 2.2e9));
    problems::load_consolidation(p, 1, 1.0, 10, 2, 1e4, 1.0);
    p.time.scheme = scheme;
    p.output.series_particles = {0, 7, 30};
    p.output.series_fields = {hmpm::Field::position, hmpm::Field::pore_pressure,
                              hmpm::Field::effective_stress};
  }
  if (scheme == hmpm::Scheme::semi_implicit) {
    // The iterative solver's initial guess (the last increment) is state.
    p.time.implicit.linear_solver = hmpm::LinearSolver::iterative;
    p.time.end = 0.03;
    p.output.series_interval = 0.002;
    p.output.snapshot_interval = 0.006;
  }
  if (scheme == hmpm::Scheme::quasi_static) {
    // Growing steps: the step plan is state too.
    p.time.end = 200.0;
    p.time.growth = hmpm::StepGrowth{1.0, 40.0, 1.3};
    p.output.series_interval = 20.0;
    p.output.snapshot_interval = 50.0;
  }
  // The boundaries' reactions and the profiles are histories like the series.
  p.output.reactions_interval = p.output.series_interval;
  p.output.profiles = {{{1, 2, 3}, {hmpm::Field::pore_pressure}},
                       {{4, 5}, {hmpm::Field::displacement, hmpm::Field::strain}}};
  p.output.profile_interval = 1.5 * p.output.series_interval;
  // And the degree of consolidation, from a reference instant after t = 0.
  if (!p.materials.empty() && p.materials[0].hydraulic) {
    p.output.consolidation.interval = 1.25 * p.output.series_interval;
    p.output.consolidation.from = 0.5 * p.output.series_interval;
  }
  return p;
}

struct Outputs {
  hmpm::RunResult result;
  std::vector<hmpm::Snapshot> snapshots;
  std::string checkpoint;  ///< the one taken after step `take_at`
  std::int64_t checkpoints = 0;
};

Outputs run(const hmpm::Problem& p, std::int64_t take_at, const std::string* resume,
            const std::string& key = "spec") {
  Outputs o;
  hmpm::RunOptions opt;
  opt.threads = 2;
  opt.min_particles_per_thread = 1;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) { o.snapshots.push_back(s); };
  opt.checkpoint_interval_s = 1e-12;  // every step
  opt.checkpoint_key = key;
  opt.on_checkpoint = [&](const hmpm::Checkpoint& c) {
    ++o.checkpoints;
    if (c.step == take_at) o.checkpoint = c.bytes;
  };
  opt.resume = resume;
  o.result = hmpm::run(p, opt);
  return o;
}

void expect_same_snapshot(const hmpm::Snapshot& a, const hmpm::Snapshot& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.displacement, b.displacement);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_EQ(a.pore_pressure, b.pore_pressure);
  EXPECT_EQ(a.darcy_velocity, b.darcy_velocity);
  EXPECT_EQ(a.effective_stress, b.effective_stress);
  EXPECT_EQ(a.total_stress, b.total_stress);
  EXPECT_EQ(a.strain, b.strain);
  EXPECT_EQ(a.porosity, b.porosity);
  EXPECT_EQ(a.plastic_strain, b.plastic_strain);
  EXPECT_EQ(a.volume, b.volume);
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.material, b.material);
}

class Resume : public ::testing::TestWithParam<hmpm::Scheme> {};

// Bit-identical: EXPECT_EQ on doubles and whole arrays, no tolerance. A
// missing piece of state (a series sample, the step plan, an initial guess,
// a plastic internal variable) changes later steps by round-off at least.
/// Bit for bit, NaN equal to NaN.
bool same_bits(const std::vector<std::vector<double>>& a,
               const std::vector<std::vector<double>>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].size() != b[i].size() ||
        std::memcmp(a[i].data(), b[i].data(), a[i].size() * sizeof(double)) != 0)
      return false;
  return true;
}

// Interrupted after `fraction` of its steps and resumed, `p` ends as run
// whole.
void expect_resume_as_whole(const hmpm::Problem& p, const char* label, double fraction = 0.5) {
  const Outputs whole = run(p, -1, nullptr);
  ASSERT_EQ(whole.result.status, hmpm::RunStatus::successful) << whole.result.message;
  const std::int64_t steps = whole.result.steps;
  ASSERT_GE(steps, 6) << "too few steps to interrupt";
  ASSERT_GE(whole.snapshots.size(), 3u);
  // Some snapshots before, some after.
  const auto k = static_cast<std::int64_t>(fraction * static_cast<double>(steps)) + 1;
  const Outputs first = run(p, k, nullptr);
  ASSERT_FALSE(first.checkpoint.empty());
  EXPECT_EQ(first.checkpoints, steps);
  const auto t0 = std::chrono::steady_clock::now();
  const hmpm::CheckpointInfo info = hmpm::inspect_checkpoint(p, "spec", first.checkpoint);
  const double inspect_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(info.step, k);
  EXPECT_EQ(info.particles, whole.result.particles);
  std::printf(
      "%s: %lld steps, checkpoint at step %lld: %zu bytes, %.1f bytes per particle, "
      "inspected in %.2g s\n",
      label, static_cast<long long>(steps), static_cast<long long>(k), first.checkpoint.size(),
      static_cast<double>(first.checkpoint.size()) / static_cast<double>(whole.result.particles),
      inspect_s);

  const Outputs resumed = run(p, -1, &first.checkpoint);
  ASSERT_EQ(resumed.result.status, hmpm::RunStatus::successful) << resumed.result.message;
  EXPECT_EQ(resumed.result.steps, steps);
  EXPECT_EQ(resumed.result.end_time, whole.result.end_time);
  EXPECT_EQ(resumed.result.message, whole.result.message);
  EXPECT_EQ(resumed.checkpoints, steps - k);
  // Snapshots: those taken before the checkpoint are not taken again.
  ASSERT_EQ(info.snapshot_times.size() + resumed.snapshots.size(), whole.snapshots.size());
  for (std::size_t i = 0; i < info.snapshot_times.size(); ++i)
    EXPECT_EQ(info.snapshot_times[i], whole.snapshots[i].time);
  for (std::size_t i = 0; i < resumed.snapshots.size(); ++i)
    expect_same_snapshot(resumed.snapshots[i], whole.snapshots[info.snapshot_times.size() + i]);
  const hmpm::Series &a = resumed.result.series, &b = whole.result.series;
  EXPECT_EQ(a.time, b.time);
  EXPECT_TRUE(same_bits(a.values, b.values));  // NaN (a particle out of the run) included
  EXPECT_EQ(a.particles, b.particles);
  ASSERT_FALSE(whole.result.reactions.time.empty());
  EXPECT_EQ(resumed.result.reactions.time, whole.result.reactions.time);
  EXPECT_EQ(resumed.result.reactions.force, whole.result.reactions.force);
  ASSERT_EQ(whole.result.profiles.size(), 2u);
  ASSERT_GE(whole.result.profiles[1].time.size(), 3u);
  ASSERT_EQ(resumed.result.profiles.size(), 2u);
  for (std::size_t l = 0; l < 2; ++l) {
    EXPECT_EQ(resumed.result.profiles[l].time, whole.result.profiles[l].time);
    EXPECT_EQ(resumed.result.profiles[l].values, whole.result.profiles[l].values);
  }
  const hmpm::RunResult::Consolidation &ca = resumed.result.consolidation,
                                       &cb = whole.result.consolidation;
  ASSERT_GE(cb.time.size(), 3u);  // every variant has pore water
  EXPECT_EQ(ca.time, cb.time);
  EXPECT_TRUE(same_bits({ca.excess, ca.degree, {ca.t50, ca.t90}},
                        {cb.excess, cb.degree, {cb.t50, cb.t90}}));
  const auto &ia = resumed.result.iterations, &ib = whole.result.iterations;
  EXPECT_EQ(ia.nonlinear, ib.nonlinear);
  EXPECT_EQ(ia.linear, ib.linear);
  EXPECT_EQ(ia.solves, ib.solves);
  EXPECT_EQ(ia.cutbacks, ib.cutbacks);
  EXPECT_EQ(ia.max_nonlinear, ib.max_nonlinear);
  EXPECT_EQ(ia.worst_residuals, ib.worst_residuals);
}

TEST_P(Resume, FromAMidRunCheckpointGivesTheUninterruptedResultsBitForBit) {
  expect_resume_as_whole(block(GetParam()), hmpm::scheme_name(GetParam()));
}

// The explicit block on an absorbing base shaken sideways: the base's
// forces at rest, taken in the first step, are state (a resumed run that
// took them again, from the state at the checkpoint, would hold the block
// up with other forces).
TEST(Resume, OnAShakenAbsorbingBase) {
  hmpm::Problem p = block(hmpm::Scheme::explicit_scheme);
  hmpm::Boundary base;
  base.nodes = problems::plane(p, 1, 0.0);
  base.absorbing = hmpm::Absorbing{1, 0};
  base.velocity[0] = [](double t) { return 0.05 * std::sin(300.0 * t); };
  p.boundaries[0] = base;
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  expect_resume_as_whole(p, "absorbing base");
}

// A staged job: the explicit block, then a fill added above it with a
// smaller Courant factor (a fresh scheme, another dt), then the fill
// removed again. (The semi-implicit scheme cannot take this collapsing
// block with free sides, staged or not: a particle volume turns negative at
// t = 0.013 s with linear shape functions.) Interrupted in the second stage and in the third (after
// both moves of particles), it resumes as run whole: the particles in the order of the
// uninterrupted run, the stage's scheme state, the iterations of the stages before.
TEST(Resume, AcrossStagesThatAddAndRemoveBodies) {
  hmpm::Problem p = block(hmpm::Scheme::explicit_scheme);
  p.time.end = 0.01;
  hmpm::Body fill = p.bodies[0];
  fill.box.min = {0.0, 1.0, 0};
  fill.box.max = {1.0, 1.2, 0};
  fill.initial = hmpm::InitialFields{};
  p.bodies.push_back(fill);
  hmpm::Stage add;
  add.name = "fill";
  add.end = 0.02;
  add.add_bodies = {1};
  hmpm::TimeControl smaller;
  smaller.courant = 0.35;
  add.time = smaller;
  hmpm::Stage dig;
  dig.name = "dig";
  dig.end = 0.03;
  dig.remove_bodies = {1};
  dig.time = hmpm::TimeControl{};
  p.stages = {add, dig};
  p.output.series_particles.push_back(hmpm::count_particles(p) - 1);  // in the fill
  ASSERT_TRUE(hmpm::check_problem(p).empty());
  expect_resume_as_whole(p, "staged, stage 2", 0.5);
  expect_resume_as_whole(p, "staged, stage 3", 0.85);
}

INSTANTIATE_TEST_SUITE_P(Schemes, Resume,
                         ::testing::Values(hmpm::Scheme::explicit_scheme,
                                           hmpm::Scheme::semi_implicit, hmpm::Scheme::quasi_static),
                         [](const auto& info) {
                           return std::string(hmpm::scheme_name(info.param));
                         });

// A run cancelled on purpose (a server shutting down) checkpoints where it
// stopped, between the periodic checkpoints; resumed, it ends as the
// uninterrupted run.
TEST(Checkpoint, ACancelledRunCheckpointsWhereItStopped) {
  const hmpm::Problem p = block(hmpm::Scheme::explicit_scheme);
  const Outputs whole = run(p, -1, nullptr);
  ASSERT_EQ(whole.result.status, hmpm::RunStatus::successful) << whole.result.message;
  std::atomic<bool> cancel{false};
  hmpm::RunOptions opt;
  opt.threads = 2;
  opt.min_particles_per_thread = 1;
  opt.cancel = &cancel;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) {
    if (s.index == 2) cancel = true;
  };
  opt.checkpoint_interval_s = 1e9;  // no periodic checkpoint in this run
  opt.checkpoint_key = "spec";
  std::vector<hmpm::Checkpoint> taken;
  opt.on_checkpoint = [&](const hmpm::Checkpoint& c) { taken.push_back(c); };
  const hmpm::RunResult stopped = hmpm::run(p, opt);
  ASSERT_EQ(stopped.status, hmpm::RunStatus::cancelled);
  ASSERT_EQ(taken.size(), 1u);
  EXPECT_EQ(taken[0].step, stopped.steps);
  EXPECT_EQ(hmpm::inspect_checkpoint(p, "spec", taken[0].bytes).snapshot_times.size(), 3u);
  const Outputs resumed = run(p, -1, &taken[0].bytes);
  ASSERT_EQ(resumed.result.status, hmpm::RunStatus::successful) << resumed.result.message;
  EXPECT_EQ(resumed.result.steps, whole.result.steps);
  EXPECT_EQ(resumed.result.series.values, whole.result.series.values);
  EXPECT_EQ(resumed.result.reactions.force, whole.result.reactions.force);
  ASSERT_EQ(resumed.snapshots.size() + 3, whole.snapshots.size());
  expect_same_snapshot(resumed.snapshots.back(), whole.snapshots.back());
}

/// The message run() refuses `bytes` with (empty when it does not).
std::string refusal(const hmpm::Problem& p, const std::string& bytes,
                    const std::string& key = "spec") {
  try {
    (void)run(p, -1, &bytes, key);
  } catch (const std::invalid_argument& e) {
    EXPECT_THROW(hmpm::inspect_checkpoint(p, key, bytes), std::invalid_argument);
    return e.what();
  }
  return "";
}

TEST(Checkpoint, OfAnotherProblemOrKeyTruncatedOrCorruptIsRefused) {
  const hmpm::Problem p = block(hmpm::Scheme::explicit_scheme);
  const Outputs first = run(p, 3, nullptr);
  ASSERT_FALSE(first.checkpoint.empty());
  const std::string& good = first.checkpoint;

  hmpm::Problem longer = p;
  longer.time.end = 0.03;
  EXPECT_NE(refusal(longer, good).find("another job spec"), std::string::npos);
  EXPECT_NE(refusal(p, good, "another spec").find("another job spec"), std::string::npos);
  hmpm::Problem finer = p;
  finer.bodies[0].particles_per_cell = 3;
  EXPECT_NE(refusal(finer, good).find("particles"), std::string::npos) << refusal(finer, good);
  EXPECT_NE(refusal(block(hmpm::Scheme::semi_implicit), good).find("time scheme"),
            std::string::npos);

  EXPECT_NE(refusal(p, good.substr(0, good.size() / 2)).find("corrupt or truncated"),
            std::string::npos);
  EXPECT_NE(refusal(p, good.substr(0, 10)).find("truncated"), std::string::npos);
  std::string flipped = good;
  flipped[flipped.size() / 3] ^= 0x10;
  EXPECT_NE(refusal(p, flipped).find("corrupt"), std::string::npos);
  EXPECT_NE(refusal(p, "not a checkpoint at all").find("HMPMCKPT"), std::string::npos);
  // The good one is accepted by the same problem and key.
  EXPECT_EQ(refusal(p, good), "");
}

}  // namespace
