#!/usr/bin/env bash
# A farm whose hosts' clocks disagree (libfaketime shifts a node's clock) still agrees on who is
# alive, because heartbeats and liveness are on the database's clock. On one PostgreSQL:
#  - Y: roles api and printers, printer y1, the true time;
#  - X: printers, x1, its clock 5 minutes behind (its heartbeats would look 5 minutes old);
#  - Z: printers, z1, its clock 5 minutes ahead (the others' heartbeats would look 5 minutes old
#    to it, and its own would look alive for 5 minutes after it died).
# And /api/v1/nodes: the nodes as Y sees them, and forgetting a dead one.
# Checked: Y lists every printer live; a print on x1 through Y runs (not 503); Z, ticking for
# several leases, interrupts neither y1's print nor x1's; Z killed -9: z1 offline on Y within
# moments and a request for it 503 naming Z (not a 504 after waiting for a dead node); the node
# list agrees; Z forgotten (admin; not Y itself, not live X); X frozen, forgotten, thawed: back
# with x1; Z restarted: back with z1.
#   farm_clocks_e2e.sh SALIENTD WORKDIR PG_DIR
set -euo pipefail
salientd=$1 work=$2 pg_dir=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
xpid=
zpid=
cleanup() {  # whatever is still running
  set +e
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null
  [ -n "$xpid" ] && kill -9 "$xpid" 2>/dev/null
  [ -n "$zpid" ] && kill -9 "$zpid" 2>/dev/null
  return 0
}
trap cleanup EXIT
if [ ! -s "$pg_dir/url" ]; then
  echo "skipped: $(cat "$pg_dir/skip" 2>/dev/null || echo "no test PostgreSQL in $pg_dir")"
  exit 77
fi
faketime_lib=$(dpkg -L libfaketime 2> /dev/null | grep 'libfaketimeMT.so.1$' | head -1 || true)
if [ -z "$faketime_lib" ]; then
  echo "skipped: libfaketime is not installed (Debian package faketime; deploy/install-deps.sh installs it)"
  exit 77
fi
cluster=$(cat "$pg_dir/url")
export PGOPTIONS="-c client_min_messages=warning"
name=e2e_clocks_$$
psql -X -q "$cluster/postgres" -c "DROP DATABASE IF EXISTS $name" -c "CREATE DATABASE $name"
database="$cluster/$name"
api() { curl -s -H "X-Api-Key: $key" "$@"; }

node_config() {  # node_config ID ROLES PRINTER
  cat > "$1.toml" <<TOML
[node]
id = "$1"
roles = [$2]
lease_seconds = 3

[[printers]]
id = "$3"
kind = "sim"
auto_start = false
sim_args = "--advanced-ok --time-scale 0.05 --heat-time-scale 0 --log $PWD/sim-$3.log"
TOML
}
# shifted OFFSET COMMAND…: COMMAND with its clock OFFSET off (libfaketime's syntax, e.g. -300s),
# its steady clock left alone. Preloaded here, not through the faketime wrapper, so that $! is the
# command itself (the wrapper forks: a signal to it would not reach the daemon). A sanitizer
# build must accept the library loaded before its runtime.
shifted() {
  local offset=$1
  shift
  # exec: in the background (a subshell) $! is then the command itself
  exec env LD_PRELOAD="$faketime_lib" FAKETIME="$offset" FAKETIME_DONT_FAKE_MONOTONIC=1 \
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0" "$@"
}
# start_shifted ID OFFSET: a printers-only node whose clock is OFFSET off; up when it says so.
# Sets $started.
start_shifted() {
  shifted "$2" "$salientd" --data "$1data" --config "$1.toml" --listen 127.0.0.1:0 \
    --database "$database" 2>> "$1.log" &
  started=$!
  for _ in $(seq 600); do
    grep -q "no api role" "$1.log" 2> /dev/null && return 0
    sleep 0.05
  done
  tail "$1.log"
  fail "node $1 did not start"
}
printer_state() { api "$base/api/v1/printers/$1" | field "['state']"; }
wait_printer() {  # wait_printer ID STATE
  for _ in $(seq 600); do [ "$(printer_state "$1")" = "$2" ] && return 0; sleep 0.1; done
  fail "$1 never $2 on Y (is $(printer_state "$1"))"
}
print_state() { api "$base/api/v1/printers/$1/prints" | field "['prints'][0]['state']"; }

node_config Y '"api", "printers"' y1
start Y.toml Ydata
node_config X '"printers"' x1
start_shifted X -300s
xpid=$started
node_config Z '"printers"' z1
start_shifted Z +300s
zpid=$started
# The shift took: each node's log says the time its clock gives.
[ "$(shifted +300s date +%s)" -gt $(($(date +%s) + 250)) ] || fail "libfaketime does not shift the clock here"
python3 - X.log <<'PY' || fail "X's clock is not 5 minutes behind: $(head -2 X.log)"
import datetime, sys, time
stamp = open(sys.argv[1]).readline().split()[0]  # salientd's log: UTC, to the second
at = datetime.datetime.strptime(stamp, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=datetime.timezone.utc)
behind = time.time() - at.timestamp()
sys.exit(0 if 250 < behind < 400 else 1)
PY

# 1. Y sees every printer live: X's heartbeats are not 5 minutes old, whatever X's clock says.
for p in y1 x1 z1; do
  api -o /dev/null -XPOST "$base/api/v1/printers/$p/connect"
  wait_printer "$p" operational
