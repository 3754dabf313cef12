// bench_mpm — throughput of the solver on the performance problem of
// docs/reference-problems.md §8: a square elastic block of NB x NB
// cells (h = 0.01 m, 2x2 particles per cell) in a grid NB wide and NB + 2
// high, E = 1 MPa, nu = 0.3, rho = 1800, gravity -9.81, bottom fixed, sides
// on rollers, dt = 1e-4 s. `--coupled` makes it saturated (u-p), `--dim 3`
// a cube NB^3. Prints one line of key=value pairs: particles, steps,
// particle_steps_per_second (time loop only), peak RSS bytes per particle.
//
//   bench_mpm --nb 158 --steps 200 [--dim 3] [--coupled] [--threads 2] [--shape gimp]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "hmpm/run.hpp"

namespace {

long peak_rss_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6) * 1024L;
  return 0;
}

hmpm::FieldOfTime zero() {
  return [](double) { return 0.0; };
}

}  // namespace

int main(int argc, char** argv) {
  int dim = 2, nb = 50, steps = 100, threads = 1, ppc = 2;
  bool coupled = false;
  hmpm::ShapeFunction shape = hmpm::ShapeFunction::linear;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--dim")
      dim = std::atoi(next());
    else if (a == "--nb")
      nb = std::atoi(next());
    else if (a == "--steps")
      steps = std::atoi(next());
    else if (a == "--threads")
      threads = std::atoi(next());
    else if (a == "--ppc")
      ppc = std::atoi(next());
    else if (a == "--coupled")
      coupled = true;
    else if (a == "--shape") {
      const std::string s = next();
      shape = s == "gimp"
                  ? hmpm::ShapeFunction::gimp
                  : (s == "bspline" ? hmpm::ShapeFunction::bspline : hmpm::ShapeFunction::linear);
    } else {
      std::fprintf(stderr,
                   "usage: bench_mpm [--dim 2|3] [--nb N] [--steps S] [--threads T] [--ppc P] "
                   "[--coupled] [--shape linear|gimp|bspline]\n");
      return 2;
    }
  }
  const double h = 0.01, side = nb * h;
  hmpm::Problem p;
  p.dimension = dim;
  p.shape_function = shape;
  const int up = dim - 1;  // vertical axis
  for (int a = 0; a < dim; ++a) {
    p.grid.max[a] = a == up ? side + 2 * h : side;
    p.grid.cells[a] = a == up ? nb + 2 : nb;
  }
  hmpm::Material m;
  m.name = "block";
  m.density = 1800;
  m.youngs_modulus = 1e6;
  m.poisson_ratio = 0.3;
  if (coupled)
    m.hydraulic = hmpm::Hydraulic{0.3, 1e-6, 2e6, 1000.0, std::numeric_limits<double>::infinity()};
  p.materials.push_back(m);
  hmpm::Body b;
  for (int a = 0; a < dim; ++a) b.box.max[a] = side;
  b.particles_per_cell = ppc;
  p.bodies.push_back(b);
  p.gravity[up] = -9.81;
  for (int a = 0; a < dim; ++a) {
    hmpm::Boundary walls;  // rollers on the sides, fixed bottom
    walls.has_velocity = true;
    walls.nodes.box.min = {0, 0, 0};
    walls.nodes.box.max = p.grid.max;
    if (a == up) {
      walls.nodes.box.max[up] = 0;
      for (int c = 0; c < dim; ++c) walls.velocity[c] = zero();
      p.boundaries.push_back(walls);
    } else {
      walls.velocity[a] = zero();
      hmpm::Boundary lo = walls, hi = walls;
      lo.nodes.box.max[a] = 0;
      hi.nodes.box.min[a] = side;
      p.boundaries.push_back(lo);
      p.boundaries.push_back(hi);
    }
  }
  p.time.dt = 1e-4;
  if (coupled) p.time.dt = std::min(1e-4, 0.5 * hmpm::stable_step(p).limit);
  p.time.end = steps * *p.time.dt;
  hmpm::RunOptions opt;
  opt.threads = threads;
  const hmpm::RunResult r = hmpm::run(p, opt);
  if (r.status != hmpm::RunStatus::successful) {
    std::fprintf(stderr, "bench_mpm: run failed: %s\n", r.message.c_str());
    return 1;
  }
  const long rss = peak_rss_bytes();
  std::printf(
      "dim=%d nb=%d coupled=%d shape=%s threads=%d particles=%lld nodes=%lld steps=%lld "
      "particle_steps_per_second=%.4g state_bytes_per_particle=%.1f "
      "peak_rss_bytes_per_particle=%.1f\n",
      dim, nb, coupled ? 1 : 0,
      shape == hmpm::ShapeFunction::linear
          ? "linear"
          : (shape == hmpm::ShapeFunction::gimp ? "gimp" : "bspline"),
      r.threads, static_cast<long long>(r.particles), static_cast<long long>(r.nodes),
      static_cast<long long>(r.steps), r.particle_steps_per_second,
      static_cast<double>(r.state_bytes) / static_cast<double>(r.particles),
      static_cast<double>(rss) / static_cast<double>(r.particles));
  return 0;
}
