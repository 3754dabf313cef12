// parse_job.cpp — placeholder while the parser is written.
#include "hmpm/api/job.hpp"

namespace hmpm::api {

ParseResult parse_job(std::string_view, const Limits&) {
  ParseResult r;
  r.errors.push_back({"", "parser not implemented yet"});
  return r;
}

}  // namespace hmpm::api
