#!/usr/bin/env bash
# Installs the Debian packages every hmpm module, test and script needs.
# Idempotent: runs `apt-get update` and `apt-get install` only when a package
# is missing. Needs root (or sudo) only in that case.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git curl   # ninja: parallel builds (scripts/build.sh)
  libeigen3-dev            # solver: linear algebra (header only)
  libsuitesparse-dev       # solver: CHOLMOD and UMFPACK, the quasi-static u-p solves (linear/)
  libmetis-dev             # solver: METIS nested dissection for MUMPS (linear/up_system.cpp)
  libmumps-seq-dev         # solver: MUMPS LDL^T of large quasi-static u-p systems (optional in CMake)
  libopenblas-serial-dev   # solver: an optimised single-threaded BLAS for MUMPS's fronts
  nlohmann-json3-dev       # api: JSON parsing
  libmuparser-dev          # api: expressions in job specs
  libsqlite3-dev           # server: job store
  libpq-dev                # server: the PostgreSQL job store (libpq)
  postgresql               # tests: a throw-away PostgreSQL (scripts/postgres.sh)
  libcpp-httplib-dev       # server: HTTP (0.11.4, compiled library)
  libssl-dev zlib1g-dev libbrotli-dev  # what libcpp-httplib links against
  libgtest-dev libgmock-dev            # tests
  libbenchmark-dev wrk                 # bench/ (wrk: bench/service.sh status reads)
  valgrind                             # docs/performance.md instruction counts
  clang-format clang-tidy              # scripts/check_format.sh, scripts/check_tidy.sh (run by test.sh)
  python3                              # clients and result checks
  python3-meshio python3-matplotlib python3-jsonschema python3-numpy
  python3-vtk9                         # tests/api/test_writers.cpp: snapshots read back by VTK itself
  python3-owslib                       # tests/python/test_ogc.py: OGC API – Processes client
  chromium chromium-driver python3-selenium  # tests/browser: the dashboard in headless Chromium
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
