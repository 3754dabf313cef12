// reference_kernel — the yardstick of bench/run.sh (issue 21): the same
// physics as bench_mpm's dry run of the performance problem
// (docs/reference-problems.md §8: an elastic block of NB^dim cells, h =
// 0.01 m, 2 particles per cell per axis, in a grid NB wide and NB + 2 high,
// E = 1 MPa, nu = 0.3, rho = 1800 kg/m3, gravity -9.81, bottom fixed,
// sides on rollers, dt = 1e-4 s), written as the tightest plain MPM we can:
// update stress last (USL), linear shape functions, small-strain linear
// elasticity without an objective rate, structure-of-arrays particles, a
// dense grid, one thread, two particle passes per step (particles to grid;
// grid update; grid to particles with the stress update). It is not hmpm
// (it shares no code with the solver) and is no use as a solver: no
// saturation, no other shape functions, no checks. Its throughput on the
// machine at hand is what hmpm's rows in docs/performance.md are divided
// by, so that the comparison holds on any machine.
//
//   reference_kernel --nb 158 --steps 200 [--dim 3]
//
// Prints one line of key=value pairs like bench_mpm's: particles, steps,
// particle_steps_per_second (time loop only) and the settlement of the
// block's top (a check that it computed the same problem: under gravity
// the block sags; hmpm's figure at the same step agrees to a few percent,
// the difference of USL against MUSL and of the objective rate).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

template <int Dim>
struct Kernel {
  static constexpr int nodes_per_particle = 1 << Dim;
  double h, inv_h, dt;
  std::array<int, 3> cells{1, 1, 1};  // per axis
  std::array<int, 3> stride{0, 0, 0};
  int up = Dim - 1;
  // Particles (structure of arrays).
  std::array<std::vector<double>, Dim> x, v;
  std::vector<double> mass, volume;
  std::array<std::vector<double>, 6> stress;  // xx yy zz xy yz zx (zz, yz, zx unused in 2D)
  // Grid (nodes (cells + 1) per axis).
  std::vector<double> node_mass;
  std::array<std::vector<double>, Dim> momentum, force;
  double lambda = 0, mu = 0, gravity = -9.81;

  Kernel(int nb, double cell, double step_length) : h(cell), inv_h(1.0 / cell), dt(step_length) {
    for (int a = 0; a < Dim; ++a) cells[a] = a == up ? nb + 2 : nb;
    int n = 1;
    for (int a = 0; a < Dim; ++a) {
      stride[a] = n;
      n *= cells[a] + 1;
    }
    node_mass.assign(n, 0.0);
    for (int a = 0; a < Dim; ++a) {
      momentum[a].assign(n, 0.0);
      force[a].assign(n, 0.0);
    }
    const double E = 1e6, nu = 0.3, rho = 1800;
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    mu = E / (2 * (1 + nu));
    // Particles at the sub-cell centres of the block [0, NB h]^dim.
    const int per_axis = 2 * nb;
    const double s = h / 2;
    long count = 1;
    for (int a = 0; a < Dim; ++a) count *= per_axis;
    for (int a = 0; a < Dim; ++a) {
      x[a].resize(count);
      v[a].assign(count, 0.0);
    }
    mass.assign(count, rho * std::pow(s, Dim));
    volume.assign(count, std::pow(s, Dim));
    for (auto& c : stress) c.assign(count, 0.0);
    for (long p = 0; p < count; ++p) {
      long rest = p;
      for (int a = 0; a < Dim; ++a) {
        x[a][p] = (static_cast<double>(rest % per_axis) + 0.5) * s;
        rest /= per_axis;
      }
    }
  }

  long particles() const { return static_cast<long>(mass.size()); }

  // The base node and the weights and gradients of a particle's 2^dim nodes.
  void stencil(long p, int& base, std::array<double, nodes_per_particle>& w,
               std::array<std::array<double, Dim>, nodes_per_particle>& g) const {
    std::array<double, Dim> f{}, lo{};
    base = 0;
    for (int a = 0; a < Dim; ++a) {
      const double xi = x[a][p] * inv_h;
      const int i = static_cast<int>(xi);
      f[a] = xi - i;
      lo[a] = 1 - f[a];
      base += i * stride[a];
    }
    for (int k = 0; k < nodes_per_particle; ++k) {
      // N = prod_a N_a; dN/dx_b = dN_b/dx_b prod_{a != b} N_a.
      double wk = 1;
      std::array<double, Dim> gk{};
      gk.fill(1.0);
      for (int a = 0; a < Dim; ++a) {
        const bool hi = (k >> a) & 1;
        const double wa = hi ? f[a] : lo[a];
        const double da = hi ? inv_h : -inv_h;
        wk *= wa;
        for (int b = 0; b < Dim; ++b) gk[b] *= b == a ? da : wa;
      }
      w[k] = wk;
      g[k] = gk;
    }
  }

  int offset(int k) const {
    int o = 0;
    for (int a = 0; a < Dim; ++a)
      if ((k >> a) & 1) o += stride[a];
    return o;
  }

