#!/usr/bin/env bash
# Configures and builds hmpm (Release) into build/.
#   bash scripts/build.sh                      everything (libraries, tools, tests, benchmarks)
#   bash scripts/build.sh --target T [T...]    only those targets (and what they need)
# Other arguments before --target go to cmake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
configure=()
targets=()
while [ $# -gt 0 ]; do
  if [ "$1" = "--target" ]; then shift; targets=("$@"); break; fi
  configure+=("$1"); shift
done
# Ninja when it is there (it keeps both cores busy across libraries); a build
# directory configured before keeps its generator.
generator=()
if [ ! -f build/CMakeCache.txt ] && command -v ninja >/dev/null; then generator=(-G Ninja); fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release "${configure[@]}" >/dev/null
if [ ${#targets[@]} -gt 0 ]; then
  cmake --build build -j "$jobs" --target "${targets[@]}"
else
  cmake --build build -j "$jobs"
fi
