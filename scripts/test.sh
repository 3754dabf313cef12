#!/usr/bin/env bash
# One command from a fresh clone to a tested build: installs dependencies,
# builds everything, checks the C++ formatting (clang-format) and lint
# (clang-tidy), runs every C++ test (ctest), every Python test and the
# dashboard's browser tests (headless Chromium with Debian's chromium-driver
# and python3-selenium, which install-deps.sh installs; about 25 s).
# The C++ and Python tests run against a throw-away PostgreSQL that
# scripts/postgres.sh starts (initdb in a temporary folder, a free port of
# 127.0.0.1) and stops at the end; its URI is HMPM_TEST_POSTGRES.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
jobs=$(nproc 2>/dev/null || echo 2)
status=0
bash scripts/check_format.sh || status=1
bash scripts/check_tidy.sh || status=1
pg_dir=$(mktemp -d /tmp/hmpm-pg.XXXXXX)
trap 'bash scripts/postgres.sh stop "$pg_dir"' EXIT
HMPM_TEST_POSTGRES=$(bash scripts/postgres.sh start "$pg_dir")
export HMPM_TEST_POSTGRES
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
