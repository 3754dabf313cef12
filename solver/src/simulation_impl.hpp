// simulation_impl.hpp — every definition of Simulation, for the explicit
// instantiations in simulation_instance.cpp (internal; include nowhere else).
#pragma once

#include "failures.hpp"
#include "output.hpp"
#include "phases/grid.hpp"
#include "phases/grid_to_particle.hpp"
#include "phases/particle_to_grid.hpp"
#include "phases/pore_pressure.hpp"
#include "phases/pressure_projection.hpp"
#include "phases/reactions.hpp"
#include "phases/stress_and_flux.hpp"
#include "schemes/explicit_scheme.hpp"
#include "schemes/semi_implicit_scheme.hpp"
#include "setup.hpp"
#include "simulation.hpp"
#include "stages.hpp"
#include "strength_reduction.hpp"
#include "time_loop.hpp"
