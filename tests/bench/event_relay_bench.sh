#!/usr/bin/env bash
# Event latency across nodes on a temporary PostgreSQL (tests/support/pg_cluster.sh; set
# SALIENT_PG_FSYNC=on for a cluster that syncs its commits, as a farm's does).
#   event_relay_bench.sh BUILD_DIR [EVENTS] [RATE_PER_SECOND]
set -euo pipefail
build=${1:?build directory}
here=$(cd "$(dirname "$0")" && pwd)
dir=$(mktemp -d /tmp/salient-relay-bench.XXXXXX)
trap 'bash "$here/../support/pg_cluster.sh" stop "$dir" >/dev/null; rm -rf "$dir"' EXIT
bash "$here/../support/pg_cluster.sh" start "$dir" >/dev/null
url=$(cat "$dir/url")
psql -X -q "$url/postgres" -c "CREATE DATABASE relay_bench"
"$build/tests/bench/event_relay_bench" "$url/relay_bench" "${2:-5000}" "${3:-1000}"
