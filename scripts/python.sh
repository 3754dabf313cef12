#!/usr/bin/env bash
# Prints the path of a Python interpreter that has the Debian-packaged
# modules our scripts and tests import (meshio, matplotlib, numpy).
# Debian installs them for /usr/bin/python3; the first python3 on PATH may
# be another interpreter without them.
for py in /usr/bin/python3 "$(command -v python3 || true)"; do
  [ -n "$py" ] && [ -x "$py" ] || continue
  if "$py" -c 'import meshio, matplotlib, numpy' >/dev/null 2>&1; then
    echo "$py"; exit 0
  fi
done
echo "scripts/python.sh: no python3 with meshio, matplotlib and numpy; run scripts/install-deps.sh" >&2
exit 1