  void step() {
    std::fill(node_mass.begin(), node_mass.end(), 0.0);
    for (int a = 0; a < Dim; ++a) {
      std::fill(momentum[a].begin(), momentum[a].end(), 0.0);
      std::fill(force[a].begin(), force[a].end(), 0.0);
    }
    std::array<int, nodes_per_particle> off{};
    for (int k = 0; k < nodes_per_particle; ++k) off[k] = offset(k);
    std::array<double, nodes_per_particle> w{};
    std::array<std::array<double, Dim>, nodes_per_particle> g{};
    // Particles to grid: mass, momentum, internal and gravity forces.
    const long n = particles();
    for (long p = 0; p < n; ++p) {
      int base = 0;
      stencil(p, base, w, g);
      const double m = mass[p], vol = volume[p];
      std::array<std::array<double, Dim>, Dim> s{};
      s[0][0] = stress[0][p];
      s[1][1] = stress[1][p];
      s[0][1] = s[1][0] = stress[3][p];
      if constexpr (Dim == 3) {
        s[2][2] = stress[2][p];
        s[1][2] = s[2][1] = stress[4][p];
        s[0][2] = s[2][0] = stress[5][p];
      }
      for (int k = 0; k < nodes_per_particle; ++k) {
        const int i = base + off[k];
        node_mass[i] += w[k] * m;
        for (int a = 0; a < Dim; ++a) {
          momentum[a][i] += w[k] * m * v[a][p];
          double fa = 0;
          for (int b = 0; b < Dim; ++b) fa -= s[a][b] * g[k][b];
          force[a][i] += vol * fa + (a == up ? w[k] * m * gravity : 0.0);
        }
      }
    }
    // Grid: momentum update, then the walls: the block's bottom (y = 0)
    // fixed, the sides x = 0 and x = NB h (and z in 3D) on rollers.
    const int count = static_cast<int>(node_mass.size());
    for (int i = 0; i < count; ++i) {
      if (node_mass[i] <= 0) continue;
      int rest = i;
      std::array<int, Dim> c{};
      for (int a = 0; a < Dim; ++a) {
        c[a] = rest % (cells[a] + 1);
        rest /= cells[a] + 1;
        momentum[a][i] += dt * force[a][i];
      }
      if (c[up] == 0)
        for (int a = 0; a < Dim; ++a) momentum[a][i] = force[a][i] = 0;
      for (int a = 0; a < Dim; ++a)
        if (a != up && (c[a] == 0 || c[a] == cells[a])) momentum[a][i] = force[a][i] = 0;
      // From here on the grid holds velocity and acceleration (one
      // division per node, none per particle-node).
      const double inv_m = 1.0 / node_mass[i];
      for (int a = 0; a < Dim; ++a) {
        momentum[a][i] *= inv_m;
        force[a][i] *= inv_m;
      }
    }
    // Grid to particles: velocity (FLIP with the grid's acceleration),
    // position (the grid's velocity), strain increment, stress (USL).
    for (long p = 0; p < n; ++p) {
      int base = 0;
      stencil(p, base, w, g);
      std::array<std::array<double, Dim>, Dim> grad{};
      std::array<double, Dim> acc{}, vel{};
      for (int k = 0; k < nodes_per_particle; ++k) {
        const int i = base + off[k];
        for (int a = 0; a < Dim; ++a) {
          const double va = momentum[a][i];  // the node's velocity now
          acc[a] += w[k] * force[a][i];      // and its acceleration
          vel[a] += w[k] * va;
          for (int b = 0; b < Dim; ++b) grad[a][b] += va * g[k][b];
        }
      }
      double trace = 0;
      for (int a = 0; a < Dim; ++a) {
        v[a][p] += dt * acc[a];
        x[a][p] += dt * vel[a];
        trace += grad[a][a];
      }
      const double de_v = dt * trace;
      volume[p] *= 1 + de_v;
      for (int a = 0; a < Dim; ++a) stress[a][p] += lambda * de_v + 2 * mu * dt * grad[a][a];
      stress[3][p] += mu * dt * (grad[0][1] + grad[1][0]);
      if constexpr (Dim == 3) {
        stress[4][p] += mu * dt * (grad[1][2] + grad[2][1]);
        stress[5][p] += mu * dt * (grad[0][2] + grad[2][0]);
      }  // (2D: sigma_zz of plane strain never enters a force; not kept)
    }
  }

  // Lowest top: the settlement of the block's top surface, m.
  double top_settlement(int nb) const {
    double lowest = 1e9;
    const long n = particles();
    const double initial = nb * h - h / 4;  // the top particles' initial height
    for (long p = 0; p < n; ++p)
      if (x[up][p] > initial - h / 2) lowest = std::min(lowest, x[up][p]);
    return initial - lowest;
  }
};

template <int Dim>
int run(int nb, int steps) {
  Kernel<Dim> k(nb, 0.01, 1e-4);
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s) k.step();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "dim=%d nb=%d particles=%ld steps=%d particle_steps_per_second=%.4g "
      "top_settlement=%.6g\n",
      Dim, nb, k.particles(), steps,
      static_cast<double>(k.particles()) * steps / std::max(seconds, 1e-9), k.top_settlement(nb));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int dim = 2, nb = 50, steps = 100;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--dim" && i + 1 < argc)
      dim = std::atoi(argv[++i]);
    else if (a == "--nb" && i + 1 < argc)
      nb = std::atoi(argv[++i]);
    else if (a == "--steps" && i + 1 < argc)
      steps = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: reference_kernel [--dim 2|3] [--nb N] [--steps S]\n");
      return 2;
    }
  }
  if (nb < 1 || steps < 1 || (dim != 2 && dim != 3)) {
    std::fprintf(stderr, "reference_kernel: --dim 2|3, --nb >= 1, --steps >= 1\n");
    return 2;
  }
  return dim == 2 ? run<2>(nb, steps) : run<3>(nb, steps);
}
