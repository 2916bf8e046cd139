#!/usr/bin/env bash
# FDM Monster itself (npm @fdm-monster/server 2.1.1 on Node 22, installed from npm's registry by
# deploy/install-fdm-monster.sh) with salientd added to it as an OctoPrint printer: through FDM
# Monster's own REST API (/api/v2) the printer is added by URL + API key (which runs its
# connection test), a G-code is uploaded through FDM Monster to salientd and printed on the
# simulator, and FDM Monster's print-job history must show the print start, progress and
# COMPLETE (it completes a job only on a `current` with flags.finishing), then a second print
# cancelled (flags.cancelling: FAILED, "Cancelled").
# Exit 77 (skipped) only when npm's registry cannot be reached to install it.
#   fdm_monster_test.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)

set +e
fdm_dir=$(bash "$root/deploy/install-fdm-monster.sh")
status=$?
set -e
if [ "$status" = 77 ]; then echo "SKIP: npm's registry cannot be reached; FDM Monster not installed"; exit 77; fi
[ "$status" = 0 ] || { echo "FAIL: deploy/install-fdm-monster.sh exited $status"; exit 1; }

rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$root/tests/support/salientd.sh"
fdm_pid=
cleanup() {
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
  [ -n "$fdm_pid" ] && kill "$fdm_pid" 2>/dev/null || true
}
trap cleanup EXIT
fdm_fail() { echo "FAIL: $*"; echo "--- FDM Monster log:"; grep -v '^    at ' fdm.log | tail -40; fail "$*"; }

# A print of the cube at a tenth of real time: about half a minute, so FDM Monster's socket
# (a `current` every second at throttle 2) and its 10 s REST poll both see it printing.
sim_config sim.toml "--advanced-ok --emergency-parser --autoreport --time-scale 0.1 --heat-time-scale 0.01 --log $PWD/sim.log"
start sim.toml
"$salient" slice "$models/cube_binary.ply" --height 10 -o fdm-cube.gcode > /dev/null

fdm_port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
fdm=http://127.0.0.1:$fdm_port/api/v2
SERVER_PORT=$fdm_port DATABASE_PATH=$PWD/fdm-db MEDIA_PATH=$PWD/fdm-media OVERRIDE_LOGIN_REQUIRED=false \
  "$fdm_dir/run-fdm-monster" > fdm.log 2>&1 &
fdm_pid=$!
for _ in $(seq 300); do curl -sf "$fdm/test" > /dev/null && break; sleep 0.2; done
curl -sf "$fdm/test" > /dev/null || fdm_fail "FDM Monster did not start"
curl -sf -X POST -H 'Content-Type: application/json' "$fdm/first-time-setup/complete" \
  -d '{"loginRequired": false, "registration": false, "rootUsername": "root", "rootPassword": "salient-test-1"}' \
  > /dev/null || fdm_fail "first-time setup"

# Add salientd as an OctoPrint printer (printerType 0): without forceSave FDM Monster validates
# the key (32–43 URL-safe characters) and calls GET /api/version with it first.
body=$(python3 -c 'import json, sys; print(json.dumps({"name": "salient-sim", "printerURL": sys.argv[1],
  "apiKey": sys.argv[2], "printerType": 0, "enabled": True}))' "$base" "$key")
code=$(curl -s -o printer.json -w '%{http_code}' -X POST -H 'Content-Type: application/json' "$fdm/printer" -d "$body")
[ "$code" = 200 ] || fdm_fail "FDM Monster refused the printer ($code): $(cat printer.json)"
id=$(field "['id']" < printer.json)

# FDM Monster's socket to salientd: passive login, currentuser, /sockjs/websocket with auth; its
# cached `current` must come to show an operational printer.
socket_operational() {
  curl -sf "$fdm/printer/$id/socket" | python3 -c '
import json, sys
d = json.load(sys.stdin) or {}
p = ((d.get("current") or {}).get("payload") or {})
sys.exit(0 if ((p.get("state") or {}).get("flags") or {}).get("operational") else 1)'
}
eventually 90 socket_operational > /dev/null || fdm_fail "FDM Monster never saw the printer operational: $(curl -s "$fdm/printer/$id/socket")"

# Upload through FDM Monster (it forwards to POST /api/files/local), then print it
# (OctoprintApi.startPrint: POST /api/files/local/PATH {"command": "select", "print": true}).
code=$(curl -s -o upload.json -w '%{http_code}' -F "startPrint=false" -F "file=@fdm-cube.gcode" "$fdm/printer-files/$id/upload")
[ "$code" = 200 ] || fdm_fail "upload through FDM Monster ($code): $(cat upload.json)"
curl -s "-H" "X-Api-Key: $key" "$base/api/files/local/fdm-cube.gcode" | grep -q '"fdm-cube.gcode"' ||
  fdm_fail "the upload did not reach salientd"

# job STATUS [MIN_PROGRESS] [REASON]: FDM Monster's newest job of the file has that status.
job() {
  curl -sf "$fdm/print-jobs/search" | python3 -c '
import json, sys
want, low, reason = sys.argv[1], float(sys.argv[2]), sys.argv[3]
jobs = [j for j in json.load(sys.stdin) if j.get("fileName") == "fdm-cube.gcode"]
jobs.sort(key=lambda j: j["id"])
j = jobs[-1] if jobs else {}
print(json.dumps({k: j.get(k) for k in ("id", "status", "progress", "statusReason", "statistics")}))
ok = j.get("status") == want and (j.get("progress") or 0) >= low and reason in json.dumps(j)
sys.exit(0 if ok else 1)' "$1" "${2:-0}" "${3:-}"
}
jobs() { curl -s "$fdm/print-jobs/search"; }
code=$(curl -s -o print.json -w '%{http_code}' -X POST -H 'Content-Type: application/json' \
  "$fdm/printer-files/$id/print" -d '{"filePath": "fdm-cube.gcode"}')
[ "$code" = 200 ] || fdm_fail "print through FDM Monster ($code): $(cat print.json)"
eventually 60 job PRINTING > /dev/null || fdm_fail "FDM Monster never marked the print started: $(jobs)"
eventually 60 job PRINTING 1 || fdm_fail "FDM Monster saw no progress: $(jobs)"
eventually 120 job COMPLETED 100 || fdm_fail "FDM Monster never saw the print finish (flags.finishing): $(jobs)"
same_commands fdm-cube.gcode sim.log

# A second print, cancelled from FDM Monster (OctoprintApi.cancelPrint: POST /api/job cancel).
code=$(curl -s -o print.json -w '%{http_code}' -X POST -H 'Content-Type: application/json' \
  "$fdm/printer-files/$id/print" -d '{"filePath": "fdm-cube.gcode"}')
[ "$code" = 200 ] || fdm_fail "second print ($code): $(cat print.json)"
eventually 60 job PRINTING 1 > /dev/null || fdm_fail "the second print never showed progress: $(jobs)"
code=$(curl -s -o cancel.json -w '%{http_code}' -X POST "$fdm/printer/$id/job/cancel")
[ "$code" = 200 ] || fdm_fail "cancel through FDM Monster ($code): $(cat cancel.json)"
eventually 60 job FAILED 0 Cancelled || fdm_fail "FDM Monster never saw the cancel (flags.cancelling): $(jobs)"
echo "PASS: FDM Monster added salientd, printed a file to completion and cancelled another"
