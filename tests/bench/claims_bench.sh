#!/usr/bin/env bash
# Claims per second PostgreSQL sustains with the lease scheme of jobs across nodes (claim → renew
# → finish, K = 1, 2, 4, 8 threads each with its own connection), on a temporary cluster
# (tests/support/pg_cluster.sh) with fsync off, then on, the median of 3 runs each; SQLite's
# figure (one node, WAL) for comparison.   Usage: tests/bench/claims_bench.sh [BUILD_DIR] [JOBS]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build} jobs=${2:-3000}
bench="$build/tests/bench/claims_bench"
dir=$(mktemp -d /tmp/salient-claims-bench.XXXXXX)
trap 'bash tests/support/pg_cluster.sh stop "$dir/pg" >/dev/null 2>&1 || true; rm -rf "$dir"' EXIT
median() {  # median RUNS…: per K, the median claims/s of the runs' outputs
  python3 -c '
import sys, statistics
rows = {}
for f in sys.argv[1:]:
    for line in open(f):
        p = line.split()
        if len(p) == 4 and p[0].isdigit(): rows.setdefault(int(p[0]), []).append(float(p[2]))
for k in sorted(rows):
    runs = ", ".join("%.0f" % v for v in rows[k])
    print("   K=%d: %.0f claims/s (runs: %s)" % (k, statistics.median(rows[k]), runs))
' "$@"
}
for fsync in off on; do
  SALIENT_PG_FSYNC=$fsync bash tests/support/pg_cluster.sh start "$dir/pg" >/dev/null
  url=$(cat "$dir/pg/url")
  psql -X -q "$url/postgres" -c "CREATE DATABASE farm"  # the bench makes its own beside it
  echo "PostgreSQL $(psql -X -tA "$url/postgres" -c 'SHOW server_version'), fsync=$(psql -X -tA "$url/postgres" -c 'SHOW fsync'), $jobs jobs per run:"
  echo "   $bench $url/farm $jobs 1 2 4 8"
  for run in 1 2 3; do "$bench" "$url/farm" "$jobs" 1 2 4 8 > "$dir/run$run"; done
  median "$dir"/run?
  bash tests/support/pg_cluster.sh stop "$dir/pg"
done
echo "SQLite (WAL, synchronous=NORMAL), $jobs jobs per run:"
echo "   $bench $dir/claims.db $jobs 1 2 4 8"
for run in 1 2 3; do rm -f "$dir"/claims.db*; "$bench" "$dir/claims.db" "$jobs" 1 2 4 8 > "$dir/run$run"; done
median "$dir"/run?
