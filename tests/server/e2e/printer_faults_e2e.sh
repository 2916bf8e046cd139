#!/usr/bin/env bash
# salientd and printers that go wrong, on the real simulator: a printer that goes silent mid-print
# (kill -STOP) fails the print within the silence limit with a reason, resumes exactly, and a
# SIGTERM stops the daemon within 5 s while it is silent; cancel during a heat-up cuts the heaters
# at once (M108); an emergency stop during a long console command acts at once and is not
# replayed on the next connection; the simulator holds none of the daemon's sockets; a kill -9
# mid-print repeats only a few commands on resume; a deleted job's files are gone; a subscriber to
# "jobs" is told first of the jobs under way.
#   printer_faults_e2e.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
cleanup() {
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
  pkill -CONT -f "salient-sim.*$work" 2>/dev/null || true
}
trap cleanup EXIT
# Limits in seconds are for a Release build; a sanitizer build runs everything slower.
slow=1
grep -q __asan_init "$salientd" && slow=3  # libasan is linked dynamically: its symbol
api() { curl -s -H "X-Api-Key: $key" "$@"; }
printer() { api "$base/api/v1/printers/sim" | field "$1"; }
wait_printer() {  # wait_printer STATE [SECONDS]
  for _ in $(seq $((${2:-60} * 10))); do
    [ "$(printer "['state']")" = "$1" ] && return 0
    sleep 0.1
  done
  fail "printer never became $1: $(api "$base/api/v1/printers/sim")"
}
sim_pid() { pgrep -P "$pid" -f salient-sim | head -1; }
file_commands() { python3 -c "
import sys
for l in open(sys.argv[1]):
    c = l.split(';')[0].strip()
    if c: print(c)" "$1"; }
executed() {  # the simulator's log without the host's own commands
  grep -v -E '^(M110|M115|M155|M105)( |$)' "$1" | sed 's/[[:space:]]*$//' || true
}

# A print of 4,000 short moves after a heat-up, uploaded as OctoPrint clients do.
python3 - > moves.gcode <<'PY'
print("M104 S200\nM140 S60\nG28\nM190 S60\nM109 S200\nG90\nM82\nG92 E0")
e = 0.0
for i in range(4000):
    e += 0.02
    print(f"G1 X{20 + (i % 50) * 0.5:.2f} Y{20 + (i // 50) * 0.2:.2f} E{e:.4f} F1800")
print("M104 S0\nM140 S0\nM84")
PY
upload() {  # upload NAME [print]: the file as NAME, printing it when asked
  api -o upload.json -w '%{http_code}' -F "file=@moves.gcode;filename=$1" ${2:+-F print=true} "$base/api/files/local"
}

# 1. Silent mid-print: fails within the limit, with a reason, and resumes exactly.
sim_config silent.toml "--advanced-ok --emergency-parser --time-scale 0.3 --heat-time-scale 0 --log $PWD/silent1.log"
start silent.toml
wait_printer operational
sim=$(sim_pid)
[ -n "$sim" ] || fail "no simulator"
# The simulator inherited nothing of the daemon's: no socket (the listening one, clients).
sockets=$(ls -l "/proc/$sim/fd" | grep -c socket || true)
[ "$sockets" = 0 ] || fail "salient-sim holds $sockets of salientd's sockets: $(ls -l /proc/$sim/fd)"
[ "$(upload moves.gcode print)" = 201 ] || fail "upload: $(cat upload.json)"
for _ in $(seq 200); do [ "$(printer "['print']['confirmed']")" -gt 500 ] 2>/dev/null && break; sleep 0.1; done
kill -STOP "$sim"
t0=$SECONDS
wait_printer error 30
took=$((SECONDS - t0))
[ "$took" -le $((13 * slow)) ] || fail "a silent printer took $took s to fail the print (limit 10 s)"
reason=$(printer "['last_print']['reason']")
echo "$reason" | grep -q "stopped answering after line" || fail "reason: $reason"
[ "$(printer "['last_print']['state']")" = failed ] || fail "state: $(printer "['last_print']")"
[ "$(printer "['last_print']['resumable']")" = True ] || fail "not resumable: $(printer "['last_print']")"
confirmed=$(printer "['last_print']['confirmed']")
print_id=$(printer "['last_print']['id']")
echo "silent printer: failed after $took s at command $confirmed: $reason"
# Resume on a fresh connection (a new simulator, its own log): the rest of the file, exactly.
sed -i "s|silent1.log|silent2.log|" silent.toml
stop
start silent.toml
wait_printer operational
api -o resume.json -w '%{http_code}' -d "{\"resume\": $print_id}" "$base/api/v1/printers/sim/print" | grep -q 20 \
  || fail "resume: $(cat resume.json)"
wait_printer operational 120
[ "$(printer "['last_print']['state']")" = finished ] || fail "resumed print: $(printer "['last_print']")"
stop  # the simulator writes its log as it stops
file_commands moves.gcode | tail -n +$((confirmed + 1)) > rest.txt
executed silent2.log > resumed.txt
tail -n "$(wc -l < rest.txt)" resumed.txt | cmp -s - rest.txt || fail "the resumed print did not run exactly the rest of the file"
prelude=$(( $(wc -l < resumed.txt) - $(wc -l < rest.txt) ))
[ "$prelude" -le 20 ] || fail "a prelude of $prelude commands"
echo "resume: $prelude prelude commands, then exactly the $(wc -l < rest.txt) left"

# 2. SIGTERM while the printer is silent: the daemon stops within 5 s.
start silent.toml
wait_printer operational
[ "$(upload moves2.gcode print)" = 201 ] || fail "upload: $(cat upload.json)"
sleep 1
sim=$(sim_pid)
kill -STOP "$sim"
sleep 0.5
t0=$(date +%s.%N)
kill -TERM "$pid"
wait "$pid" || fail "salientd exited with an error after SIGTERM"
pid=
python3 -c "import sys; t=float(sys.argv[2])-float(sys.argv[1]); print(f'SIGTERM with a silent printer: stopped in {t:.1f} s'); sys.exit(t > 5 * int(sys.argv[3]))" \
  "$t0" "$(date +%s.%N)" "$slow" || fail "SIGTERM took more than 5 s"
kill -CONT "$sim" 2>/dev/null || true

# 3. Cancel during a real-time heat-up: the heaters are off at once, not after M109 ends.
sim_config heat.toml "--advanced-ok --emergency-parser --autoreport --time-scale 0.05 --heat-time-scale 1 --log $PWD/heat.log"
start heat.toml
wait_printer operational
[ "$(upload heat.gcode print)" = 201 ] || fail "upload: $(cat upload.json)"
for _ in $(seq 100); do
  [ "$(printer "['temperatures']['hotend']['target']")" = 200.0 ] && break
  sleep 0.1
done
sleep 1  # M109 is waiting now
api -o /dev/null -X POST "$base/api/v1/printers/sim/cancel"
t0=$(date +%s.%N)
wait_printer operational 30
python3 -c "import sys; t=float(sys.argv[2])-float(sys.argv[1]); print(f'cancel during heat-up: done in {t:.1f} s'); sys.exit(t > 3 * int(sys.argv[3]))" \
  "$t0" "$(date +%s.%N)" "$slow" || fail "cancel during the heat-up waited for it"
[ "$(printer "['last_print']['state']")" = cancelled ] || fail "state after cancel: $(printer "['last_print']")"
stop
grep -q "^M104 S0" heat.log || fail "no M104 S0 after the cancel"

# 4. Emergency stop during a long console command: at once; nothing replayed after reconnecting.
sim_config dwell.toml "--advanced-ok --emergency-parser --time-scale 1 --heat-time-scale 0 --log $PWD/dwell.log"
start dwell.toml
wait_printer operational
api -o /dev/null -d '{"commands": ["G4 S30"]}' "$base/api/v1/printers/sim/command"
sleep 0.5
api -o /dev/null -X POST "$base/api/v1/printers/sim/emergency-stop"
wait_printer error $((3 * slow))
printer "['error']" | grep -q "emergency stop" || fail "error after the emergency stop: $(printer "['error']")"
api -o /dev/null -X POST "$base/api/v1/printers/sim/connect"
wait_printer operational 20
sleep 1.5
[ "$(printer "['state']")" = operational ] || fail "the emergency stop was replayed on the new connection: $(printer "['error']")"
stop

# 5. kill -9 mid-print: what was saved as confirmed trails what the printer executed by a few commands.
sim_config kill.toml "--advanced-ok --time-scale 0.3 --heat-time-scale 0 --log $PWD/kill.log"
start kill.toml
wait_printer operational
[ "$(upload moves3.gcode print)" = 201 ] || fail "upload: $(cat upload.json)"
for _ in $(seq 200); do [ "$(printer "['print']['confirmed']")" -gt 1500 ] 2>/dev/null && break; sleep 0.1; done
kill -9 "$pid"; wait "$pid" 2>/dev/null || true; pid=
sleep 1  # the simulator stops with the daemon and writes its log
ran=$(executed kill.log | wc -l)
sed -i "s|kill.log|kill2.log|" kill.toml
start kill.toml
saved=$(printer "['last_print']['confirmed']")
repeats=$((ran - saved))
echo "kill -9: the printer had executed $ran commands, $saved were saved as confirmed: $repeats would be repeated"
[ "$repeats" -le 8 ] || fail "$repeats commands would be repeated on resume"
stop

# 6. A deleted job takes its files with it, except those another job still uses.
start
files() { find data/files/objects -type f | wc -l; }
before=$(files)
submit() { api -F "file=@$models/$1" -F "settings=$2" "$base/api/v1/jobs" | field "['id']"; }
a=$(submit cube_binary.ply '{"height": 10}')
b=$(submit cube_binary.ply '{"height": 12}')
for id in $a $b; do
  for _ in $(seq 600); do [ "$(api "$base/api/v1/jobs/$id" | field "['state']")" = done ] && break; sleep 0.2; done
done
with_both=$(files)
[ "$(api -o /dev/null -w '%{http_code}' -X DELETE "$base/api/v1/jobs/$a")" = 204 ] || fail "delete $a"
after_one=$(files)
api -s -f -o /dev/null "$base/api/v1/jobs/$b/gcode" || fail "the other job's G-code went with the first"
[ "$(api -o /dev/null -w '%{http_code}' -X DELETE "$base/api/v1/jobs/$b")" = 204 ] || fail "delete $b"
after_both=$(files)
echo "files: $before before, $with_both with two jobs, $after_one after deleting one, $after_both after both"
[ "$after_one" -lt "$with_both" ] || fail "deleting a job removed no file"
[ "$after_both" = "$before" ] || fail "files left after deleting both jobs: $after_both, $before before"

# 7. Subscribing to "jobs" tells first the jobs that are not finished, then "subscribed".
id=$(submit spot.obj '{"height": 30, "saliency": "spectral", "up": "y"}')
for _ in $(seq 300); do [ "$(api "$base/api/v1/jobs/$id" | field "['state']")" = running ] && break; sleep 0.1; done
SALIENT_SERVER=$base SALIENT_API_KEY=$key timeout 3 "$salient" events jobs > jobs-events.jsonl 2>/dev/null || true
head -1 jobs-events.jsonl | field "['type'] + ' ' + d['data']['id']" | grep -qx "job $id" \
  || fail "no snapshot of the running job first: $(head -3 jobs-events.jsonl)"
sed -n 2p jobs-events.jsonl | grep -q '"subscribed"' || fail "not 'subscribed' after the snapshot: $(head -3 jobs-events.jsonl)"
stop
# 8. Between prints, a board that stops answering is noticed; a daemon connecting to a silent one stops at once.
sim_config idle.toml "--time-scale 0 --heat-time-scale 0 --faults silent-after=3"
start idle.toml
wait_printer operational
t0=$SECONDS
wait_printer error 40
echo "idle printer gone silent: error after $((SECONDS - t0)) s: $(printer "['error']")"
printer "['error']" | grep -q "stopped answering" || fail "error: $(printer "['error']")"
stop
python3 -c "
import socket, time
s = socket.socket(); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1); s.bind(('127.0.0.1', 0)); s.listen(4)
open('bridge.port', 'w').write(str(s.getsockname()[1]))
conns = []
end = time.time() + 60
while time.time() < end:
    s.settimeout(1)
    try: conns.append(s.accept()[0])  # accepts, reads nothing, says nothing
    except socket.timeout: pass
" &
bridge=$!
for _ in $(seq 50); do [ -s bridge.port ] && break; sleep 0.1; done
cat > tcp.toml <<TOML
[[printers]]
id = "sim"
kind = "tcp"
port = "127.0.0.1:$(cat bridge.port)"
TOML
start tcp.toml
sleep 1  # the handshake waits for an answer that never comes
[ "$(printer "['state']")" = connecting ] || fail "not connecting: $(printer "['state']")"
t0=$(date +%s.%N)
kill -TERM "$pid"
wait "$pid" || fail "salientd exited with an error after SIGTERM"
pid=
kill "$bridge" 2>/dev/null || true
python3 -c "import sys; t=float(sys.argv[2])-float(sys.argv[1]); print(f'SIGTERM while connecting to a silent board (and a job slicing): stopped in {t:.1f} s'); sys.exit(t > 5 * int(sys.argv[3]))" \
  "$t0" "$(date +%s.%N)" "$slow" || fail "SIGTERM waited for the handshake"
echo "ok: printer faults end to end"
