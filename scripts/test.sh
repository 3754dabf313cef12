#!/usr/bin/env bash
# One command from a fresh clone to a tested build: installs dependencies,
# builds everything, checks the C++ formatting (clang-format) and lint
# (clang-tidy), runs every C++ test (ctest), every Python test and the
# dashboard's browser tests (headless Chromium with Debian's chromium-driver
# and python3-selenium, which install-deps.sh installs; about 25 s).
set -euo pipefail
cd "$(dirname "$0")/.."
# Each stage is timed; a summary of stages, seconds and results ends the run.
summary=()
status=0
stage() {
  local name=$1 t0=$SECONDS rc=0
  shift
  echo "=== test.sh: $name" >&2
  "$@" || rc=$?
  summary+=("$(printf '%-14s %5d s  %s' "$name" $((SECONDS - t0)) "$([ $rc -eq 0 ] && echo ok || echo "FAILED ($rc)")")")
  [ $rc -eq 0 ] || status=1
}
stage install-deps bash scripts/install-deps.sh
stage build bash scripts/build.sh
if [ $status -ne 0 ]; then printf '%s\n' "${summary[@]}" >&2; exit 1; fi
jobs=$(nproc 2>/dev/null || echo 2)
stage format bash scripts/check_format.sh
# clang-tidy over the code changed since .ci/tidy-baseline, the last commit
# on which every file was checked clean (a full run takes 7 min of the 15-min
# budget); a baseline git does not know means a full run.
# `bash scripts/check_tidy.sh` with no argument checks everything.
tidy_base=$(cat .ci/tidy-baseline 2>/dev/null || true)
if [ -n "$tidy_base" ] && git rev-parse --verify -q "$tidy_base^{commit}" >/dev/null 2>&1; then
  stage tidy bash scripts/check_tidy.sh "$tidy_base"
else
  stage tidy bash scripts/check_tidy.sh
fi
# A throw-away PostgreSQL for the store contract suite and the many-server
# tests (scripts/postgres.sh: initdb in a temporary folder, a free port of
# 127.0.0.1); its URI is HMPM_TEST_POSTGRES, and it is stopped at the end.
pg_dir=$(mktemp -d /tmp/hmpm-pg.XXXXXX)
trap 'bash scripts/postgres.sh stop "$pg_dir"' EXIT
HMPM_TEST_POSTGRES=$(bash scripts/postgres.sh start "$pg_dir")
export HMPM_TEST_POSTGRES
stage ctest bash -c "cd build && ctest --output-on-failure -j $jobs --timeout 600"
py=$(bash scripts/python.sh)
stage python env HMPM_BUILD_DIR="$PWD/build" PYTHONPATH="$PWD/clients/python" \
  "$py" -m unittest discover -s tests/python -t . -v
# The hostile suite: attacks on a live server (tests/hostile/run.py prints
# faults survived, bad inputs tried, load held and anything lost).
stage hostile env HMPM_BUILD_DIR="$PWD/build" "$py" tests/hostile/run.py
# Selenium is Debian's python3-selenium: the system interpreter, not a venv.
stage browser-embed /usr/bin/python3 tests/browser/check_embed.py
stage browser env HMPM_BUILD_DIR="$PWD/build" /usr/bin/python3 tests/browser/test_dashboard.py
echo "=== test.sh: summary" >&2
printf '%s\n' "${summary[@]}" >&2
exit $status
