#!/usr/bin/env bash
# The print history as Moonraker keeps it, on the real simulator: a finished print used the
# filament the file's analysis says (our estimator's count against the printer's, two code paths);
# a paused then cancelled one used part of it, its pause out of its printing time; the totals per
# printer and for the farm add them up, survive a restart, and need a key.
#   history_e2e.sh SALIENTD SALIENT MODELS WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
printer() { api "$base/api/v1/printers/sim" | field "$1"; }
wait_idle() {
  for _ in $(seq 1200); do [ "$(printer "['state']")" = operational ] && return 0; sleep 0.1; done
  fail "printer never idle"
}
eval_json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
near() { python3 -c "import sys; a, b, tol = map(float, sys.argv[1:]); sys.exit(abs(a - b) > tol)" "$@"; }

"$salient" slice "$models/cube_binary.ply" --height 10 -o cube.gcode > /dev/null || fail "slice"
sim_config s.toml "--advanced-ok --time-scale 0.03 --heat-time-scale 0 --log $PWD/sim.log"
start s.toml
wait_idle
api -o /dev/null -F "file=@cube.gcode;filename=cube.gcode" "$base/api/files/local"
want=$(api "$base/api/files/local/cube.gcode" | field "['gcodeAnalysis']['filament']['tool0']['length']")

# 1. Finished: all of the file's filament.
api -o /dev/null -XPOST -d '{"file":"cube.gcode"}' "$base/api/v1/printers/sim/print"
wait_idle
api "$base/api/v1/printers/sim/prints" > prints.json
[ "$(field "['prints'][0]['state']" < prints.json)" = finished ] || fail "not finished: $(cat prints.json)"
got=$(field "['prints'][0]['filament_mm']" < prints.json)
near "$got" "$want" 1e-6 || fail "filament of a finished print: $got mm, the file's analysis says $want"
full=$got

# 2. Paused 1.5 s, then cancelled: part of the filament; the pause is out of the printing time.
api -o /dev/null -XPOST -d '{"file":"cube.gcode"}' "$base/api/v1/printers/sim/print"
for _ in $(seq 300); do
  [ "$(api "$base/api/v1/printers/sim" | eval_json "(d['print'] or {}).get('confirmed', 0) > 300")" = True ] && break
  sleep 0.05
done
api -o /dev/null -XPOST "$base/api/v1/printers/sim/pause"
mid=$(printer "['print']['filament_mm']")
python3 -c "import sys; sys.exit(not (0 < $mid < $full))" || fail "filament while printing: $mid of $full"
sleep 1.5
api -o /dev/null -XPOST "$base/api/v1/printers/sim/cancel"
wait_idle
api "$base/api/v1/printers/sim/prints" > prints.json
[ "$(field "['prints'][0]['state']" < prints.json)" = cancelled ] || fail "not cancelled: $(cat prints.json)"
part=$(field "['prints'][0]['filament_mm']" < prints.json)
python3 -c "import sys; sys.exit(not ($mid <= $part < $full))" || fail "filament of the cancelled print: $part (paused at $mid, all $full)"
[ "$(eval_json "d['prints'][0]['paused_seconds'] >= 1.4" < prints.json)" = True ] || fail "paused_seconds: $(cat prints.json)"
[ "$(eval_json "abs(d['prints'][0]['duration'] - d['prints'][0]['paused_seconds'] - d['prints'][0]['print_duration']) < 1e-6" < prints.json)" = True ] ||
  fail "print_duration is not duration less pauses: $(cat prints.json)"

# 3. Totals, per printer and for the farm; kept across a restart.
check_totals() {
  api "$base/api/v1/printers/sim/history/totals" > t.json
  [ "$(eval_json "(d['prints'], d['finished'], d['cancelled'], d['failed'])" < t.json)" = "(2, 1, 1, 0)" ] ||
    fail "totals: $(cat t.json)"
  near "$(field "['filament_mm']" < t.json)" "$(python3 -c "print($full + $part)")" 1e-6 || fail "filament total: $(cat t.json)"
  [ "$(eval_json "d['print_seconds'] < d['total_seconds'] and d['longest_seconds'] <= d['total_seconds']" < t.json)" = True ] ||
    fail "times: $(cat t.json)"
  api "$base/api/v1/history/totals" > all.json
  [ "$(eval_json "d['prints'] == 2 and d['printers']['sim']['prints'] == 2" < all.json)" = True ] || fail "farm totals: $(cat all.json)"
}
check_totals
stop
start s.toml
check_totals
code=$(curl -s -o /dev/null -w '%{http_code}' "$base/api/v1/history/totals")
[ "$code" = 401 ] || fail "totals without a key: $code"
code=$(api -o /dev/null -w '%{http_code}' "$base/api/v1/printers/nope/history/totals")
[ "$code" = 404 ] || fail "totals of an unknown printer: $code"
stop
echo "history: filament of a finished print = the file's analysis ($full mm); a paused+cancelled one $part mm, pause out of its print time; totals per printer and farm, kept across a restart"
