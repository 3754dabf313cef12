#!/usr/bin/env bash
# Runs one Python check of tests/api with the interpreter scripts/python.sh
# picks (Debian's python3 with meshio, numpy and jsonschema).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
py="$(bash "$here/../../scripts/python.sh")"
script="$1"
shift
exec "$py" "$here/$script" "$@"
