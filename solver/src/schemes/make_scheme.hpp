// schemes/make_scheme.hpp — the constructors of the rows of
// schemes/table.hpp (internal; for the Simulation's instantiation).
#pragma once

#include <memory>

#include "schemes/explicit_scheme.hpp"
#include "schemes/quasi_static_scheme.hpp"
#include "schemes/semi_implicit_scheme.hpp"
#include "schemes/table.hpp"

namespace hmpm {

template <int Dim, class Shape>
std::unique_ptr<TimeScheme> make_scheme(StepContext<Dim, Shape> context, Scheme s) {
  switch (s) {
    case Scheme::explicit_scheme:
      break;
    case Scheme::semi_implicit:
      return std::make_unique<SemiImplicitScheme<Dim, Shape>>(context);
    case Scheme::quasi_static:
      return std::make_unique<QuasiStaticScheme<Dim, Shape>>(context);
  }
  return std::make_unique<ExplicitScheme<Dim, Shape>>(context);
}

}  // namespace hmpm
