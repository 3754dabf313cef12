#!/usr/bin/env bash
# One command from a fresh clone to a running service: installs the Debian
# packages, builds only what serving needs (hmpm-server and the libraries it
# links; `bash scripts/build.sh` builds the hmpm command, the test command the
# tests and benchmarks) and starts hmpm-server
# with its SQLite database under ./data/.
#
#   bash scripts/serve.sh [--host H] [--port P] [--data DIR] [-- SERVER OPTIONS...]
#
#   --host H    address to listen on (default 127.0.0.1; HMPM_HOST)
#   --port P    port (default 8080; HMPM_PORT); 0 picks a free one
#   --data DIR  where the database and result files live (default ./data)
#   after --     anything hmpm-server accepts, e.g. -- --workers 2 --token s3cret
#                or -- --retain-days 7 (docs/api.md lists them)
set -euo pipefail
cd "$(dirname "$0")/.."
host=${HMPM_HOST:-127.0.0.1}
port=${HMPM_PORT:-8080}
data=data
while [ $# -gt 0 ]; do
  case "$1" in
    --host) host=$2; shift 2 ;;
    --port) port=$2; shift 2 ;;
    --data) data=$2; shift 2 ;;
    --) shift; break ;;
    -h|--help) sed -n '2,/^set /{/^#/p}' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "serve.sh: unknown option '$1' (see bash scripts/serve.sh --help)" >&2; exit 1 ;;
  esac
done
bash scripts/install-deps.sh
bash scripts/build.sh --target hmpm-server
mkdir -p "$data"
exec build/bin/hmpm-server --host "$host" --port "$port" --db "$data/hmpm.sqlite" \
  --data-dir "$data/results" "$@"
