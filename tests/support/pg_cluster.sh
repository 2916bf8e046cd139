#!/bin/bash
# pg_cluster.sh start|stop DIR: a throwaway PostgreSQL for the tests, on loopback.
#   start: initdb a cluster in a fresh temporary directory, start it on a free port (its unix
#          socket in that directory too) and write its base URL, postgresql://salient@127.0.0.1:PORT,
#          to DIR/url; tests add /DBNAME. Exits 77 with the reason in DIR/skip if the postgresql
#          package is missing.
#   stop:  stop the cluster DIR names and remove it.
# SALIENT_PG_BIN: the server's bin directory (default: the newest /usr/lib/postgresql/*/bin).
# SALIENT_PG_FSYNC: on or off (default off).
# PostgreSQL refuses to run as root (CI's user), so as root the cluster is run by `nobody`.
set -euo pipefail
command=${1:?start or stop}
dir=${2:?a directory}
mkdir -p "$dir"

as_owner=()
if [[ $(id -u) == 0 ]]; then
  as_owner=(setpriv --reuid=nobody --regid=nogroup --clear-groups --)
fi

stop() {
  [[ -f "$dir/cluster" ]] || return 0
  local cluster bin
  cluster=$(cat "$dir/cluster")
  bin=$(cat "$dir/bin")
  "${as_owner[@]}" "$bin/pg_ctl" -D "$cluster/data" -m immediate -w stop >/dev/null 2>&1 || true
  rm -rf "$cluster"
  rm -f "$dir/cluster" "$dir/url"
}

case "$command" in
  start)
    stop  # one left by an interrupted run
    rm -f "$dir/skip" "$dir/url"
    bin=${SALIENT_PG_BIN:-$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)}
    if [[ -z "$bin" || ! -x "$bin/initdb" || ! -x "$bin/pg_ctl" ]]; then
      echo "the postgresql package is missing (no /usr/lib/postgresql/*/bin/initdb): apt-get install postgresql" |
        tee "$dir/skip"
      exit 77
    fi
    cluster=$(mktemp -d /tmp/salient-pg.XXXXXX)
    chmod 755 "$cluster"
    [[ ${#as_owner[@]} == 0 ]] || chown nobody:nogroup "$cluster"
    echo "$cluster" >"$dir/cluster"
    echo "$bin" >"$dir/bin"
    "${as_owner[@]}" "$bin/initdb" -D "$cluster/data" -U salient --auth=trust -E UTF8 --no-locale \
      >"$cluster/initdb.log" 2>&1 || { cat "$cluster/initdb.log"; exit 1; }
    # fsync off: a test cluster that dies is thrown away anyway, and the tests run faster. The
    # benchmarks set SALIENT_PG_FSYNC=on: a farm's database syncs its commits.
    for attempt in 1 2 3; do
      port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
      if "${as_owner[@]}" "$bin/pg_ctl" -D "$cluster/data" -l "$cluster/server.log" -w -t 60 \
        -o "-p $port -k $cluster -c listen_addresses=127.0.0.1 -c fsync=${SALIENT_PG_FSYNC:-off} -c max_connections=200" \
        start >/dev/null; then
        echo "postgresql://salient@127.0.0.1:$port" >"$dir/url"
        echo "PostgreSQL $("$bin/postgres" --version | awk '{print $3}') on 127.0.0.1:$port ($cluster)"
        exit 0
      fi
      echo "attempt $attempt: PostgreSQL did not start on port $port" >&2
    done
    cat "$cluster/server.log" >&2
    exit 1
    ;;
  stop) stop ;;
  *)
    echo "usage: $0 start|stop DIR" >&2
    exit 2
    ;;
esac
