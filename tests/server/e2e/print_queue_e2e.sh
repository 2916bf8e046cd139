#!/usr/bin/env bash
# The print queue on the real simulator: three prints sent to one busy printer are queued (202,
# positions), run in order through POST …/queue/next, each executed exactly (the simulator's log
# is the three files, one after the other); the queue survives a restart; reorder, remove and
# bad input (unknown entry 404, bad position 400).
#   print_queue_e2e.sh SALIENTD WORKDIR
set -euo pipefail
salientd=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
state() { api "$base/api/v1/printers/sim" | field "['state']"; }
wait_idle() {
  for _ in $(seq 600); do [ "$(state)" = operational ] && return 0; sleep 0.1; done
  fail "printer never idle"
}
for n in 1 2 3; do
  python3 -c "
for i in range(300): print(f'G1 X{10 + i % 50 + $n} Y{10 + $n} F3000')" > f$n.gcode
done
sim_config s.toml "--advanced-ok --time-scale 0.05 --heat-time-scale 0 --log $PWD/sim.log"
start s.toml
wait_idle
for n in 1 2 3; do api -o /dev/null -F "file=@f$n.gcode;filename=f$n.gcode" "$base/api/files/local"; done
api -XPOST -d '{"file":"f1.gcode"}' "$base/api/v1/printers/sim/print" > p1.json
[ "$(field "['state']" < p1.json)" = printing ] || fail "first print: $(cat p1.json)"
for n in 2 3; do
  api -XPOST -d "{\"file\":\"f$n.gcode\"}" "$base/api/v1/printers/sim/print" > p$n.json
  [ "$(field "['queued']" < p$n.json)" = True ] || fail "print $n not queued: $(cat p$n.json)"
  [ "$(field "['position']" < p$n.json)" = $((n - 1)) ] || fail "print $n position: $(cat p$n.json)"
done
# Bad input.
code=$(api -o e.json -w '%{http_code}' -XDELETE "$base/api/v1/printers/sim/queue/999")
[ "$code" = 404 ] && grep -q '"error"' e.json || fail "unknown entry: $code $(cat e.json)"
e2=$(field "['entry']" < p2.json) e3=$(field "['entry']" < p3.json)
code=$(api -o e.json -w '%{http_code}' -XPOST -d '{"position":7}' "$base/api/v1/printers/sim/queue/$e2/move")
[ "$code" = 400 ] && grep -q '"error"' e.json || fail "bad position: $code $(cat e.json)"
# Reorder there and back: f3 first, then f2 first again.
api -XPOST -d '{"position":1}' "$base/api/v1/printers/sim/queue/$e3/move" | grep -q "\"entry\":$e3,\"file\":\"f3.gcode\",\"position\":1" || fail "move"
api -XPOST -d '{"position":1}' "$base/api/v1/printers/sim/queue/$e2/move" > /dev/null
for _ in 2 3; do wait_idle; api -o /dev/null -XPOST "$base/api/v1/printers/sim/queue/next"; done
wait_idle
cat f1.gcode f2.gcode f3.gcode > all.gcode
same_commands all.gcode sim.log
# A restart keeps the queue; remove empties it.
api -XPOST -d '{"file":"f1.gcode"}' "$base/api/v1/printers/sim/print" > /dev/null
api -XPOST -d '{"file":"f2.gcode"}' "$base/api/v1/printers/sim/print" > q.json
entry=$(field "['entry']" < q.json)
stop
start s.toml
api "$base/api/v1/printers/sim/queue" | grep -q "\"entry\":$entry,\"file\":\"f2.gcode\"" || fail "queue lost in restart"
api -XDELETE "$base/api/v1/printers/sim/queue/$entry" | grep -q '"entries":\[\]' || fail "remove"
stop
echo "print queue: 3 prints in order, exact; kept across a restart; move, remove, 404, 400"
