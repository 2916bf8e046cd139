#!/usr/bin/env bash
# Events across nodes, end to end: two salientd on one PostgreSQL (their own data directories,
# ports and [node] ids). A WebSocket client on node A subscribed to "jobs" sees every state change
# of a job submitted on (and sliced by) node B, in order: queued, running, done; and a job
# submitted on A is seen by a client on B.
#   events_across_nodes_e2e.sh SALIENTD MODELS_DIR WORKDIR PG_DIR
# PG_DIR is the directory of the test cluster (tests/support/pg_cluster.sh); none: skipped (77).
set -euo pipefail
salientd=$1 models=$2 work=$3 pg_dir=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
pid_a= pid_b=
trap 'for p in $pid_a $pid_b; do kill -9 "$p" 2>/dev/null || true; done' EXIT
if [ ! -s "$pg_dir/url" ]; then
  echo "skipped: $(cat "$pg_dir/skip" 2>/dev/null || echo "no test PostgreSQL in $pg_dir")"
  exit 77
fi
cluster=$(cat "$pg_dir/url")
export PGOPTIONS="-c client_min_messages=warning"
name=e2e_events_$$
psql -X -q "$cluster/postgres" -c "DROP DATABASE IF EXISTS $name" -c "CREATE DATABASE $name"
database="$cluster/$name"

printf '[node]\nid = "node-a"\n' > a.toml
printf 'printers = []\n[node]\nid = "node-b"\n' > b.toml  # printer ids are unique in a farm: a's "sim" is enough
start a.toml node-a
pid_a=$pid base_a=$base
grep -q "events: relayed between nodes.*node=node-a" daemon.log || fail "node A does not relay its events"
mkdir node-b && cp node-a/api-key node-b/  # the key is in the database; the file is for curl
start b.toml node-b
pid_b=$pid base_b=$base

# watch BASE OUT: a client on BASE's events socket, subscribed to "jobs"; it writes OUT.ready once
# subscribed, then every job event's (id, state), until OUT.stop exists and it has seen "done" for
# each job id OUT.stop names (or 20 s of quiet: the check below then says what is missing).
watch() {
  /usr/bin/python3 - "$1" "$key" "$2" <<'PY' &
import json, os, sys, time, websocket
base, key, out = sys.argv[1:4]
ws = websocket.create_connection(base.replace("http", "ws") + "/api/v1/events",
                                 subprotocols=["salient.v1", "salient-key." + key], timeout=30)
ws.send(json.dumps({"subscribe": ["jobs"]}))
seen = []
while True:
    m = json.loads(ws.recv())
    if m["type"] == "subscribed":
        break
open(out + ".ready", "w").close()
ws.settimeout(0.5)
quiet_since = time.monotonic()
deadline = time.monotonic() + 300
while time.monotonic() < deadline:
    try:
        m = json.loads(ws.recv())
    except websocket.WebSocketTimeoutException:
        if os.path.exists(out + ".stop"):
            want = set(open(out + ".stop").read().split())
            done = {i for i, s in seen if s == "done"}
            if want <= done or time.monotonic() - quiet_since > 20:
                break
        continue
    quiet_since = time.monotonic()
    if m["type"] == "job":
        seen.append([m["data"]["id"], m["data"]["state"]])
json.dump(seen, open(out, "w"))
PY
}
wait_ready() { for _ in $(seq 600); do [ -e "$1.ready" ] && return 0; sleep 0.1; done; fail "the client on $1 did not subscribe"; }

watch "$base_a" on-a.json
watch_a=$!
watch "$base_b" on-b.json
watch_b=$!
wait_ready on-a.json
wait_ready on-b.json

submit() {  # submit BASE HEIGHT: a new job (another height: not the other's result from the cache)
  curl -s -H "X-Api-Key: $key" -F "file=@$models/suzanne.obj" -F "settings={\"height\": $2}" "$1/api/v1/jobs" |
    field "['id']"
}
id_b=$(submit "$base_b" 20)
base=$base_b wait_state "$id_b" done
id_a=$(submit "$base_a" 21)
[ "$id_a" != "$id_b" ] || fail "the second job is the first"
base=$base_a wait_state "$id_a" done
printf '%s\n' "$id_a" "$id_b" > ids.txt
for o in on-a.json on-b.json; do cp ids.txt "$o.part" && mv "$o.part" "$o.stop"; done  # whole, never half-written
wait "$watch_a" || fail "the client on node A failed"
wait "$watch_b" || fail "the client on node B failed"

# Each client's states of each job, repeats (progress) folded: exactly queued, running, done.
/usr/bin/python3 - "$id_a" "$id_b" <<'PY' || fail "a client missed or misordered a state change"
import json, sys
ids = sys.argv[1:3]
for node in ("a", "b"):
    seen = json.load(open(f"on-{node}.json"))
    for job in ids:
        states = []
        for i, s in seen:
            if i == job and (not states or states[-1] != s):
                states.append(s)
        print(f"client on node {node}, job {job}: {states}")
        assert states == ["queued", "running", "done"], states
PY
kill -TERM "$pid_a" "$pid_b"
wait "$pid_a" || true
wait "$pid_b" || true
pid_a= pid_b=
grep -q "event relay:.*failed" daemon.log && fail "a relay error was logged"
psql -X -q "$cluster/postgres" -c "DROP DATABASE $name"
echo "PASS: a client on each node saw every state change of the jobs of both, in order"
