// version.cpp — hmpm::api::version(), from the project version CMake passes in.
#include "hmpm/api/job.hpp"

namespace hmpm::api {

const char* version() {
  return HMPM_VERSION;
}

}  // namespace hmpm::api
