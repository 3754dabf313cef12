#!/usr/bin/env bash
# Runs every example with two builds of the `hmpm` command and compares
# series.json, reactions.json and consolidation.json byte for byte (the rooms issue's "identical results" check).
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
    # Every history both builds wrote (an example may ask for reactions
    # only, as the footing does).
    compared=0
    for file in series.json reactions.json consolidation.json; do
      [ -f "$work/old-$name-$t/$file" ] || continue
      compared=1
      a=$(sha256sum < "$work/old-$name-$t/$file" | cut -c1-16)
      b=$(sha256sum < "$work/new-$name-$t/$file" 2>/dev/null | cut -c1-16 || true)
      if [ "$a" = "$b" ]; then echo "identical  $name threads=$t $file $a"
      else echo "DIFFERENT  $name threads=$t $file $a vs ${b:-missing}"; status=1; fi
    done
    [ $compared = 1 ] || { echo "NO HISTORY $name threads=$t (neither series.json nor reactions.json)"; status=1; }
  done
done
exit $status
