#!/usr/bin/env bash
# bench/run.sh — runs the benchmark matrix and rewrites the measured part of
# docs/performance.md (between the bench:begin and bench:end markers).
#
#   bash bench/run.sh            # full matrix (about 15 minutes on 2 vCPU)
#   bash bench/run.sh --quick    # a few rows, to check the script itself
#   bash bench/run.sh --no-doc   # print the table, leave the doc alone
#
# Benchmarks, not tests: nothing here asserts a time. Run on a quiet machine;
# every row is the best of REPEAT runs (default 3) to shave off interference.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh >/dev/null  # wrk, valgrind, the build tools
# shellcheck source=bench/doc_section.sh
source bench/doc_section.sh

quick=0
write_doc=1
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    --no-doc) write_doc=0 ;;
    *) echo "usage: bench/run.sh [--quick] [--no-doc]" >&2; exit 2 ;;
  esac
done
repeat=${REPEAT:-3}
pairs=${PAIRS:-9}
build=${BUILD_DIR:-build-bench}

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DHMPM_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target bench_mpm reference_kernel -j"$(nproc)" >/dev/null
bench="$build/bin/bench_mpm"
reference="$build/bin/reference_kernel"

# Side lengths in cells giving about 10k, 100k, 400k and 1M particles at 2
# particles per cell per axis (2D: 4 per cell, 3D: 8 per cell).
nb2d=(50 158 316 500)
nb3d=(11 23 37 50)
# Particle-steps per run: enough for a few seconds of time loop.
work=40000000
if ((quick)); then
  nb2d=(50)
  nb3d=(11)
  work=4000000
fi

value() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }

# The reference kernel's throughput (best of $repeat) for a dimension and
# block size, measured once per script run: bench/reference_kernel.cpp, a
# plain USL MPM of the same dry problem (issue 21's yardstick).
declare -A reference_ps
reference_for() {
  local dim=$1 nb=$2 steps=$3 key="$1/$2"
  if [[ -z ${reference_ps[$key]:-} ]]; then
    local best=0 ps r
    for ((r = 0; r < repeat; ++r)); do
      ps=$("$reference" --dim "$dim" --nb "$nb" --steps "$steps" | value particle_steps_per_second)
      best=$(awk -v a="$ps" -v b="$best" 'BEGIN{print (a > b) ? a : b}')
    done
    reference_ps[$key]=$best
  fi
  reference_value=${reference_ps[$key]}  # a global: $(...) would lose the cache
}

# One row: best throughput over $repeat runs of bench_mpm with these flags.
row() {
  local label=$1
  shift
  local best="" line="" out
  for ((r = 0; r < repeat; ++r)); do
    out=$("$bench" "$@")
    local ps
    ps=$(value particle_steps_per_second <<<"$out")
    if [[ -z $best ]] || awk -v a="$ps" -v b="$best" 'BEGIN{exit !(a > b)}'; then
      best=$ps
      line=$out
    fi
  done
  local particles threads state rss dim nb steps ref coupled shape key of_linear
  dim=$(value dim <<<" $line")
  nb=$(value nb <<<"$line")
  steps=$(value steps <<<"$line")
  coupled=$(value coupled <<<"$line")
  shape=$(value shape <<<"$line")
  reference_for "$dim" "$nb" "$steps"
  ref=$reference_value
  particles=$(value particles <<<"$line")
  threads=$(value threads <<<"$line")
  state=$(value state_bytes_per_particle <<<"$line")
  rss=$(value peak_rss_bytes_per_particle <<<"$line")
  # The shape functions against linear of the same dimension, size and kind
  # (issue 21's targets), measured earlier in the same script.
  key="$dim/$nb/$coupled/$threads"
  if [[ $shape == linear ]]; then
    linear_ps[$key]=$best
    of_linear=1
  elif [[ -n ${linear_ps[$key]:-} ]]; then
    of_linear=$(awk -v a="$best" -v b="${linear_ps[$key]}" 'BEGIN{printf "%.2f", a / b}')
  else
    of_linear="—"
  fi
  printf '| %s | %s | %s | %.2f M | %.2f× | %s× | %.0f | %.0f |\n' "$label" "$particles" "$threads" \
    "$(awk -v v="$best" 'BEGIN{print v / 1e6}')" "$(awk -v a="$best" -v b="$ref" 'BEGIN{print a / b}')" \
    "$of_linear" "$state" "$rss"
}
declare -A linear_ps

steps_for() {  # particles-per-cell^dim * nb^dim -> steps for ~$work particle-steps
  local n=$1
  local s=$((work / n))
  ((s < 20)) && s=20
  echo "$s"
}

