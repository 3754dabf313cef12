// locations.cpp — JSON pointers for the locations the solver reports.
//
// check_problem and problem_warnings name a location in the job-spec
// vocabulary as '/'-separated parts ("time/dt", "bodies/0/box",
// "materials/NAME/hydraulic"). Every part is a key or an index, which holds
// no '/', except a material's NAME, which may ("a/b"). The pointer is built
// part by part (each escaped per RFC 6901); the material is the one whose
// name is followed by a key path that a material accepts (materials.cpp).
// That choice is unique: the only nested material object is "hydraulic",
// and none of its keys is also a key of a material, so "a" + "/b/density"
// and "a/b" + "/density" cannot both be key paths.
#include <string_view>

#include "parser.hpp"

namespace hmpm::api::parse {
namespace {

// `pointer` followed by each '/'-separated part of `relative`, escaped.
std::string append_parts(std::string pointer, std::string_view relative) {
  while (!relative.empty()) {
    const std::size_t slash = relative.find('/');
    pointer = child_pointer(pointer, relative.substr(0, slash));
    if (slash == std::string_view::npos) break;
    relative.remove_prefix(slash + 1);
  }
  return pointer;
}

}  // namespace

std::string pointer_of_solver_location(const Problem& p, const std::string& where) {
  constexpr std::string_view materials_prefix = "materials/";
  const std::string_view w = where;
  if (w.starts_with(materials_prefix)) {
    const std::string_view rest = w.substr(materials_prefix.size());
    for (const Material& m : p.materials) {
      if (!rest.starts_with(m.name) || rest.size() <= m.name.size() + 1 ||
          rest[m.name.size()] != '/')
        continue;
      const std::string_view key_path = rest.substr(m.name.size() + 1);
      if (is_material_key_path(key_path))
        return append_parts(child_pointer("/materials", m.name), key_path);
    }
  }
  return append_parts("", w);
}

}  // namespace hmpm::api::parse