done
api "$base/api/v1/printers" > list.json
python3 - list.json <<'PY' || fail "Y's list: $(cat list.json)"
import json, sys
ps = {p['id']: (p['node'], p['state']) for p in json.load(open(sys.argv[1]))['printers']}
assert ps == {'x1': ('X', 'operational'), 'y1': ('Y', 'operational'), 'z1': ('Z', 'operational')}, ps
PY

# 2. Prints on y1 and x1 (through Y) go on while Z ticks for several leases: Z's clock makes the
# others' heartbeats look 5 minutes old to it, and it must not mark their prints interrupted.
# F400: about 45 s at the simulators' 20x, so that neither print can end before the check below
# however slow the machine (they are cancelled right after it).
python3 -c "
for i in range(3000): print(f'G1 X{10 + i % 100} Y{10 + (i // 100)} F400')" > slow.gcode
api -o /dev/null -F "file=@slow.gcode;filename=slow.gcode" "$base/api/files/local"
for p in y1 x1; do
  code=$(api -o print-$p.json -w '%{http_code}' -XPOST -d '{"file": "slow.gcode"}' "$base/api/v1/printers/$p/print")
  [ "$code" = 202 ] || fail "print on $p through Y: $code $(cat print-$p.json)"
  wait_printer "$p" printing
done
sleep 8  # more than two of Z's leases, eight of its ticks
for p in y1 x1; do
  [ "$(print_state $p)" = printing ] || fail "the print on $p is $(print_state $p) after Z ticked: $(api "$base/api/v1/printers/$p/prints")"
  [ "$(printer_state $p)" = printing ] || fail "$p is $(printer_state $p)"
done
for p in y1 x1; do
  api -o /dev/null -XPOST "$base/api/v1/printers/$p/cancel"
  wait_printer "$p" operational
done

# 3. Z killed: its heartbeat (written on the database's clock) ages at once, however far ahead
# Z's own clock was: z1 offline on Y within a lease and a bit, and a request for it 503 naming Z.
kill -9 "$zpid"
wait "$zpid" 2> /dev/null || true
zpid=
killed=$SECONDS
wait_printer z1 offline
[ $((SECONDS - killed)) -le 15 ] || fail "z1 took $((SECONDS - killed)) s to go offline"
code=$(api -o dead.json -w '%{http_code}' -XPOST "$base/api/v1/printers/z1/connect")
[ "$code" = 503 ] && grep -q "'Z'" dead.json || fail "a request for the dead node's printer: $code $(cat dead.json)"
[ "$(printer_state x1)" = operational ] || fail "x1 is $(printer_state x1) after Z died"

# 4. GET /api/v1/nodes says the same; a dead node is forgotten (admin only), a live one or this
# one is not; a forgotten node that comes back registers its printers again.
nodes() {  # nodes: "ID:live:printers …" by id
  api "$base/api/v1/nodes" | python3 -c "
import json, sys
print(' '.join(f\"{n['id']}:{n['live']}:{','.join(n['printers'])}\" for n in json.load(sys.stdin)['nodes']))"
}
[ "$(nodes)" = "X:True:x1 Y:True:y1 Z:False:z1" ] || fail "GET /api/v1/nodes: $(api "$base/api/v1/nodes")"
[ "$(api "$base/api/v1/nodes" | field "['nodes'][1]['self']")" = True ] || fail "Y is not marked self"
operator=$(api -XPOST -d '{"user": "otto", "role": "operator"}' "$base/api/v1/keys" | field "['key']")
forget() {  # forget ID [KEY]: the status of DELETE /api/v1/nodes/ID
  curl -s -o forget.json -w '%{http_code}' -H "X-Api-Key: ${2:-$key}" -XDELETE "$base/api/v1/nodes/$1"
}
[ "$(forget Z "$operator")" = 403 ] || fail "an operator forgot a node: $(cat forget.json)"
[ "$(forget Y)" = 409 ] && grep -q "this node" forget.json || fail "Y forgot itself: $(cat forget.json)"
[ "$(forget X)" = 409 ] && grep -q "alive" forget.json || fail "a live node was forgotten: $(cat forget.json)"
[ "$(forget Z)" = 204 ] || fail "forgetting dead Z: $(cat forget.json)"
[ "$(forget Z)" = 404 ] || fail "forgetting Z twice: $(cat forget.json)"
[ "$(nodes)" = "X:True:x1 Y:True:y1" ] || fail "after forgetting Z: $(api "$base/api/v1/nodes")"
[ "$(api -o /dev/null -w '%{http_code}' "$base/api/v1/printers/z1")" = 404 ] || fail "z1 is still listed"
# X frozen until it is dead, forgotten, then thawed: its next heartbeat registers x1 again.
kill -STOP "$xpid"
wait_printer x1 offline
[ "$(forget X)" = 204 ] || fail "forgetting frozen X: $(cat forget.json)"
[ "$(api -o /dev/null -w '%{http_code}' "$base/api/v1/printers/x1")" = 404 ] || fail "x1 is still listed"
kill -CONT "$xpid"
wait_printer x1 operational
[ "$(nodes)" = "X:True:x1 Y:True:y1" ] || fail "X back: $(api "$base/api/v1/nodes")"
# Z restarted (its clock still ahead) is a node again, with z1.
start_shifted Z +300s
zpid=$started
wait_printer z1 operational
[ "$(nodes)" = "X:True:x1 Y:True:y1 Z:True:z1" ] || fail "Z back: $(api "$base/api/v1/nodes")"
echo "ok: nodes 5 minutes apart agree on who is alive; z1 offline $((SECONDS - killed)) s after Z died"
