#!/bin/bash
# bench/estimate.sh — the wall-time estimate against the measured time for
# every example (docs/performance.md, "Wall-time estimate"). For each
# example, three rounds of: `hmpm validate --calibrate --threads 2` (the
# estimate, with a fresh calibration as hmpm-server measures it at
# start-up) then `hmpm run --threads 2` (the measured time: summary.json
# solve_seconds). Prints a Markdown table of the medians.
#   bash bench/estimate.sh [BUILD_DIR]      # about 3 minutes on 2 vCPU
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
hmpm=$build/bin/hmpm
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
echo "| example | scheme | particles | steps | estimate, s | measured, s | measured / estimate |"
echo "|---|---|---|---|---|---|---|"
for spec in "$root"/examples/*.json; do
  name=$(basename "$spec" .json)
  rows=()
  for round in 1 2 3; do
    est=$("$hmpm" validate --calibrate --threads 2 "$spec" 2>/dev/null |
          sed -n 's/^scheme .*expected wall time \([0-9.e+-]*\) s$/\1/p')
    # a run that ends in a collapse it reports (random-bearing) still counts
    "$hmpm" run "$spec" --threads 2 --out "$scratch/$name" >/dev/null 2>&1 || true
    rows+=("$est $(python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(s['solve_seconds'], s['particles'], s['steps'])" "$scratch/$name/summary.json")")
  done
  kind=$(python3 -c "
import json, sys
s = json.load(open(sys.argv[1]))
k = [s['time'].get('scheme', 'explicit')]
if s.get('stages'): k.append('staged')
if any(m['model'] != 'linear_elastic' for m in s['materials'].values()): k.append('plastic')
if s.get('strength_reduction'): k.append('strength reduction')
print(', '.join(k))" "$spec")
  printf '%s\n' "${rows[@]}" | python3 -c "
import statistics, sys
rows = [list(map(float, l.split())) for l in sys.stdin if l.strip()]
est = statistics.median(r[0] for r in rows)
meas = statistics.median(r[1] for r in rows)
print(f'| $name | $kind | {int(rows[0][2])} | {int(rows[0][3])} | {est:.3g} | {meas:.3g} | {meas / est:.2f} |')"
done
