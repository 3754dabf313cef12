#!/usr/bin/env bash
# Runs clang-tidy (checks in .clang-tidy) over the project's .cpp files, using
# the compile commands of a configured build directory. Exit 0 without
# findings; 1 with findings (printed as clang-tidy prints them, then a count
# per check); 2 on a usage or set-up error.
#
#   bash scripts/check_tidy.sh                 # every .cpp file of the project
#   bash scripts/check_tidy.sh origin/main     # only code changed since that base
#   HMPM_TIDY_BASE=origin/main bash scripts/check_tidy.sh    # the same
#
# With a base, the files changed relative to it (committed or not) are
# checked: changed .cpp files, and for each changed header one .cpp file that
# includes it (its own .cpp when there is one); only findings located in a
# changed file are reported. A header's findings are the same in every file
# that includes it, so one suffices: checking every includer of a core header
# (problem.hpp reaches nearly all files) took CI's tidy stage to 6 minutes.
# Environment: BUILD_DIR (default build; configured with cmake if it has no
# compile_commands.json), JOBS (default nproc), CLANG_TIDY (default
# clang-tidy), TIDY_OUT (also write every finding to this file), TIDY_LIST
# (non-empty: list the files checked on stderr).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
base=${1:-${HMPM_TIDY_BASE:-}}
build=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}
clang_tidy=${CLANG_TIDY:-clang-tidy}
if ! command -v "$clang_tidy" >/dev/null; then
  echo "check_tidy: $clang_tidy not found (Debian: apt-get install clang-tidy)" >&2
  exit 2
fi
if [ ! -f "$build/compile_commands.json" ]; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The build's compile commands without its precompiled headers (CMake's
# `-include .../cmake_pch.hxx`): clang cannot read GCC's .gch files, and the
# headers they hold are included by the sources themselves.
# A unity batch (CMake's Unity/unity_N_cxx.cxx, which #includes the
# target's sources: the api and the server build so) becomes one entry per
# source it includes, with the batch's command.
python3 - "$build/compile_commands.json" "$out/compile_commands.json" <<'PY'
import json, re, sys
entries = []
for e in json.load(open(sys.argv[1])):
    e["command"] = re.sub(r"\s-Winvalid-pch|\s-include\s+\S*cmake_pch\.hxx", "", e["command"])
    if re.search(r"/Unity/unity_\d+_cxx\.cxx$", e["file"]):
        for source in re.findall(r'^#include "([^"]+)"', open(e["file"]).read(), re.M):
            entries.append(dict(e, file=source,
                                command=e["command"].replace(e["file"], source)))
    else:
        entries.append(e)
json.dump(entries, open(sys.argv[2], "w"))
PY
# Tracked .cpp files that have a compile command (fuzz/ only when configured
# with HMPM_FUZZ=ON).
mapfile -t compiled < <(python3 - "$out/compile_commands.json" "$root" <<'PY'
import json, os, sys
root = sys.argv[2]
for entry in json.load(open(sys.argv[1])):
    path = os.path.normpath(os.path.join(entry["directory"], entry["file"]))
    if path.startswith(root + "/"):
        print(os.path.relpath(path, root))
PY
)
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t tracked < <(git ls-files -- solver api server tests bench fuzz | grep -E '\.cpp$')
else
  mapfile -t tracked < <(find solver api server tests bench fuzz -name '*.cpp' | sort)
fi
mapfile -t all < <(comm -12 <(printf '%s\n' "${compiled[@]}" | sort -u) \
                            <(printf '%s\n' "${tracked[@]}" | sort -u))
