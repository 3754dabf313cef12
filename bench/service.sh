#!/usr/bin/env bash
# bench/service.sh — what the service costs on top of the solver.
#
#   bash bench/service.sh [--no-doc]
#
# 1. Wall time of bench/service-job.json (a 2D column, about 10 s) with
#    `hmpm run --threads 1`, against the same job through hmpm-server
#    (--workers 1 --threads-per-job 1): from the 201 of POST /jobs to the
#    job's `finished` timestamp, and to the client's event stream ending. Best of
#    REPEAT runs each (default 3), alternating, so drift hits both alike.
# 2. Status reads: wrk, 32 keep-alive connections, 2 threads, 10 s, on
#    GET /jobs/{id} of a finished job.
# Rewrites the part of docs/performance.md between service:begin and
# service:end unless --no-doc.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh >/dev/null  # wrk, valgrind, the build tools
# shellcheck source=bench/doc_section.sh
source bench/doc_section.sh
write_doc=1
[[ ${1:-} == --no-doc ]] && write_doc=0
repeat=${REPEAT:-3}
build=${BUILD_DIR:-build-bench}
port=${PORT:-18080}
py=$(bash scripts/python.sh)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DHMPM_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target hmpm hmpm-server -j"$(nproc)" >/dev/null
work=$(mktemp -d)
trap 'kill "$server_pid" 2>/dev/null || true; rm -rf "$work"' EXIT
spec=bench/service-job.json
url=http://127.0.0.1:$port

"$build/bin/hmpm-server" --port "$port" --db "$work/db.sqlite" --data-dir "$work/results" \
  --workers 1 --threads-per-job 1 >"$work/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 100); do curl -sf "$url/health" >/dev/null && break; sleep 0.1; done

now() { date +%s.%N; }
solve_seconds() { "$py" -c 'import json,sys; print("%.3f" % json.load(sys.stdin)["solve_seconds"])'; }
cli_best="" svc_best="" seen_best="" job=""
for ((r = 0; r < repeat; ++r)); do
  t0=$(now)
  "$build/bin/hmpm" run "$spec" --out "$work/cli" --threads 1 >/dev/null
  t1=$(now)
  cli=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.3f", b - a}')
  cli_solve=$(solve_seconds <"$work/cli/summary.json")

  t0=$(now)
  job=$(curl -sf -X POST -H 'Content-Type: application/json' --data-binary @"$spec" "$url/jobs" |
    "$py" -c 'import json,sys; print(json.load(sys.stdin)["jobID"])')
  # The event stream ends with the final state: no polling load on the machine.
  curl -sfN "$url/jobs/$job/events" >/dev/null
  doc=$(curl -sf "$url/jobs/$job")
  status=$("$py" -c 'import json,sys; print(json.loads(sys.argv[1])["status"])' "$doc")
  t1=$(now)
  [[ $status == successful ]] || { echo "bench/service.sh: job $job failed" >&2; exit 1; }
  svc=$("$py" -c '
import json, sys
from datetime import datetime
d = json.loads(sys.argv[1])
p = lambda s: datetime.fromisoformat(s.replace("Z", "+00:00"))
print("%.3f" % (p(d["finished"]) - p(d["created"])).total_seconds())' "$doc")
  svc_solve=$(curl -sf "$url/jobs/$job/results/summary.json" | solve_seconds)
  seen=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.3f", b - a}')
  echo "run $r: hmpm run ${cli}s (solve ${cli_solve}s), service created->finished ${svc}s" \
    "(solve ${svc_solve}s), client POST->stream done ${seen}s" >&2
  # What the service adds besides the solve itself, which machine noise
  # moves for both alike: (wall - solve) of each.
  extra=$(awk -v w="$svc" -v s="$svc_solve" -v cw="$cli" -v cs="$cli_solve" 'BEGIN{printf "%.3f", (w - s) - (cw - cs)}')
  [[ -z ${extra_best:-} ]] || awk -v a="$extra" -v b="$extra_best" 'BEGIN{exit !(a < b)}' && extra_best=$extra
  [[ -z $cli_best ]] || awk -v a="$cli" -v b="$cli_best" 'BEGIN{exit !(a < b)}' && cli_best=$cli
  [[ -z $svc_best ]] || awk -v a="$svc" -v b="$svc_best" 'BEGIN{exit !(a < b)}' && svc_best=$svc
  [[ -z $seen_best ]] || awk -v a="$seen" -v b="$seen_best" 'BEGIN{exit !(a < b)}' && seen_best=$seen
done

wrk_out=$(wrk -t2 -c32 -d10s "$url/jobs/$job")
rps=$(sed -n 's/^Requests\/sec:[[:space:]]*//p' <<<"$wrk_out")
lat=$(awk '/Latency/ {print $2; exit}' <<<"$wrk_out")
non2xx=$(sed -n 's/.*Non-2xx or 3xx responses: //p' <<<"$wrk_out")

pct() { awk -v a="$1" -v b="$cli_best" 'BEGIN{printf "%+.1f %%", 100 * (a - b) / b}'; }
result=$(
  echo "- Command: \`bash bench/service.sh\` (best of $repeat; commit $(git rev-parse --short HEAD), $(date -u '+%Y-%m-%d %H:%M UTC'))"
  echo
  echo "| measurement | value |"
  echo "|---|---:|"
  echo "| \`hmpm run --threads 1\` wall time (parse, solve, write) | ${cli_best} s |"
  echo "| service, \`created\` → \`finished\` | ${svc_best} s ($(pct "$svc_best")) |"
  echo "| service, client POST → its event stream says \`done\` | ${seen_best} s ($(pct "$seen_best")) |"
  echo "| service minus \`hmpm run\`, outside the time loop: (wall − solve_seconds) of each | ${extra_best} s ($(awk -v a="$extra_best" -v b="$cli_best" 'BEGIN{printf "%+.2f %%", 100 * a / b}')) |"
  echo "| \`GET /jobs/{id}\`, wrk 32 connections, 2 threads, 10 s | ${rps} req/s (mean latency ${lat}${non2xx:+, non-2xx $non2xx}) |"
)
echo "$result"
if ((write_doc)); then
  replace_doc_section service "$result"
fi
