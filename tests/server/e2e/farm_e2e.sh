#!/usr/bin/env bash
# A print farm: one PostgreSQL and three salientd nodes on loopback, each with its own data
# directory and port:
#   n1: api + slicer (no printers)   n2: slicer + printers b1 b2   n3: api + printers c1 c2
# A WebSocket client on n1 records every job and printer event. 30 jobs are submitted through
# both API nodes (n1, n3); n2 is killed with SIGKILL while it slices one and is started again:
# every job ends done exactly once (one "done" event each, the killed one re-queued with its
# reason kept). Then 12 prints go to the farm-wide queue through both API nodes: they run on the
# four simulators of n2 and n3, and each simulator's log is exactly the G-code of its prints, in
# order; the client on n1 saw every print start and finish, and every job's state changes.
#   farm_e2e.sh SALIENTD SALIENT MODELS_DIR WORKDIR PG_DIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4 pg_dir=$5
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
if [ ! -s "$pg_dir/url" ]; then
  echo "skipped: $(cat "$pg_dir/skip" 2>/dev/null || echo "no test PostgreSQL in $pg_dir")"
  exit 77
fi
declare -A pids bases
watcher= snapshot=
cleanup() {
  for n in "${!pids[@]}"; do kill -9 "${pids[$n]}" 2>/dev/null || true; done
  [ -n "$watcher" ] && kill "$watcher" 2>/dev/null || true
  [ -n "$snapshot" ] && kill "$snapshot" 2>/dev/null || true
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in n1.log n2.log n3.log; do echo "== $f"; tail -15 "$f" 2>/dev/null; done; exit 1; }
cluster=$(cat "$pg_dir/url")
export PGOPTIONS="-c client_min_messages=warning"
name=farm_$$
psql -X -q "$cluster/postgres" -c "DROP DATABASE IF EXISTS $name" -c "CREATE DATABASE $name"
database="$cluster/$name"
sql() { psql -X -q -tA "$database" -c "$1"; }

