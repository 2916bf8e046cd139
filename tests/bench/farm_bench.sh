#!/usr/bin/env bash
# The farm's database, measured on this machine (a temporary PostgreSQL cluster with fsync on, as
# a farm's would be, beside salientd on the same 2 cores):
#  1. HTTP status requests a dashboard polls, salientd on PostgreSQL against salientd on SQLite in
#     the same run (wrk, interleaved twice so drift shows);
#  2. what the farm costs the database: transactions per second of one printing printer, and per
#     sliced job (pg_stat_database.xact_commit before and after), and the transactions per second
#     this PostgreSQL sustains (pgbench, simple updates), for the capacity calculation in
#     BENCHMARKS.md;
#  3. the lease scheme's claims per second (claims_bench) and 4. the event latency across nodes
#     (event_relay_bench), on the same cluster.
#   tests/bench/farm_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
build=$(cd "${1:-build}" && pwd)
models=$(cd ../shared/models && pwd)
work=$(mktemp -d)
chmod 755 "$work"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  bash "$root/tests/support/pg_cluster.sh" stop "$work/pg" > /dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT
SALIENT_PG_FSYNC=on bash tests/support/pg_cluster.sh start "$work/pg"
cluster=$(cat "$work/pg/url")
psql -X -q "$cluster/postgres" -c "CREATE DATABASE bench"
database="$cluster/bench"
bin=$(cat "$work/pg/bin")

# start NAME [--database URL]: a salientd with one simulated printer; sets base_NAME, key_NAME.
start() {
  local name=$1 base; shift
  cat > "$work/$name.toml" <<TOML
[[printers]]
id = "sim"
kind = "sim"
sim_args = "--advanced-ok --time-scale 0.05 --heat-time-scale 0"
TOML
  "$build/server/salientd" --config "$work/$name.toml" --data "$work/$name" --listen 127.0.0.1:0 "$@" 2> "$work/$name.log" &
  pids+=($!)
  for _ in $(seq 200); do grep -q "listening on" "$work/$name.log" 2>/dev/null && break; sleep 0.05; done
  base=$(grep -o "http://127.0.0.1:[0-9]*" "$work/$name.log" | tail -1)
  printf -v "base_$name" '%s' "$base"
  printf -v "key_$name" '%s' "$(cat "$work/$name/api-key")"
}
start sqlite
start pg --database "$database"
job_of() {  # job_of BASE KEY: a finished job's id
  local id
  id=$(curl -s -H "X-Api-Key: $2" -F "file=@$models/cube_binary.ply" -F 'settings={"saliency": "uniform"}' "$1/api/v1/jobs" |
    python3 -c "import json,sys; print(json.load(sys.stdin)['id'])")
  for _ in $(seq 300); do curl -s -H "X-Api-Key: $2" "$1/api/v1/jobs/$id" | grep -q '"done"' && break; sleep 0.1; done
  echo "$id"
}
job_sqlite=$(job_of "$base_sqlite" "$key_sqlite")
job_pg=$(job_of "$base_pg" "$key_pg")
run_wrk() {  # run_wrk LABEL URL KEY
  local out
  out=$(wrk -t2 -c50 -d10s --latency -H "X-Api-Key: $3" "$2")
  printf '%-40s %10s req/s   p50 %8s   p99 %8s\n' "$1" "$(echo "$out" | awk '/Requests\/sec/ {print $2}')" \
    "$(echo "$out" | awk '$1 == "50%" {print $2}')" "$(echo "$out" | awk '$1 == "99%" {print $2}')"
}
echo "== 1. HTTP status requests, wrk -t2 -c50 -d10s (client, server and PostgreSQL share the 2 cores)"
for round in 1 2; do
  run_wrk "GET /api/v1/jobs/{id}, SQLite" "$base_sqlite/api/v1/jobs/$job_sqlite" "$key_sqlite"
  run_wrk "GET /api/v1/jobs/{id}, PostgreSQL" "$base_pg/api/v1/jobs/$job_pg" "$key_pg"
  run_wrk "GET /api/v1/printers/sim, SQLite" "$base_sqlite/api/v1/printers/sim" "$key_sqlite"
  run_wrk "GET /api/v1/printers/sim, PostgreSQL" "$base_pg/api/v1/printers/sim" "$key_pg"
done