changed=()
if [ -n "$base" ]; then
  if ! git rev-parse --verify -q "$base^{commit}" >/dev/null; then
    echo "check_tidy: unknown base '$base'" >&2
    exit 2
  fi
  mapfile -t changed < <(git diff --name-only --diff-filter=ACMR "$base" -- \
                           solver api server tests bench fuzz | grep -E '\.(cpp|hpp|h)$' || true)
  if [ ${#changed[@]} -eq 0 ]; then
    echo "check_tidy: no C++ file changed since $base"
    exit 0
  fi
  # The changed .cpp files, and for each changed header the .cpp files that
  # include it directly or, when none does, the first one that reaches it
  # through other headers: one translation unit shows a header's findings.
  mapfile -t files < <(python3 - "${changed[@]}" -- "${all[@]}" <<'PY'
import os, re, subprocess, sys
args = sys.argv[1:]
changed, cpps = args[:args.index("--")], args[args.index("--") + 1:]
headers = [f for f in subprocess.run(["git", "ls-files", "solver", "api", "server", "tests",
                                      "bench", "fuzz"], capture_output=True, text=True).stdout.split()
           if f.endswith((".hpp", ".h"))]
by_name = {}
for h in headers:
    by_name.setdefault(os.path.basename(h), []).append(h)
include = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]', re.M)
def direct(f):
    try:
        text = open(f, errors="replace").read()
    except OSError:
        return set()
    return {h for name in include.findall(text) for h in by_name.get(os.path.basename(name), [])}
graph = {}
def reach(f):
    seen, todo = set(), [f]
    while todo:
        g = todo.pop()
        for h in graph.setdefault(g, direct(g)):
            if h not in seen:
                seen.add(h)
                todo.append(h)
    return seen
out = []
for c in changed:
    if c.endswith(".cpp"):
        if c in cpps:
            out.append(c)
        continue
    # One translation unit shows a header's findings: its own .cpp when that
    # includes it, else the first that includes it, else the first that
    # reaches it through other headers.
    stem = os.path.splitext(os.path.basename(c))[0]
    users = [f for f in cpps if c in graph.setdefault(f, direct(f))]
    own = [f for f in users if os.path.splitext(os.path.basename(f))[0] == stem]
    if not users:
        users = [f for f in cpps if c in reach(f)]
    out.extend((own or users)[:1])
if out:
    print("\n".join(dict.fromkeys(out)))
PY
)
  if [ ${#files[@]} -eq 0 ]; then
    echo "check_tidy: no compiled file reaches the C++ changed since $base"
    exit 0
  fi
else
  files=("${all[@]}")
fi
echo "check_tidy: ${#files[@]} files, $jobs jobs${base:+, changed since $base}" >&2
[ -n "${TIDY_LIST:-}" ] && printf '  %s\n' "${files[@]}" >&2
export clang_tidy out
printf '%s\n' "${files[@]}" | xargs -P "$jobs" -I{} sh -c \
  '"$clang_tidy" -p "$out" --quiet --extra-arg=-Wno-unknown-warning-option "$1" \
     > "$out/$(echo "$1" | tr / _).log" 2>&1 || true' _ {}
# A unit clang-tidy could not process is a failure, not a clean file.
if grep -l -E '^Error while processing|error: .*\[clang-diagnostic-error\]' "$out"/*.log >/dev/null 2>&1; then
  grep -h -E '^Error while processing|\[clang-diagnostic-error\]' "$out"/*.log | sort -u | head -20 >&2
  echo "check_tidy: clang-tidy could not process some files (above)" >&2
  exit 1
fi
# One line per finding (file:line:col: warning: text [check]), relative paths,
# each finding once even when several files include its header.
{ cat "$out"/*.log | grep -E '^/.*:[0-9]+:[0-9]+: (warning|error): ' || true; } |
  sed "s|^$root/||" | sort -u > "$out/findings"
if [ -n "$base" ]; then
  grep -F -f <(printf '%s:\n' "${changed[@]}") "$out/findings" > "$out/kept" || true
  mv "$out/kept" "$out/findings"
fi
[ -n "${TIDY_OUT:-}" ] && cp "$out/findings" "$TIDY_OUT"
n=$(wc -l < "$out/findings")
if [ "$n" -eq 0 ]; then
  echo "check_tidy: no findings"
  exit 0
fi
cat "$out/findings"
echo "check_tidy: $n findings by check:" >&2
sed -E 's/.*\[([^]]+)\]$/\1/' "$out/findings" | sort | uniq -c | sort -rn >&2
exit 1
