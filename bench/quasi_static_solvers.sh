#!/bin/bash
# bench/quasi_static_solvers.sh — the quasi-static u-p linear solves of two
# builds, alternating (docs/performance.md, "Quasi-static linear solvers,
# issue 42"): the embankment refined to about 10k / 100k / 400k particles
# (bench/scheme_specs.py), its first 8 steps (-short) or the whole 14 years,
# one thread. Prints per run: wall and user seconds, peak RSS, steps,
# solve_seconds and the Newton iterations (summary.json), s per iteration.
#   bash bench/quasi_static_solvers.sh OLD_BIN_DIR NEW_BIN_DIR [PATTERN] [ROUNDS]
# PATTERN: a grep -E on the spec names (default: -direct-short).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
old=$1; new=$2; pattern=${3:--direct-short}; rounds=${4:-1}
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
lscpu | grep 'Model name' || true
python3 "$root/bench/scheme_specs.py" "$root" "$scratch/specs"
for spec in $(ls "$scratch"/specs/embankment-*quasi_static*.json | grep -E "$pattern"); do
  name=$(basename "$spec" .json)
  for round in $(seq "$rounds"); do
    for which in old new; do
      bin=$old; [ "$which" = new ] && bin=$new
      out="$scratch/$name-$which"
      rm -rf "$out"
      /usr/bin/time -f "%e %U %M" "$bin/hmpm" run "$spec" --threads 1 --out "$out" \
        > /dev/null 2> "$scratch/time.txt" || true
      python3 - "$out/summary.json" "$scratch/time.txt" "$name" "$which" "$round" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
wall, user, rss = open(sys.argv[2]).read().split()[-3:]
it = s.get("iterations", {})
n = it.get("nonlinear") or 0
per = s["solve_seconds"] / n if n else float("nan")
print(f"{sys.argv[3]} {sys.argv[4]} round {sys.argv[5]}: {s['status']}, {s['particles']} particles, "
      f"{s['steps']} steps, wall {float(wall):.1f} s, user {float(user):.1f} s, "
      f"peak RSS {int(rss) / 1024:.0f} MiB, time loop {s['solve_seconds']:.1f} s, "
      f"Newton {n} (solves {it.get('solves')}), {per:.3f} s per iteration; "
      f"load {open('/proc/loadavg').read().split()[0]}")
PY
    done
  done
done
