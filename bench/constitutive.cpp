// bench_constitutive — the cost of each soil model's stress update per
// plastic particle-step (docs/performance.md "Soil models per
// particle-step"): the dispatch the explicit scheme calls
// (return_to_yield_surface) on a fixed set of trial stresses, each pushed
// past yield in a random direction, in a loop as the time step does it
// (one particle after another, structure of arrays, no allocation).
//
//   bench_constitutive [--points N] [--repeats R]
//
// One line per model: ns per update (elastic and plastic trials apart)
// and the fraction of trials that yielded.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include "../solver/src/materials/material.hpp"

namespace {

using hmpm::constitutive::Voigt;

hmpm::Material soil(hmpm::Plasticity model) {
  hmpm::Material m;
  m.density = 2000;
  m.youngs_modulus = 50e6;
  m.poisson_ratio = 0.3;
  m.plasticity = std::move(model);
  return m;
}

struct Row {
  std::string name;
  hmpm::Material material;
  int state_variables = 0;
};

}  // namespace

namespace {

int run(int argc, char** argv) {
  std::size_t points = 20000;
  int repeats = 50;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--points")) points = std::strtoul(argv[i + 1], nullptr, 10);
    if (!std::strcmp(argv[i], "--repeats")) repeats = std::atoi(argv[i + 1]);
  }
  hmpm::MohrCoulomb mc{30, 5, 20e3, 0};
  hmpm::MohrCoulomb soft = mc;
  soft.softening = hmpm::MohrCoulomb::Softening{2e3, 20, 0, 30, 0};
  hmpm::ModifiedCamClay cc;
  cc.lambda = 0.1;
  cc.kappa = 0.02;
  cc.critical_state_ratio = 1.2;
  cc.initial_void_ratio = 1.0;
  const std::vector<Row> rows = {
      {"linear_elastic", soil(hmpm::LinearElastic{}), 0},
      {"mohr_coulomb", soil(mc), 0},
      {"mohr_coulomb + softening", soil(soft), 1},
      {"drucker_prager", soil(hmpm::DruckerPrager{30, 5, 20e3, 0}), 0},
      {"modified_cam_clay", soil(cc), 2},
  };
  // Trials: a mean stress of 20-200 kPa compression, a deviator of 0-150 kPa
  // in a random direction, a strain increment of 1e-4 (for Cam-Clay, whose
  // update takes sigma_n and the increment).
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), u01(0, 1);
  std::vector<Voigt> start(points), increment(points);
  for (std::size_t p = 0; p < points; ++p) {
    Voigt dev;
    for (int i = 0; i < 6; ++i) dev(i) = u(rng);
    const double tr = (dev(0) + dev(1) + dev(2)) / 3;
    dev.head<3>().array() -= tr;
    start[p] = (150e3 * u01(rng)) * dev.normalized();
    start[p].head<3>().array() -= 20e3 + 180e3 * u01(rng);
    for (int i = 0; i < 6; ++i) increment[p](i) = 1e-4 * u(rng);
  }
  std::printf("points=%zu repeats=%d\n", points, repeats);
  for (const Row& row : rows) {
    const hmpm::MaterialConstants c = hmpm::material_constants(row.material, 9.81);
    std::vector<double> slots[2] = {std::vector<double>(points, 0.0),
                                    std::vector<double>(points, 0.0)};
    if (c.model == hmpm::Model::modified_cam_clay)
      for (std::size_t p = 0; p < points; ++p) {
        slots[0][p] = 1.0;
        slots[1][p] = 150e3;
      }
    std::vector<Voigt> sig(points);
    std::size_t plastic = 0;
    double checksum = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < repeats; ++r) {
      for (std::size_t p = 0; p < points; ++p) {
        Voigt s = start[p];
        if (hmpm::elastic_trial_outside(c.model)) {
          const Voigt& de = increment[p];
          const double tr = de(0) + de(1) + de(2);
          for (int i = 0; i < 3; ++i) s(i) += c.elastic.lambda * tr + 2 * c.elastic.shear * de(i);
          for (int i = 3; i < 6; ++i) s(i) += 2 * c.elastic.shear * de(i);
        }
        // The state is not committed, so every repeat sees the same input.
        const double n =
            hmpm::return_to_yield_surface(s, increment[p], c, hmpm::InternalState{slots, p, false});
        if (r == 0 && n > 0) ++plastic;
        checksum += s(0);
      }
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("model=\"%s\" ns_per_update=%.1f plastic_fraction=%.3f checksum=%.6g\n",
                row.name.c_str(), 1e9 * s / (static_cast<double>(points) * repeats),
                static_cast<double>(plastic) / static_cast<double>(points), checksum);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_constitutive: %s\n", e.what());
    return 1;
  }
}
