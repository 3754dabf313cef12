#!/usr/bin/env bash
# A throw-away PostgreSQL for the tests: initdb in a temporary folder as an
# unprivileged user, listening on a free port of 127.0.0.1 only, one
# database `hmpm_test`. Tests run as root here and in CI, and the server
# refuses to run as root, so the cluster belongs to the Debian package's
# `postgres` user (or `nobody` when that is missing).
#   scripts/postgres.sh start DIR   prints the libpq URI (also in DIR/uri)
#   scripts/postgres.sh stop DIR    stops the cluster and removes DIR
#   scripts/postgres.sh run CMD...  starts one, runs CMD with HMPM_TEST_POSTGRES
#                                   set to its URI, stops it; exits with CMD's status
set -euo pipefail

pg_bin() {
  local dir
  for dir in /usr/lib/postgresql/*/bin; do
    [ -x "$dir/initdb" ] && { echo "$dir"; return; }
  done
  command -v initdb >/dev/null && { dirname "$(command -v initdb)"; return; }
  echo "postgres.sh: no initdb (install the Debian package postgresql)" >&2
  exit 1
}

free_port() {
  python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

# Runs "$@" as the cluster's owner when we are root, else as ourselves.
as_owner() {
  if [ "$(id -u)" -eq 0 ]; then
    local user=postgres
    id "$user" >/dev/null 2>&1 || user=nobody
    # From /: the owner may not be allowed into the caller's folder (pg_ctl
    # would say "could not change directory ... Permission denied").
    (cd / && setpriv --reuid="$user" --regid="$(id -g "$user")" --clear-groups -- "$@")
  else
    "$@"
  fi
}

start() {
  local dir=$1 bin port user
  bin=$(pg_bin)
  mkdir -p "$dir"
  if [ "$(id -u)" -eq 0 ]; then
    user=postgres
    id "$user" >/dev/null 2>&1 || user=nobody
    chown "$user" "$dir"
  fi
  user=$(as_owner id -un)
  as_owner "$bin/initdb" -D "$dir/data" -U "$user" -A trust -E UTF8 --no-locale >"$dir/initdb.log"
  port=$(free_port)
  # fsync off: a test cluster is thrown away, durability is not what we test.
  as_owner "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 30 \
    -o "-h 127.0.0.1 -p $port -k $dir -c fsync=off -c max_connections=200" start >/dev/null
  as_owner "$bin/createdb" -h 127.0.0.1 -p "$port" -U "$user" hmpm_test
  echo "postgresql://$user@127.0.0.1:$port/hmpm_test" | tee "$dir/uri"
}

stop() {
  local dir=$1
  [ -d "$dir/data" ] && as_owner "$(pg_bin)/pg_ctl" -D "$dir/data" -m fast -w stop >/dev/null || true
  rm -rf "$dir"
}

case "${1:-}" in
  start) start "$2" ;;
  stop) stop "$2" ;;
  run)
    shift
    dir=$(mktemp -d /tmp/hmpm-pg.XXXXXX)
    trap 'stop "$dir"' EXIT
    HMPM_TEST_POSTGRES=$(start "$dir")
    export HMPM_TEST_POSTGRES
    status=0
    "$@" || status=$?
    exit $status
    ;;
  *)
    echo "usage: scripts/postgres.sh start DIR | stop DIR | run CMD..." >&2
    exit 2
    ;;
esac
