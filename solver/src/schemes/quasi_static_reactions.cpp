// schemes/quasi_static_reactions.cpp — the quasi-static scheme's boundary
// reactions (QuasiStaticScheme::tally_reactions), for every dimension and
// shape function (one unit: the headers are parsed once for the three
// dimensions; solver/CMakeLists.txt links it after the Simulation units).
// A unit of its own: in simulation_instance.cpp its call of
// particle_stress changed GCC's inlining of particle_stress in the Newton
// loop, and runs without reactions differed by round-off from before.
#include "phases/particle_to_grid.hpp"
#include "schemes/quasi_static_scheme.hpp"

namespace hmpm {

/// The force each boundary exerts on the soil in the converged state
/// (before commit moves the particles): minus the residual R_u (external
/// minus internal force, phases/reactions.hpp) at the node components
/// charged to it. At a prescribed component that is the force holding the
/// prescribed increment; at a tied one (summed over the tie) and at a
/// friction wall's tangential one (frictionless here) it is the Newton
/// residual, zero within the tolerance. Serial over the particles, on
/// the steps the time loop samples only.
template <int Dim, class Shape>
void QuasiStaticScheme<Dim, Shape>::tally_reactions() {
  auto& parts = sim_.particles_;
  const auto& grid = sim_.grid_;
  const std::vector<int>& owner = sim_.reaction_owner_;
  std::vector<Vec3>& reaction = sim_.reaction_;
  for (Vec3& r : reaction) r = {0.0, 0.0, 0.0};
  for (const auto& ch : sim_.charges_)  // the tractions at t + h
    reaction[static_cast<std::size_t>(ch.boundary)][static_cast<std::size_t>(ch.axis)] -=
        grid.force[ch.node][ch.axis];
  const Vec gravity = sim_.gravity_;
  StencilT s;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    sim_.template stencil_in_step<true, true>(p, s);
    Mat g;
    Voigt de, sig;
    particle_stress(p, s, g, de, sig);
    const bool sat = sim_.fluid_ && sim_.constants_[parts.material[p]].saturated;
    const double vol = parts.volume[p], m = parts.mass[p];
    const Mat vs = vol * Sim::active_stress(sig);
    double p_hat = 0.0;
    if (sat)
      for (int k = 0; k < N; ++k) p_hat += s.w[k] * p_[static_cast<std::size_t>(s.node[k])];
    for (int k = 0; k < N; ++k) {
      const auto i = static_cast<std::size_t>(s.node[k]);
      const Vec gk = s.grad(k);
      const Vec fs = vs * gk, fp = (vol * p_hat) * gk, fg = (s.w[k] * m) * gravity;
      for (int a = 0; a < Dim; ++a) {
        const int b = owner[i * Dim + static_cast<std::size_t>(a)];
        if (b >= 0)
          reaction[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)] -=
              fg[a] - fs[a] + fp[a];
      }
    }
  }
}

template void QuasiStaticScheme<1, shape::Linear>::tally_reactions();
template void QuasiStaticScheme<1, shape::Gimp>::tally_reactions();
template void QuasiStaticScheme<1, shape::BSpline>::tally_reactions();
template void QuasiStaticScheme<2, shape::Linear>::tally_reactions();
template void QuasiStaticScheme<2, shape::Gimp>::tally_reactions();
template void QuasiStaticScheme<2, shape::BSpline>::tally_reactions();
template void QuasiStaticScheme<3, shape::Linear>::tally_reactions();
template void QuasiStaticScheme<3, shape::Gimp>::tally_reactions();
template void QuasiStaticScheme<3, shape::BSpline>::tally_reactions();

}  // namespace hmpm
