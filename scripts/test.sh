#!/usr/bin/env bash
# One command from a fresh clone to a tested build: installs dependencies,
# builds everything, checks the C++ formatting (clang-format) and lint
# (clang-tidy), runs every C++ test (ctest), every Python test and the
# dashboard's browser tests (headless Chromium with Debian's chromium-driver
# and python3-selenium, which install-deps.sh installs; about 25 s).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
jobs=$(nproc 2>/dev/null || echo 2)
status=0
bash scripts/check_format.sh || status=1
# clang-tidy over the code changed since .ci/tidy-baseline, the last commit
# on which every file was checked clean (a full run takes 7 min of the 15-min
# budget); a baseline git does not know means a full run.
# `bash scripts/check_tidy.sh` with no argument checks everything.
tidy_base=$(cat .ci/tidy-baseline 2>/dev/null || true)
if [ -n "$tidy_base" ] && git rev-parse --verify -q "$tidy_base^{commit}" >/dev/null 2>&1; then
  bash scripts/check_tidy.sh "$tidy_base" || status=1
else
  bash scripts/check_tidy.sh || status=1
fi
(cd build && ctest --output-on-failure -j "$jobs" --timeout 600) || status=1
py=$(bash scripts/python.sh)
if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  HMPM_BUILD_DIR="$PWD/build" PYTHONPATH="$PWD/clients/python" \
    "$py" -m unittest discover -s tests/python -t . -v || status=1
fi
# Selenium is Debian's python3-selenium: the system interpreter, not a venv.
/usr/bin/python3 tests/browser/check_embed.py || status=1
HMPM_BUILD_DIR="$PWD/build" /usr/bin/python3 tests/browser/test_dashboard.py || status=1
exit $status
