// output.hpp — what a run reports of its particles: snapshots of whole
// fields and the time series of selected particles (internal).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "simulation.hpp"

namespace hmpm {

template <int Dim, class Shape>
double Simulation<Dim, Shape>::parameter_at(std::size_t p, MaterialParameter k) const {
  const std::vector<double>& own = particles_.varying.value[static_cast<std::size_t>(k)];
  return own.empty() ? parameter_of(model_.problem.materials[particles_.material[p]], k) : own[p];
}

template <int Dim, class Shape>
double Simulation<Dim, Shape>::cam_clay_value(std::size_t p, Field f) const {
  using M = constitutive::ModifiedCamClayModel;
  if (model_.constants[particles_.material[p]].model != Model::modified_cam_clay ||
      static_cast<int>(particles_.internal.size()) < M::state_variables)
    return 0.0;
  return particles_
      .internal[f == Field::void_ratio ? M::void_ratio_slot : M::preconsolidation_slot][p];
}

template <int Dim, class Shape>
double Simulation<Dim, Shape>::excess_pore_pressure(std::size_t p) const {
  if (particles_.pressure_out.empty() || !model_.constants[particles_.material[p]].saturated)
    return 0.0;
  const FieldOfPosition& steady = job_.output.consolidation.steady_pore_pressure;
  double ps = 0.0;
  if (steady) {
    Vec3 x{0.0, 0.0, 0.0};
    for (int a = 0; a < Dim; ++a) x[a] = particles_.x[p][a];
    ps = steady(x);
  }
  return particles_.pressure_out[p] - ps;
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::fill_snapshot(Snapshot& snap, const std::vector<Field>& fields) const {
  const std::size_t n = particles_.size();
  snap.dimension = Dim;
  snap.particles = static_cast<std::int64_t>(n);
  snap.fields = fields;
  auto vec3 = [&](std::vector<double>& out, const std::vector<Vec>& in) {
    out.assign(3 * n, 0.0);
    if (in.empty()) return;
    for (std::size_t p = 0; p < n; ++p)
      for (int a = 0; a < Dim; ++a) out[3 * p + a] = in[p][a];
  };
  auto voigt = [&](std::vector<double>& out, const std::vector<Voigt>& in) {
    out.resize(6 * n);
    for (std::size_t p = 0; p < n; ++p)
      for (int c = 0; c < 6; ++c) out[6 * p + c] = in[p][c];
  };
  auto scalar = [&](std::vector<double>& out, const std::vector<double>& in) {
    if (in.empty())
      out.assign(n, 0.0);
    else
      out.assign(in.begin(), in.end());
  };
  auto parameter_values = [&](std::vector<double>& out, MaterialParameter k) {
    out.resize(n);
    for (std::size_t p = 0; p < n; ++p) out[p] = parameter_at(p, k);
  };
  for (Field f : fields) {
    switch (f) {
      case Field::position:
        vec3(snap.position, particles_.x);
        break;
      case Field::displacement: {
        snap.displacement.assign(3 * n, 0.0);
        for (std::size_t p = 0; p < n; ++p)
          for (int a = 0; a < Dim; ++a)
            snap.displacement[3 * p + a] = particles_.x[p][a] - particles_.x0[p][a];
        break;
      }
      case Field::velocity:
        vec3(snap.velocity, particles_.v);
        break;
      case Field::darcy_velocity:
        vec3(snap.darcy_velocity, particles_.darcy);
        break;
      case Field::pore_pressure:
        scalar(snap.pore_pressure, particles_.pressure_out);
        break;
      case Field::porosity:
        scalar(snap.porosity, particles_.porosity);
        break;
      case Field::plastic_strain:
        scalar(snap.plastic_strain, particles_.plastic_strain);
        break;
      case Field::excess_pore_pressure:
        snap.excess_pore_pressure.resize(n);
        for (std::size_t p = 0; p < n; ++p) snap.excess_pore_pressure[p] = excess_pore_pressure(p);
        break;
      case Field::void_ratio:
      case Field::preconsolidation_pressure: {
        std::vector<double>& out =
            f == Field::void_ratio ? snap.void_ratio : snap.preconsolidation_pressure;
        out.resize(n);
        for (std::size_t p = 0; p < n; ++p) out[p] = cam_clay_value(p, f);
        break;
      }
      case Field::effective_stress:
        voigt(snap.effective_stress, particles_.stress);
        break;
      case Field::strain:
        voigt(snap.strain, particles_.strain);
        break;
      case Field::youngs_modulus:
        parameter_values(snap.youngs_modulus, MaterialParameter::youngs_modulus);
        break;
      case Field::cohesion:
        parameter_values(snap.cohesion, MaterialParameter::cohesion);
        break;
      case Field::friction_angle:
        parameter_values(snap.friction_angle, MaterialParameter::friction_angle);
        break;
      case Field::hydraulic_conductivity:
        parameter_values(snap.hydraulic_conductivity, MaterialParameter::hydraulic_conductivity);
        break;
      case Field::total_stress: {
        voigt(snap.total_stress, particles_.stress);
        if (!particles_.pressure_out.empty())
          for (std::size_t p = 0; p < n; ++p)
            for (int c = 0; c < 3; ++c) snap.total_stress[6 * p + c] -= particles_.pressure_out[p];
        break;
      }
    }
  }
  snap.volume.assign(particles_.volume.begin(), particles_.volume.end());
  snap.mass.assign(particles_.mass.begin(), particles_.mass.end());
  snap.material.assign(particles_.material.begin(), particles_.material.end());
  // Staged jobs whose stages move bodies keep each particle's job index;
  // otherwise the run's order is the job's.
  snap.id.resize(n);
  for (std::size_t p = 0; p < n; ++p)
    snap.id[p] = particles_.id.empty() ? static_cast<std::int64_t>(p) : particles_.id[p];
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::sample_series(Series& series, double t) const {
  series.time.push_back(t);
  for (std::size_t f = 0; f < series.fields.size(); ++f) {
    std::vector<double>& out = series.values[f];
    for (std::int64_t pi : series.particles) {
      // A staged job numbers particles as the job does; one out of the run
      // (a body not added yet, or removed) has no values: NaN (null).
      const std::int64_t slot = slot_.empty() ? pi : slot_[static_cast<std::size_t>(pi)];
      if (slot < 0) {
        out.insert(out.end(), static_cast<std::size_t>(field_components(series.fields[f], Dim)),
                   std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      const auto p = static_cast<std::size_t>(slot);
      switch (series.fields[f]) {
        case Field::position:
          for (int a = 0; a < Dim; ++a) out.push_back(particles_.x[p][a]);
          break;
        case Field::displacement:
          for (int a = 0; a < Dim; ++a) out.push_back(particles_.x[p][a] - particles_.x0[p][a]);
          break;
        case Field::velocity:
          for (int a = 0; a < Dim; ++a) out.push_back(particles_.v[p][a]);
          break;
        case Field::darcy_velocity:
          for (int a = 0; a < Dim; ++a)
            out.push_back(particles_.darcy.empty() ? 0.0 : particles_.darcy[p][a]);
          break;
        case Field::pore_pressure:
          out.push_back(particles_.pressure_out.empty() ? 0.0 : particles_.pressure_out[p]);
          break;
        case Field::porosity:
          out.push_back(particles_.porosity.empty() ? 0.0 : particles_.porosity[p]);
          break;
        case Field::plastic_strain:
          out.push_back(particles_.plastic_strain.empty() ? 0.0 : particles_.plastic_strain[p]);
          break;
        case Field::excess_pore_pressure:
          out.push_back(excess_pore_pressure(p));
          break;
        case Field::void_ratio:
        case Field::preconsolidation_pressure:
          out.push_back(cam_clay_value(p, series.fields[f]));
          break;
        case Field::effective_stress:
          for (int c = 0; c < 6; ++c) out.push_back(particles_.stress[p][c]);
          break;
        case Field::strain:
          for (int c = 0; c < 6; ++c) out.push_back(particles_.strain[p][c]);
          break;
        case Field::youngs_modulus:
        case Field::cohesion:
        case Field::friction_angle:
        case Field::hydraulic_conductivity:
          out.push_back(parameter_at(p, parameter_of_field(series.fields[f])));
          break;
        case Field::total_stress: {
          const double pw = particles_.pressure_out.empty() ? 0.0 : particles_.pressure_out[p];
          for (int c = 0; c < 6; ++c) out.push_back(particles_.stress[p][c] - (c < 3 ? pw : 0.0));
          break;
        }
      }
    }
  }
}

template <int Dim, class Shape>
void Simulation<Dim, Shape>::sample_consolidation(RunResult::Consolidation& c,
                                                  const std::vector<std::int64_t>& counted,
                                                  double t) const {
  double excess = 0.0, volume = 0.0;
  auto add = [&](std::size_t p) {
    const MaterialConstants& m = model_.constants[particles_.material[p]];
    if (!m.saturated || particles_.pressure_out.empty()) return;
    const double v0 = particles_.mass[p] / m.mixture_density;
    excess += excess_pore_pressure(p) * v0;
    volume += v0;
  };
  if (job_.output.consolidation.all) {
    for (std::size_t p = 0; p < particles_.size(); ++p) add(p);  // those in the run
  } else {
    for (std::int64_t pi : counted) {
      // A staged job numbers particles as the job does; one out of the run
      // (a body not added yet, or removed) does not count.
      const std::int64_t slot = slot_.empty() ? pi : slot_[static_cast<std::size_t>(pi)];
      if (slot >= 0) add(static_cast<std::size_t>(slot));
    }
  }
  c.time.push_back(t);
  c.excess.push_back(excess);
  c.volume.push_back(volume);
}

/// The degree of consolidation of every sample of `c` from its excess, and
/// the times it reaches 50 % and 90 %. An excess at the first sample (at
/// `from`) below a millionth of the largest later one, or averaging below
/// 1e-6 Pa, counts as none: nothing to consolidate (every degree NaN;
/// returns false).
inline bool finish_consolidation(RunResult::Consolidation& c) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.degree.assign(c.time.size(), nan);
  c.t50 = c.t90 = nan;
  if (c.excess.empty()) return true;
  const double e0 = c.excess.front();
  double largest = 0.0;
  for (double e : c.excess) largest = std::max(largest, std::abs(e));
  if (!std::isfinite(e0) || !(std::abs(e0) > 1e-6 * largest) ||
      !(std::abs(e0) > 1e-6 * c.volume.front()))
    return false;
  for (std::size_t k = 0; k < c.time.size(); ++k) c.degree[k] = 1.0 - c.excess[k] / e0;
  auto first_reaching = [&](double u) {
    for (std::size_t k = 1; k < c.time.size(); ++k)
      if (c.degree[k] >= u && c.degree[k - 1] < u)
        return c.time[k - 1] + (u - c.degree[k - 1]) / (c.degree[k] - c.degree[k - 1]) *
                                   (c.time[k] - c.time[k - 1]);
    return nan;
  };
  c.t50 = first_reaching(0.5);
  c.t90 = first_reaching(0.9);
  return true;
}

}  // namespace hmpm
