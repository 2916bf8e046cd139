#!/usr/bin/env bash
# OctoPrint's REST as farm managers (FDM Monster) and phone apps (OctoPod) call it, against
# salientd with a simulated printer (the calls and checks are in octoprint_rest.py): a
# select+print of a file in a folder that the simulator executes exactly, the job with its
# analysis, printer controls as G-code (and 400 for bad values, 409 when not operational),
# folders, move/copy, delete, Range downloads, hostile paths, "files" events, settings kept
# across a restart, system info and commands, connection; then on a slow printer: 409 for
# deleting what prints, prints queued on a busy printer, restart of a paused print.
#   octoprint_rest_e2e.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
events=
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; [ -n "$events" ] && kill "$events" 2>/dev/null || true' EXIT
py() { /usr/bin/python3 "$here/octoprint_rest.py" "$1" "$base" "$key" "${@:2}" || fail "phase $1"; }
"$salient" slice "$models/cube_binary.ply" --height 6 -o cube.gcode > /dev/null

sim_config sim.toml "--advanced-ok --emergency-parser --autoreport --time-scale 0 --heat-time-scale 0 --log $PWD/sim.log"
start sim.toml
eventually 60 curl -s -f -H "X-Api-Key: $key" "$base/api/printer" > /dev/null || fail "never operational"
py print "$PWD/cube.gcode"
finished() {
  curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim" | python3 -c "
import json, sys
d = json.load(sys.stdin); p = d['last_print'] or {}
sys.exit(0 if d['state'] == 'operational' and p.get('state') == 'finished' and p.get('file') == 'prints/cube.gcode' else 1)"
}
eventually 300 finished > /dev/null || fail "the select+print never finished"
same_commands cube.gcode sim.log
py job "$PWD/cube.gcode"
py controls "$PWD/sim.log"
SALIENT_SERVER=$base SALIENT_API_KEY=$key "$salient" events files > events.jsonl 2> events.err &
events=$!
for _ in $(seq 200); do grep -q '"subscribed"' events.jsonl 2>/dev/null && break; sleep 0.05; done
grep -q '"subscribed"' events.jsonl || fail "no subscription to files: $(cat events.err)"
py files
sleep 0.5
kill "$events"; events=
py events "$PWD/events.jsonl"
py settings
py system
py connection
stop
start sim.toml
py settings_kept
stop

# A printer slow enough to be caught printing.
/usr/bin/python3 -c "
for i in range(4000): print(f'G1 X{10 + i % 80} Y{10 + i % 7} F3000')" > long.gcode
sim_config slow.toml "--advanced-ok --emergency-parser --time-scale 0.2 --heat-time-scale 0 --log $PWD/slow.log"
start slow.toml slow-data
eventually 60 curl -s -f -H "X-Api-Key: $key" "$base/api/printer" > /dev/null || fail "slow printer never operational"
py busy "$PWD/long.gcode"
stop
echo "ok: OctoPrint REST for farm managers and phone apps"