table() {
  echo '| case | particles | threads | particle-steps/s | ÷ reference kernel | ÷ linear | state B/particle | peak RSS B/particle |'
  echo '|---|---:|---:|---:|---:|---:|---:|---:|'
  local nb n
  for coupled in "" "--coupled"; do
    local kind=dry
    [[ -n $coupled ]] && kind=coupled
    for nb in "${nb2d[@]}"; do
      n=$((4 * nb * nb))
      # shellcheck disable=SC2086
      row "2D $kind linear" --dim 2 --nb "$nb" --steps "$(steps_for $n)" --threads 1 $coupled
    done
    for nb in "${nb3d[@]}"; do
      n=$((8 * nb * nb * nb))
      # shellcheck disable=SC2086
      row "3D $kind linear" --dim 3 --nb "$nb" --steps "$(steps_for $n)" --threads 1 $coupled
    done
  done
  # Shape functions at about 100k and 400k particles (the quick run: its one size).
  local size
  for size in 1 2; do
    local nbs=${nb2d[$size]:-} nbs3=${nb3d[$size]:-}
    [[ -z $nbs ]] && { ((size == 1)) || continue; nbs=${nb2d[0]}; nbs3=${nb3d[0]}; }
    for shape in gimp bspline; do
      for coupled in "" "--coupled"; do
        local kind=dry
        [[ -n $coupled ]] && kind=coupled
        # shellcheck disable=SC2086
        row "2D $kind $shape" --dim 2 --nb "$nbs" --steps "$(steps_for $((4 * nbs * nbs)))" --threads 1 --shape $shape $coupled
        # shellcheck disable=SC2086
        row "3D $kind $shape" --dim 3 --nb "$nbs3" --steps "$(steps_for $((8 * nbs3 * nbs3 * nbs3)))" --threads 1 --shape $shape $coupled
      done
    done
  done
}

# Two threads against one: runs alternate (1, 2, 1, 2, ...) so that both see
# the same machine state. Two speed-ups: the ratio of the best of each (the
# statistic of the single-thread table) and the median of the per-pair
# ratios over $pairs pairs (stricter: every pair ratio carries the noise of
# two runs).
pair() {
  local label=$1
  shift
  local ratios=() best1=0 best2=0 out1 out2 p1 p2 particles
  for ((r = 0; r < pairs; ++r)); do
    out1=$("$bench" "$@" --threads 1)
    out2=$("$bench" "$@" --threads 2)
    p1=$(value particle_steps_per_second <<<"$out1")
    p2=$(value particle_steps_per_second <<<"$out2")
    ratios+=("$(awk -v a="$p2" -v b="$p1" 'BEGIN{printf "%.2f", a / b}')")
    best1=$(awk -v a="$p1" -v b="$best1" 'BEGIN{print (a > b) ? a : b}')
    best2=$(awk -v a="$p2" -v b="$best2" 'BEGIN{print (a > b) ? a : b}')
  done
  particles=$(value particles <<<"$out1")
  local median
  median=$(printf '%s\n' "${ratios[@]}" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}')
  printf '| %s | %s | %.2f M | %.2f M | %.2f× | %.2f× (%s) |\n' "$label" "$particles" \
    "$(awk -v v="$best1" 'BEGIN{print v / 1e6}')" "$(awk -v v="$best2" 'BEGIN{print v / 1e6}')" \
    "$(awk -v a="$best2" -v b="$best1" 'BEGIN{print a / b}')" \
    "$median" "$(IFS=' '; echo "${ratios[*]}")"
}

threads_table() {
  echo '| case | particles | 1 thread (best) | 2 threads (best) | speed-up: best / best | speed-up: median of pairs (each pair) |'
  echo '|---|---:|---:|---:|---:|---:|'
  # 400k particles (the quick run uses its single size).
  local nb2=${nb2d[2]:-${nb2d[0]}} nb3=${nb3d[2]:-${nb3d[0]}}
  for coupled in "" "--coupled"; do
    local kind=dry
    [[ -n $coupled ]] && kind=coupled
    # shellcheck disable=SC2086
    pair "2D $kind linear" --dim 2 --nb "$nb2" --steps "$(steps_for $((4 * nb2 * nb2)))" $coupled
    # shellcheck disable=SC2086
    pair "3D $kind linear" --dim 3 --nb "$nb3" --steps "$(steps_for $((8 * nb3 * nb3 * nb3)))" $coupled
  done
}

machine() {
  local cpu
  cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
  echo "- Machine: $(nproc) vCPU, $cpu, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo) RAM"
  local march
  march=$(grep -o -- '-march=[^ ]*' "$build/solver/CMakeFiles/hmpm_solver.dir/flags.make" | head -1)
  echo "- Compiler: $(c++ --version | head -1); Release (-O3 ${march:-no -march}; HMPM_ARCH=$(sed -n 's/^HMPM_ARCH:STRING=//p' "$build/CMakeCache.txt"))"
  echo "- Commit: $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- solver bench || echo ' (with local changes)'); measured $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "- Command: \`bash bench/run.sh\` (best of $repeat runs per row; the time loop only, as in summary.json)"
}

reference_table() {
  echo '| reference kernel (bench/reference_kernel.cpp) | particles | particle-steps/s |'
  echo '|---|---:|---:|'
  local key
  for key in $(printf '%s\n' "${!reference_ps[@]}" | sort -t/ -k1,1n -k2,2n); do
    local dim=${key%/*} nb=${key#*/}
    printf '| %sD dry linear, USL | %s | %.2f M |\n' "$dim" "$(( (2 * nb) ** dim ))" \
      "$(awk -v v="${reference_ps[$key]}" 'BEGIN{print v / 1e6}')"
  done
}

result=$(
  machine
  echo
  table
  echo
  echo "Each row's throughput divided by the reference kernel's on the same dimension and block size,"
  echo "run in this script (best of $repeat):"
  echo
  reference_table
  echo
  echo "Two threads (alternating runs, $pairs pairs per row):"
  echo
  threads_table
)
echo "$result"

if ((write_doc && !quick)); then
  replace_doc_section bench "$result"
fi