# node_config NAME ROLES PRINTER_IDS…
node_config() {
  local node=$1 roles=$2; shift 2
  {
    [ $# -eq 0 ] && printf 'printers = []\n'
    printf '[node]\nid = "%s"\nroles = %s\nlease_seconds = 3\n\n[jobs]\nqueue_limit = 64\n\n' "$node" "$roles"
    for id in "$@"; do
      cat <<TOML
[[printers]]
id = "$id"
kind = "sim"
profile = "generic-i3"
auto_start = true
sim_args = "--advanced-ok --time-scale 0.01 --heat-time-scale 0 --log $PWD/sim-$id.log"
TOML
    done
  } > "$node.toml"
}
# start_node NAME: salientd with NAME.toml, data dir NAME, log NAME.log; sets bases[NAME].
start_node() {
  local n=$1 before
  before=$(grep -c "listening on" "$n.log" 2>/dev/null || true)
  "$salientd" --config "$n.toml" --data "$n" --listen 127.0.0.1:0 --database "$database" 2>>"$n.log" &
  pids[$n]=$!
  for _ in $(seq 600); do
    [ "$(grep -c "listening on" "$n.log" 2>/dev/null || true)" -gt "${before:-0}" ] && break
    sleep 0.05
  done
  [ "$(grep -c "listening on" "$n.log")" -gt "${before:-0}" ] || fail "$n did not start"
  bases[$n]=$(grep -o "http://127.0.0.1:[0-9]*" "$n.log" | tail -1)
}
on() { local n=$1 path=$2; shift 2; curl -s -H "X-Api-Key: $key" "$@" "${bases[$n]}$path"; }

node_config n1 '["api", "slicer"]'
node_config n2 '["slicer", "printers"]' b1 b2
node_config n3 '["api", "printers"]' c1 c2
start_node n1
key=$(cat n1/api-key)
for n in n2 n3; do mkdir -p "$n" && cp n1/api-key "$n/"; start_node "$n"; done

# Every API node lists the farm's four printers, with their node.
printers_seen() {
  on "$1" /api/v1/printers | python3 -c "
import json, sys
ps = {p['id']: (p.get('node'), p['state']) for p in json.load(sys.stdin)['printers']}
want = {'b1': 'n2', 'b2': 'n2', 'c1': 'n3', 'c2': 'n3'}
ok = all(ps.get(i, (None,))[0] == n and ps[i][1] == 'operational' for i, n in want.items())
print(ps); sys.exit(0 if ok else 1)"
}
eventually 60 printers_seen n1 > /dev/null || fail "n1 does not list the farm's printers: $(cat eventually.out)"
eventually 60 printers_seen n3 > /dev/null || fail "n3 does not list the farm's printers: $(cat eventually.out)"

# A client on n1 subscribing to another node's printer gets its state first, from the registry.
SALIENT_SERVER=${bases[n1]} SALIENT_API_KEY=$key "$salient" events printer/c1 > snapshot.jsonl 2>&1 &
snapshot=$!
snapshot_seen() { grep '"topic":"printer/c1"' snapshot.jsonl | grep -q '"node":"n3"'; }
eventually 60 snapshot_seen > /dev/null || fail "no snapshot of n3's c1 on n1: $(cat snapshot.jsonl)"
kill "$snapshot" 2>/dev/null || true
wait "$snapshot" 2>/dev/null || true
snapshot=

# The watcher on n1: every job and printer event.
SALIENT_SERVER=${bases[n1]} SALIENT_API_KEY=$key "$salient" events jobs printers > events.jsonl 2> events.err &
watcher=$!
for _ in $(seq 1200); do grep -q '"subscribed"' events.jsonl 2>/dev/null && break; sleep 0.05; done
grep -q '"subscribed"' events.jsonl || fail "no subscription on n1's /api/v1/events: $(cat events.err)"

# 30 jobs through n1 and n3; a few larger ones (the bunny, saliency on) so that one is surely
# being sliced by n2 when it is killed. Settings differ, so that no job reuses another's result.
: > jobs.txt
for i in $(seq 1 30); do
  n=$([ $((i % 2)) = 0 ] && echo n1 || echo n3)
  if [ $((i % 10)) = 0 ]; then
    model=stanford-bunny.obj settings="{\"up\": \"y\", \"height\": $((20 + i))}"
  else
    model=cube_binary.ply settings="{\"height\": $((6 + i % 5)).$i, \"saliency\": \"uniform\"}"
  fi
  code=$(on "$n" /api/v1/jobs -o job$i.json -w '%{http_code}' -F "file=@$models/$model" -F "settings=$settings")
  [ "$code" = 201 ] || fail "job $i through $n: $code $(cat job$i.json)"
  field "['id']" < job$i.json >> jobs.txt
done

# Kill n2 while it slices a job, then start it again.
running_on_n2() { [ -n "$(sql "SELECT id FROM jobs WHERE state = 'running' AND node = 'n2' LIMIT 1")" ]; }
# The victim is a job still running on n2 once it is dead (a job seen running before the kill may
# have been finished in between); if n2 held none at the kill, it is started and killed again.
victim=
for _ in 1 2 3 4 5; do
  eventually 120 running_on_n2 > /dev/null || fail "n2 never took a job"
  kill -9 "${pids[n2]}"
  wait "${pids[n2]}" 2>/dev/null || true
  victim=$(sql "SELECT id FROM jobs WHERE state = 'running' AND node = 'n2' LIMIT 1")
  sleep 1
  start_node n2
  [ -n "$victim" ] && break
done
[ -n "$victim" ] || fail "n2 was never killed in the middle of a job"
echo "killed n2 while it sliced $victim"

all_done() {
  local n
  n=$(sql "SELECT count(*) FROM jobs WHERE state = 'done'")
  echo "$n of 30 done; $(sql "SELECT string_agg(id || ':' || state, ' ') FROM jobs WHERE state <> 'done'")"
  [ "$n" = 30 ]
}
eventually 900 all_done > /dev/null || fail "not every job was done: $(cat eventually.out)"
[ "$(sql "SELECT count(*) FROM jobs WHERE state <> 'done'")" = 0 ] || fail "jobs not done"
on n3 "/api/v1/jobs/$victim" > victim.json
python3 - victim.json <<'PY' || fail "the killed job: $(cat victim.json)"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["state"] == "done", j
assert j["attempts"] >= 2, f"attempts {j['attempts']}: the killed attempt was not counted"
assert any("n2" in r.get("reason", "") or r.get("node") == "n2" for r in j["requeues"]), j["requeues"]
print("killed job", j["id"], "done at attempt", j["attempts"], "after", j["requeues"])
PY

# 12 prints through the farm-wide queue, 6 through each API node.
head -12 jobs.txt > printed.txt
i=0
while read -r job; do
  i=$((i + 1))
  n=$([ $((i % 2)) = 0 ] && echo n1 || echo n3)
  code=$(on "$n" /api/v1/farm/generic-i3/print -o print$i.json -w '%{http_code}' -XPOST -H 'Content-Type: application/json' \
    -d "{\"job\": \"$job\"}")
  [ "$code" = 202 ] || fail "farm print $i through $n: $code $(cat print$i.json)"
done < printed.txt
twelve_finished() {
  local n
  n=$(sql "SELECT count(*) FROM prints WHERE state = 'finished'")
  echo "$n finished: $(sql "SELECT string_agg(printer_id || ':' || state, ' ') FROM prints")"
  [ "$n" = 12 ]
}
eventually 900 twelve_finished > /dev/null || fail "the 12 prints did not all finish: $(cat eventually.out)"
[ "$(sql "SELECT count(*) FROM prints")" = 12 ] || fail "more prints than asked: $(sql "SELECT count(*) FROM prints")"
[ "$(sql "SELECT count(DISTINCT job_id) FROM prints")" = 12 ] || fail "a job printed twice"
[ "$(sql "SELECT count(*) FROM print_queue")" = 0 ] || fail "the farm queue is not empty"

# Each simulator executed exactly the G-code of its prints, in order.
for printer in b1 b2 c1 c2; do
  : > want-$printer.gcode
  for job in $(sql "SELECT job_id FROM prints WHERE printer_id = '$printer' ORDER BY id"); do
    on n1 "/api/v1/jobs/$job/gcode" >> want-$printer.gcode
  done
  if [ -s want-$printer.gcode ]; then same_commands want-$printer.gcode sim-$printer.log; fi
done
[ "$(sql "SELECT count(DISTINCT printer_id) FROM prints")" -ge 3 ] || fail "the prints were not spread over the farm"

# The client on n1 saw every job's state changes (queued … done, exactly one done each) and
# every print start and finish, from the nodes that made them (the last ones may still be on their
# way through the database: waited for).
sql "SELECT id, printer_id, job_id FROM prints ORDER BY id" > prints.txt
events_complete() {
  python3 - events.jsonl jobs.txt prints.txt "$victim" <<'PY'
import json, sys
events = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
jobs = [l.strip() for l in open(sys.argv[2]) if l.strip()]
prints = [l.strip().split("|") for l in open(sys.argv[3]) if l.strip()]
victim = sys.argv[4]
states = {j: [] for j in jobs}
for e in events:
    if e.get("type") == "job" and e["data"]["id"] in states:
        s = e["data"]["state"]
        if not states[e["data"]["id"]] or states[e["data"]["id"]][-1] != s:
            states[e["data"]["id"]].append(s)
for j, seen in states.items():
    assert seen[0] == "queued", f"{j}: {seen}"
    assert "running" in seen, f"{j}: {seen}"
    assert seen.count("done") == 1 and seen[-1] == "done", f"{j}: {seen}"
reruns = [e for e in events if e.get("type") == "job" and e["data"]["id"] == victim
          and e["data"]["state"] == "running" and e["data"]["attempts"] >= 2]
assert reruns, f"the killed job was not seen running again: {states[victim]}"
print_states = {}
for e in events:
    if e.get("type") != "printer":
        continue
    for key in ("print", "last_print"):
        p = e["data"].get(key)
        if p:
            print_states.setdefault(str(p["id"]), set()).add(p["state"])
for pid, printer, job in prints:
    seen = print_states.get(pid, set())
    assert "printing" in seen and "finished" in seen, f"print {pid} on {printer}: {seen}"
print(f"n1 saw {len(events)} events: 30 jobs queued..done once each (the killed one seen running "
      f"again at attempt {reruns[0]['data']['attempts']}), 12 prints printing..finished")
PY
}
eventually 60 events_complete || fail "the events on n1 are incomplete"
kill "$watcher" 2>/dev/null || true
watcher=
# Operations: each node's /metrics names it; salient doctor sees the database, and fails its
# line when the database goes away under the nodes.
for n in n1 n2 n3; do
  on "$n" /metrics > metrics-$n.txt
  grep -q "^salient_node_info{node=\"$n\"," metrics-$n.txt || fail "$n's /metrics does not name it"
  grep -Eq '^salient_relay_events_total\{what="received"\} [1-9]' metrics-$n.txt || fail "$n's /metrics has no relayed events"
done
doctor_run() {  # doctor_run EXPECTED_STATUS
  local got=0
  "$salient" doctor --server "${bases[n1]}" --key "$key" --data n1 > doctor.out 2>&1 || got=$?
  sed 's/^/  | /' doctor.out
  [ "$got" = "$1" ] || fail "doctor: exit $got, expected $1"
}
doctor_run 0
grep -Eq "^ok +database +postgresql answers in .* \(node n1\)" doctor.out || fail "doctor's database line"
psql -X -q "$cluster/postgres" -c "DROP DATABASE $name WITH (FORCE)"
doctor_run 1
grep -Eq "^FAIL +database +salientd cannot reach its database.*— fix: .*store" doctor.out || fail "doctor's database failure"
[ "$(curl -s -o /dev/null -w '%{http_code}' "${bases[n3]}/healthz")" = 503 ] || fail "n3's healthz without its database"
for n in n1 n2 n3; do kill -TERM "${pids[$n]}"; wait "${pids[$n]}" || true; unset "pids[$n]"; done
echo "PASS: three nodes, 30 jobs done once each through a SIGKILL, 12 prints exact through the farm queue, all seen on n1"
