#!/usr/bin/env bash
# salientd under load, on this machine: wrk on GET /api/v1/printers/sim (the status a dashboard
# polls) idle and while a slicing job keeps a core busy, against /healthz (no key, no work) as the
# ceiling of the same server; idle memory; 200 WebSocket subscribers receiving every state change.
#   tests/bench/daemon_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
models=$(cd ../shared/models && pwd)
work=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$work"' EXIT
"$build/server/salientd" --data "$work/data" --listen 127.0.0.1:0 2> "$work/daemon.log" &
pid=$!
for _ in $(seq 200); do grep -q "listening on" "$work/daemon.log" 2>/dev/null && break; sleep 0.05; done
base=$(grep -o "http://127.0.0.1:[0-9]*" "$work/daemon.log" | tail -1)
port=${base##*:}
key=$(cat "$work/data/api-key")
for _ in $(seq 100); do curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim" | grep -q '"operational"' && break; sleep 0.1; done
sleep 2
sim=$(pgrep -P "$pid" salient-sim || true)
echo "idle memory: salientd $(awk '/VmRSS/ {print $2}' /proc/$pid/status) KB RSS (threads: $(ls /proc/$pid/task | wc -l))," \
  "salient-sim $( [ -n "$sim" ] && awk '/VmRSS/ {print $2}' /proc/$sim/status) KB"

run_wrk() {  # run_wrk LABEL PATH [HEADER]
  local out
  out=$(wrk -t2 -c50 -d10s --latency ${3:+-H "$3"} "$base$2")
  printf '%-44s %10s req/s   p50 %8s   p99 %8s\n' "$1" "$(echo "$out" | awk '/Requests\/sec/ {print $2}')" \
    "$(echo "$out" | awk '$1 == "50%" {print $2}')" "$(echo "$out" | awk '$1 == "99%" {print $2}')"
}
echo "wrk -t2 -c50 -d10s (client and server share the 2 cores)"
run_wrk "GET /healthz (ceiling: no key, no work)" /healthz
run_wrk "GET /api/v1/printers/sim, idle" /api/v1/printers/sim "X-Api-Key: $key"
id=$(curl -s -H "X-Api-Key: $key" -F "file=@$models/stanford-bunny.obj" \
  -F 'settings={"up": "y", "height": 80, "saliency": "spectral", "planner": "exact"}' "$base/api/v1/jobs" |
  python3 -c "import json,sys; print(json.load(sys.stdin)['id'])")
for _ in $(seq 100); do curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$id" | grep -q '"running"' && break; sleep 0.1; done
run_wrk "GET /api/v1/printers/sim, a job slicing" /api/v1/printers/sim "X-Api-Key: $key"
echo "  (the job was $(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$id" | python3 -c "import json,sys; d=json.load(sys.stdin); print(d['state'], d['phase'])") when wrk ended)"
curl -s -o /dev/null -X DELETE -H "X-Api-Key: $key" "$base/api/v1/jobs/$id"
sleep 1
done_id=$(curl -s -H "X-Api-Key: $key" -F "file=@$models/cube_binary.ply" "$base/api/v1/jobs" |
  python3 -c "import json,sys; print(json.load(sys.stdin)['id'])")
sleep 1
run_wrk "GET /api/v1/jobs/{id} (a finished job)" "/api/v1/jobs/$done_id" "X-Api-Key: $key"
echo "WebSocket fan-out: 200 subscribers to 'jobs', 5 jobs submitted"
"$build/tests/bench/events_fanout_bench" 127.0.0.1 "$port" "$key" "$models/cube_binary.ply" 200 5
echo "memory after all this: salientd $(awk '/VmRSS/ {print $2}' /proc/$pid/status) KB RSS"