echo "== 2. what the farm asks of the database"
commits() { psql -X -tA "$database" -c "SELECT xact_commit FROM pg_stat_database WHERE datname = 'bench'"; }
# A printing printer: a long file on the simulator, 30 s of it.
python3 -c "
for i in range(200000): print(f'G1 X{10 + i % 100} Y{10 + (i // 100) % 100} F1200')" > "$work/long.gcode"
curl -s -o /dev/null -H "X-Api-Key: $key_pg" -F "file=@$work/long.gcode;filename=long.gcode" "$base_pg/api/files/local"
curl -s -o /dev/null -H "X-Api-Key: $key_pg" -H 'Content-Type: application/json' -XPOST -d '{"file": "long.gcode"}' \
  "$base_pg/api/v1/printers/sim/print"
sleep 5
before=$(commits) t0=$(date +%s.%N)
sleep 30
after=$(commits) t1=$(date +%s.%N)
lines=$(curl -s -H "X-Api-Key: $key_pg" "$base_pg/api/v1/printers/sim" | python3 -c "import json,sys; print(json.load(sys.stdin)['print']['confirmed'])")
python3 -c "print(f'one printing printer: {($after - $before) / ($t1 - $t0):.2f} transactions/s (the daemon idle but for it; {$lines} lines confirmed so far)')"
curl -s -o /dev/null -H "X-Api-Key: $key_pg" -XPOST "$base_pg/api/v1/printers/sim/cancel"
sleep 3
# Idle: the node's own background (heartbeats, leases, polls).
before=$(commits) t0=$(date +%s.%N)
sleep 20
after=$(commits) t1=$(date +%s.%N)
python3 -c "print(f'one idle node: {($after - $before) / ($t1 - $t0):.2f} transactions/s')"
# Jobs: 10 small ones, sliced one after the other.
before=$(commits) t0=$(date +%s.%N)
for i in $(seq 10); do
  id=$(curl -s -H "X-Api-Key: $key_pg" -F "file=@$models/cube_binary.ply" -F "settings={\"height\": 1$i, \"saliency\": \"uniform\"}" \
    "$base_pg/api/v1/jobs" | python3 -c "import json,sys; print(json.load(sys.stdin)['id'])")
  for _ in $(seq 600); do curl -s -H "X-Api-Key: $key_pg" "$base_pg/api/v1/jobs/$id" | grep -q '"done"' && break; sleep 0.1; done
done
after=$(commits) t1=$(date +%s.%N)
python3 -c "
idle_rate = 0
print(f'one sliced job (cube, uniform): {($after - $before) / 10:.1f} transactions, {($t1 - $t0) / 10:.2f} s each here (submit, claim, progress, renewals, result files, finish, and the polls to see it done)')"
"$bin/pgbench" -i -q "$database" > /dev/null 2>&1
for c in 1 4 16; do
  tps=$("$bin/pgbench" -n -N -c $c -j 2 -T 10 "$database" 2>/dev/null | awk '/^tps/ {print $3; exit}')
  echo "pgbench -N (simple updates), $c clients: $tps transactions/s"
done
echo "== 2b. a request for another node's printer, carried through the database (sequential, 200)"
cat > "$work/px.toml" <<TOML
[node]
id = "px"
roles = ["printers"]
[[printers]]
id = "remote"
kind = "sim"
sim_args = "--advanced-ok --time-scale 0.05 --heat-time-scale 0"
TOML
mkdir -p "$work/px" && cp "$work/pg/api-key" "$work/px/"
"$build/server/salientd" --config "$work/px.toml" --data "$work/px" --listen 127.0.0.1:0 --database "$database" 2> "$work/px.log" &
pids+=($!)
for _ in $(seq 300); do curl -s -H "X-Api-Key: $key_pg" "$base_pg/api/v1/printers/remote" | grep -q '"operational"' && break; sleep 0.1; done
latency() {  # latency PATH: p50/p99 of 200 sequential GETs through the pg node
  for _ in $(seq 200); do curl -s -o /dev/null -w '%{time_total}\n' -H "X-Api-Key: $key_pg" "$base_pg$1"; done |
    python3 -c "import sys; t = sorted(float(l) * 1000 for l in sys.stdin); print(f'p50 {t[len(t) // 2]:.1f} ms  p99 {t[int(len(t) * 0.99) - 1]:.1f} ms')"
}
echo "GET /api/v1/printers/remote/queue (another node's): $(latency /api/v1/printers/remote/queue)"
echo "GET /api/v1/printers/sim/queue (this node's):       $(latency /api/v1/printers/sim/queue)"
echo "== 3. claims per second with the lease scheme (claim, renew, finish; K connections)"
echo "   $build/tests/bench/claims_bench URL 3000 1 2 4 8"
"$build/tests/bench/claims_bench" "$database" 3000 1 2 4 8
echo "== 4. event latency across two relays (nodes) on this PostgreSQL"
echo "   $build/tests/bench/event_relay_bench URL 5000 1000"
"$build/tests/bench/event_relay_bench" "$database" 5000 1000
