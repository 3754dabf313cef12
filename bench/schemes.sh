#!/bin/bash
# bench/schemes.sh — time to solution of the three time schemes
# (docs/performance.md, "Time schemes"). For each spec: `hmpm validate
# --calibrate --threads 2` (the estimate of every scheme) then `hmpm run
# --threads 2` (summary.json: steps, solve_seconds, iterations). Prints one
# line per run: name, particles, nodes, steps, measured s, estimated s for
# its scheme, iterations (nonlinear / solves / linear / max per step), and
# the estimates of the other schemes.
#   bash bench/schemes.sh [BUILD_DIR] [PATTERN]   # PATTERN: a grep -E on the spec names
# The specs: bench/scheme_specs.py (examples/soft-clay.json, the real-water
# Terzaghi of the reference problems, examples/embankment.json refined to
# about 10k, 100k and 400k particles; "-short" runs are the first steps
# only, for the time per step and per solve).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
pattern=${2:-.}
hmpm=$build/bin/hmpm
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
lscpu | grep 'Model name' || true
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 "$root/bench/scheme_specs.py" "$root" "$scratch/specs"
cp "$root/examples/soft-clay.json" "$scratch/specs/soft-clay.json"
for spec in $(ls "$scratch"/specs/*.json | grep -E "$pattern"); do
  name=$(basename "$spec" .json)
  "$hmpm" validate --calibrate --threads 2 "$spec" > "$scratch/validate.txt" 2>&1 || true
  case "$name" in
    *-explicit*) echo "$name: explicit, estimate only: $(grep -E '^scheme ' "$scratch/validate.txt")"; continue ;;
  esac
  "$hmpm" run "$spec" --threads 2 --out "$scratch/$name" > /dev/null 2>&1 || true
  python3 - "$scratch/$name/summary.json" "$scratch/validate.txt" "$name" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
est = {}
for line in open(sys.argv[2]):
    m = re.match(r"\s*(?:scheme |with )(\w+): (\d+) steps.*expected wall time ([0-9.e+-]+) s", line)
    if m:
        est[m.group(1)] = (int(m.group(2)), float(m.group(3)))
it = s.get("iterations", {})
mine = est.get(s["scheme"], (0, float("nan")))
others = ", ".join(f"{k} {v[0]} steps {v[1]:.3g} s" for k, v in est.items() if k != s["scheme"])
print(f"{sys.argv[3]}: {s['status']}, {s['particles']} particles, {s['nodes']} nodes, "
      f"{s['steps']} steps, {s['solve_seconds']:.3f} s measured, {mine[1]:.3g} s estimated "
      f"(ratio {s['solve_seconds'] / mine[1]:.2f}); iterations nonlinear {it.get('nonlinear')} "
      f"solves {it.get('solves')} linear {it.get('linear')} max/step {it.get('max_nonlinear')}; "
      f"others: {others}")
PY
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
