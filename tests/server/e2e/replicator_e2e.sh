#!/usr/bin/env bash
# salientd with a simulated Replicator 2X, end to end: the replicator2x profile makes the printer
# speak s3g to a simulated Sailfish board (lost replies and buffer-full storms on the wire); a job
# sliced for it prints, and the board executed exactly the x3g that `salient export-x3g` (= gpx)
# writes for the job's G-code; an OctoPrint upload prints through the same routes; a cancel ends
# the print with the heaters off.
#   replicator_e2e.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
printer() { api "$base/api/v1/printers/r2x" | field "$1"; }
wait_printer() {  # wait_printer STATE [SECONDS]
  for _ in $(seq $((${2:-120} * 10))); do
    [ "$(printer "['state']")" = "$1" ] && return 0
    sleep 0.1
  done
  fail "printer never became $1: $(api "$base/api/v1/printers/r2x")"
}
wait_print() {  # wait_print STATE [AFTER_ID]: the last print (a later one than AFTER_ID) ended so
  for _ in $(seq 3000); do
    [ "$(printer "['last_print']['state'] if d['last_print'] and d['last_print']['id'] != ${2:-0} else ''")" = "$1" ] && return 0
    sleep 0.1
  done
  fail "the print never became $1: $(api "$base/api/v1/printers/r2x")"
}
# executed_is X3G LOG: the board's log (hex payloads, a line each) is the file's actions, once each.
executed_is() {
  python3 - "$1" "$2" <<'PY'
import sys
want = open(sys.argv[1], "rb").read().hex()
got = "".join(l.strip() for l in open(sys.argv[2]))
if got != want:
    i = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
    print(f"log {len(got) // 2} bytes, x3g {len(want) // 2}; first difference at byte {i // 2}")
    sys.exit(1)
print(f"{sys.argv[1]}: {len(want) // 2} bytes of actions executed, exactly once each")
PY
}

cat > r2x.toml <<TOML
[[printers]]
id = "r2x"
kind = "sim"
profile = "replicator2x"
sim_args = "--firmware sailfish --time-scale 0 --heat-time-scale 0 --log $PWD/r2x.log --faults drop-reply=0.002,full-storm=0.01,seed=5"
TOML
start r2x.toml
wait_printer operational
[ "$(printer "['protocol']")" = s3g ] || fail "protocol: $(printer "['protocol']")"
printer "['firmware']" | grep -q Sailfish || fail "firmware: $(printer "['firmware']")"

# 1. A job sliced for the Replicator, printed on it.
id=$(api -F "file=@$models/stanford-bunny.obj" -F 'settings={"printer": "replicator2x", "up": "y", "height": 8}' \
  "$base/api/v1/jobs" | field "['id']")
for _ in $(seq 1200); do
  s=$(api "$base/api/v1/jobs/$id" | field "['state']")
  [ "$s" = done ] && break
  case $s in failed|cancelled) fail "job $id ended $s";; esac
  sleep 0.1
done
[ "$s" = done ] || fail "job $id never done"
api -f -o job.gcode "$base/api/v1/jobs/$id/gcode" || fail "gcode download"
grep -q "M132 X Y Z A B" job.gcode || fail "the job's G-code is not the Replicator profile's"
# The daemon names the build after the printer: so does export-x3g for an output called r2x.x3g.
"$salient" export-x3g job.gcode -o r2x.x3g > export.out || fail "export-x3g: $(cat export.out)"
api -f -o print.json -d "{\"job\": \"$id\"}" "$base/api/v1/printers/r2x/print" || fail "print: $(cat print.json)"
wait_print finished
[ "$(printer "['last_print']['confirmed'] == d['last_print']['total']")" = True ] || fail "print not complete"
eventually 60 executed_is r2x.x3g r2x.log || fail "the board did not execute the job's x3g exactly once"

# 2. The same G-code uploaded as OctoPrint clients do, printed on the first printer: r2x.
first=$(printer "['last_print']['id']")
code=$(api -o upload.json -w '%{http_code}' -F "file=@job.gcode;filename=part.gcode" -F print=true "$base/api/files/local")
[ "$code" = 201 ] || fail "upload: $code $(cat upload.json)"
wait_print finished "$first"
cat r2x.x3g r2x.x3g > twice.x3g
eventually 60 executed_is twice.x3g r2x.log || fail "the upload's print is not the x3g again"

