// Threads change only the order of floating-point sums at the nodes: runs
// with 1 and 2 threads agree to round-off, and two runs with the same thread
// count are identical bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "hmpm/run.hpp"
#include "problems.hpp"

namespace {

hmpm::Problem saturated_block() {
  hmpm::Problem p;
  p.dimension = 2;
  p.grid.max = {1.0, 1.2, 0};
  p.grid.cells = {20, 24, 1};
  hmpm::Material m;
  m.name = "soil";
  m.density = 2000;
  m.youngs_modulus = 5e6;
  m.poisson_ratio = 0.3;
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
  p.time.end = 0.05;
  p.output.snapshot_interval = 0.05;
  return p;
}

std::vector<double> final_state(const hmpm::Problem& p, int threads) {
  std::vector<double> out;
  hmpm::RunOptions opt;
  opt.threads = threads;
  opt.min_particles_per_thread = 1;
  opt.on_snapshot = [&](const hmpm::Snapshot& s) {
    out = s.position;
    out.insert(out.end(), s.effective_stress.begin(), s.effective_stress.end());
    out.insert(out.end(), s.pore_pressure.begin(), s.pore_pressure.end());
  };
  const hmpm::RunResult r = hmpm::run(p, opt);
  EXPECT_EQ(r.status, hmpm::RunStatus::successful) << r.message;
  EXPECT_EQ(r.threads, threads);
  return out;
}

// The dry block: its stress pass (which also moves the particles) shares
// particles between the threads in dynamic blocks, not fixed chunks.
hmpm::Problem dry_block() {
  hmpm::Problem p = saturated_block();
  p.materials[0].hydraulic.reset();
  p.bodies[0].initial.pore_pressure = nullptr;
  p.boundaries.pop_back();  // the pore-pressure boundary
  return p;
}

// Tolerance: sums of up to 9 nodal contributions reordered per step give
// relative differences of ~1e-16 per step; over 600 steps of a stable,
// non-chaotic elastic response they stay below 1e-9 of each field's scale.
TEST(Threads, TwoThreadsAgreeWithOneAndAreDeterministic) {
  for (bool dry : {false, true})
    for (auto shape : {hmpm::ShapeFunction::linear, hmpm::ShapeFunction::gimp}) {
      hmpm::Problem p = dry ? dry_block() : saturated_block();
      p.shape_function = shape;
      const std::vector<double> one = final_state(p, 1);
      ASSERT_FALSE(one.empty());
      double scale = 0;
      for (double v : one) scale = std::max(scale, std::abs(v));
      // Three threads: two private buffers, each reduced over its own band of nodes.
      for (int threads : {2, 3}) {
        const std::vector<double> many = final_state(p, threads);
        const std::vector<double> again = final_state(p, threads);
        ASSERT_EQ(one.size(), many.size());
        double worst = 0;
        for (std::size_t i = 0; i < one.size(); ++i)
          worst = std::max(worst, std::abs(one[i] - many[i]));
        std::printf("threads (%s): %d against 1, largest difference %.2e of the largest value\n",
                    dry ? "dry" : "saturated", threads, worst / scale);
        EXPECT_LT(worst, 1e-9 * scale) << threads << " threads";
        EXPECT_EQ(many, again) << threads << " threads";
      }
    }
}

}  // namespace
