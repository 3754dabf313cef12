// locations.cpp — JSON pointers for the locations the solver reports.
//
// check_problem and problem_warnings name a location of the job spec as its
// parts (hmpm::Location: keys and indices, e.g. {"materials", "a/b",
// "hydraulic"}); the pointer is those parts, each escaped per RFC 6901
// ("/materials/a~1b/hydraulic"). Nothing is recovered from a joined string,
// so a material name holding '/' or '~' keeps its meaning.
#include "parser.hpp"

namespace hmpm::api::parse {

std::string pointer_of_solver_location(const Location& where) {
  std::string pointer;
  for (const std::string& part : where.parts) pointer = child_pointer(pointer, part);
  return pointer;
}

}  // namespace hmpm::api::parse