# A file sliced for a Marlin printer is refused before it starts, naming the first command the
# Replicator cannot take: nothing is silently left out of a print.
printf 'G28\nM204 S800\nG1 X10 Y10 F3000\n' > marlin.gcode
code=$(api -o upload.json -w '%{http_code}' -F "file=@marlin.gcode" "$base/api/files/local")
[ "$code" = 201 ] || fail "upload: $code $(cat upload.json)"
code=$(api -o refused.json -w '%{http_code}' -d '{"file": "marlin.gcode"}' "$base/api/v1/printers/r2x/print")
[ "$code" = 422 ] || fail "a Marlin file on the Replicator: $code $(cat refused.json)"
[ "$(field "['error']['code']" < refused.json)" = not_x3g ] || fail "$(cat refused.json)"
field "['error']['message']" < refused.json | grep -q "line 2 'M204 S800' cannot be printed over s3g" \
  || fail "$(cat refused.json)"
[ "$(printer "['state']")" = operational ] || fail "the refusal left the printer $(printer "['state']")"

# 3. Cancel mid-print (real-time moves): the print ends cancelled, the board's heaters off.
stop
sed -i 's/--time-scale 0 --heat-time-scale 0/--time-scale 1 --heat-time-scale 0/; s/r2x.log/r2x-cancel.log/' r2x.toml
start r2x.toml
wait_printer operational
api -f -o print.json -d "{\"job\": \"$id\"}" "$base/api/v1/printers/r2x/print" || fail "print: $(cat print.json)"
for _ in $(seq 300); do [ "$(printer "['print']['confirmed']")" -gt 50 ] 2>/dev/null && break; sleep 0.1; done
api -f -o cancel.json -X POST "$base/api/v1/printers/r2x/cancel" || fail "cancel: $(cat cancel.json)"
t0=$SECONDS
wait_print cancelled
echo "cancelled in $((SECONDS - t0)) s"
heaters_off() {  # the targets the board reports (polled by the link) are 0
  [ "$(printer "['temperatures']['hotend']['target'] in (0, None) and d['temperatures']['bed']['target'] in (0, None)")" = True ]
}
eventually 15 heaters_off || fail "heaters still on after the cancel: $(printer "['temperatures']")"

# 4. The board resets mid-print (after 3,000 actions: before the middle of the x3g, as the check of
# the resumed rest below needs): the print fails saying so, resumable from what had started; on
# the next connection (a fresh board, no fault) the resume runs the prelude and the rest of the x3g,
# not the whole file again.
stop
sed -i 's/--time-scale 1 --heat-time-scale 0/--time-scale 0 --heat-time-scale 0/; s/r2x-cancel.log/r2x-reset.log/' r2x.toml
sed -i 's/--faults [^"]*/--faults reset-at=3000/' r2x.toml
start r2x.toml
wait_printer operational
before=$(printer "['last_print']['id']")
api -f -o print.json -d "{\"job\": \"$id\"}" "$base/api/v1/printers/r2x/print" || fail "print: $(cat print.json)"
wait_print failed "$before"
printer "['last_print']['reason']" | grep -qi "reset" || fail "reason: $(printer "['last_print']")"
[ "$(printer "['last_print']['resumable']")" = True ] || fail "not resumable: $(printer "['last_print']")"
failed=$(printer "['last_print']['id']")
confirmed=$(printer "['last_print']['confirmed']")
[ "$confirmed" -gt 1000 ] || fail "resumable from command $confirmed only, after 3,000 actions had run"
# A failed print leaves the printer in error until it is connected again, as for Marlin: here the
# daemon restarts with the board's fault gone.
[ "$(printer "['state']")" = error ] || fail "after the reset: $(printer "['state']")"
stop
sed -i 's/ --faults [^"]*//; s/r2x-reset.log/r2x-resume.log/' r2x.toml
start r2x.toml
wait_printer operational
api -f -o resume.json -d "{\"resume\": $failed}" "$base/api/v1/printers/r2x/print" || fail "resume: $(cat resume.json)"
wait_print finished "$failed"
[ "$(printer "['last_print']['confirmed'] == d['last_print']['total']")" = True ] || fail "resumed print not complete"
resumed_rest() {
  python3 - r2x.x3g r2x-resume.log <<'PY'
import sys
want = open(sys.argv[1], "rb").read()
got = b"".join(bytes.fromhex(l.strip()) for l in open(sys.argv[2]))
half = want[len(want) // 2:]
if not got.endswith(half) or got.count(half) != 1:
    sys.exit(f"the resumed print does not end with the rest of the x3g ({len(got)} bytes)")
if len(got) >= len(want):
    sys.exit(f"the resumed print ran {len(got)} bytes: the whole file again ({len(want)})")
print(f"resumed: {len(got)} bytes of the x3g's {len(want)}, ending with its rest")
PY
}
eventually 60 resumed_rest || fail "the resumed print is not the rest of the x3g"
echo "replicator e2e: ok"
