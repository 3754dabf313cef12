// schemes/table.cpp — lookups in the table of schemes (schemes/table.hpp).
#include "schemes/table.hpp"

#include "hmpm/problem.hpp"
#include "schemes/quasi_static_plan.hpp"
#include "schemes/time_scheme.hpp"

namespace hmpm {

const SchemeRow& scheme_row(Scheme s) {
  for (const SchemeRow& row : scheme_table)
    if (row.scheme == s) return row;
  return scheme_table[0];
}

const char* scheme_name(Scheme s) {
  return scheme_row(s).name;
}

const SchemeRules& scheme_rules(const Problem& problem) {
  return scheme_row(problem.time.scheme).rules();
}

}  // namespace hmpm
