// schemes/rules.cpp — which scheme's rules a Problem runs under.
#include "hmpm/problem.hpp"
#include "schemes/quasi_static_plan.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

const SchemeRules& scheme_rules(const Problem& problem) {
  switch (problem.time.scheme) {
    case Scheme::semi_implicit:
      return semi_implicit_scheme_rules();
    case Scheme::quasi_static:
      return quasi_static_scheme_rules();
    case Scheme::explicit_scheme:
      break;
  }
  return explicit_scheme_rules();
}

}  // namespace hmpm
