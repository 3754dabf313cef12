#!/usr/bin/env bash
# Where a 100 MB result lives when many servers share one PostgreSQL:
#   shared folder   write = copy into --data-dir + fsync, read = cat (what
#                   GET /jobs/{id}/results/{name} streams from disk)
#   large object    write = psql \lo_import (streamed through libpq in
#                   chunks, never whole in memory), read = \lo_export
# Usage: HMPM_TEST_POSTGRES=postgresql://... bench/result_storage.sh [MB]
# (scripts/postgres.sh run bench/result_storage.sh starts a throw-away one).
# Prints MB/s per direction; reads come from the page cache in both cases.
set -euo pipefail
mb=${1:-100}
uri=${HMPM_TEST_POSTGRES:?set HMPM_TEST_POSTGRES (scripts/postgres.sh run ...)}
dir=$(mktemp -d /tmp/hmpm-results-bench.XXXXXX)
trap 'rm -rf "$dir"' EXIT
head -c $((mb << 20)) /dev/urandom >"$dir/result.bin"
rate() { python3 -c "import sys; print(f'{$mb / max(float(sys.argv[1]), 1e-9):.0f} MB/s')" "$1"; }
seconds() { local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null; t1=$(date +%s.%N); echo "$t1 - $t0" | bc -l; }

mkdir -p "$dir/data/job"
w=$(seconds bash -c "cp '$dir/result.bin' '$dir/data/job/result.bin' && sync '$dir/data/job/result.bin'")
r=$(seconds cat "$dir/data/job/result.bin")
echo "shared folder:  write $(rate "$w"), read $(rate "$r")"

oid_file="$dir/oid"
w=$(seconds bash -c "psql '$uri' -At -c '\\lo_import $dir/result.bin' | awk '{print \$2}' >'$oid_file'")
oid=$(cat "$oid_file")
r=$(seconds psql "$uri" -qAt -c "\\lo_export $oid $dir/back.bin")
cmp -s "$dir/result.bin" "$dir/back.bin" || { echo "large object: read back differs" >&2; exit 1; }
psql "$uri" -qAt -c "SELECT lo_unlink($oid)" >/dev/null
echo "large object:   write $(rate "$w"), read $(rate "$r")"
