#!/usr/bin/env bash
# One command from a fresh clone to a running service:
# installs dependencies, builds, and starts hmpm-server on
# http://127.0.0.1:8080 with its SQLite database under ./data/.
# Options after `--` go to hmpm-server (e.g. -- --workers 2 --token s3cret).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p data
host=${HMPM_HOST:-127.0.0.1}
port=${HMPM_PORT:-8080}
[ "${1:-}" = "--" ] && shift
exec build/bin/hmpm-server --host "$host" --port "$port" --db data/hmpm.sqlite --data-dir data/results "$@"
