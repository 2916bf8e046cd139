#!/usr/bin/env bash
# A USB replug, on a pseudo-terminal: a serial printer named by a stable path (a symbolic link, as
# /dev/serial/by-id/… is) whose device vanishes mid-print (the simulator killed, the link gone)
# is marked in error without the daemon crashing or hanging, the print is left interrupted and
# resumable, and when a device appears under the same name again (a new pty) salientd connects
# by itself within seconds; then the interrupted print resumes and a new one prints exactly.
#   replug_e2e.sh SALIENTD SALIENT_SIM WORKDIR
set -euo pipefail
salientd=$1 sim_program=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
sim=
cleanup() {
  [ -n "$sim" ] && kill -9 "$sim" 2>/dev/null || true
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
}
trap cleanup EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
status() { api "$base/api/v1/printers/usb" | field "$1"; }
state_is() { [ "$(status "['state']")" = "$1" ]; }
# plug LOG [SIM_ARGS…]: a simulated board on a new pty, reachable as ./printer (as udev's by-id link would be).
plug() {
  "$sim_program" --link "$work/printer" --advanced-ok --time-scale 0.2 --heat-time-scale 0 --log "$1" "${@:2}" > sim.out 2>&1 &
  sim=$!
  for _ in $(seq 100); do [ -e printer ] && break; sleep 0.05; done
  [ -e printer ] || fail "salient-sim did not make its link: $(cat sim.out)"
}
# unplug: the board gone at once (kill -9: it cannot tidy up), then its name (udev removes it).
unplug() { kill -9 "$sim"; wait "$sim" 2>/dev/null || true; sim=; rm -f printer; }

python3 -c "
print('G28\nG90')
for i in range(4000): print(f'G1 X{20 + (i % 50) * 0.5:.2f} Y{20 + (i // 50) * 0.2:.2f} F3000')" > long.gcode
printf 'G28\nG1 X10 Y10 F3000\nG1 X20 Y20\nG1 X30 Y5\n' > small.gcode
cat > replug.toml <<TOML
[[printers]]
id = "usb"
kind = "serial"
port = "$work/printer"
TOML
plug first.log
start replug.toml
eventually 15 state_is operational > /dev/null || fail "never operational: $(status "")"
echo "connected: $(status "['device']")"
[ "$(api -o up.json -w '%{http_code}' -F "file=@long.gcode" -F print=true "$base/api/files/local")" = 201 ] || fail "upload: $(cat up.json)"
eventually 15 state_is printing > /dev/null || fail "never printing: $(status "")"
sleep 1

unplug
eventually 10 state_is error > /dev/null || fail "not in error after the unplug: $(status "")"
[ "$(status "['last_print']['state']")" = interrupted ] || fail "the print: $(status "['last_print']")"
[ "$(status "['last_print']['resumable']")" = True ] || fail "not resumable: $(status "['last_print']")"
print_id=$(status "['last_print']['id']")
eventually 10 sh -c "curl -s -H 'X-Api-Key: $key' $base/api/v1/printers/usb | grep -q 'is gone'" || fail "no 'gone' message: $(status "")"
echo "unplugged: $(status "['error']"); print $print_id interrupted at $(status "['last_print']['confirmed']")"
[ "$(curl -s "$base/healthz" | field "['status']")" = ok ] || fail "healthz while unplugged"
sleep 3
kill -0 "$pid" || fail "salientd died"
state_is error || fail "not in error while unplugged: $(status "")"

# Plugged in again: a new pty under the same name.
plug second.log
t0=$SECONDS
eventually 8 state_is operational > /dev/null || fail "did not reconnect: $(status "")"
echo "reconnected by itself in $((SECONDS - t0)) s: $(status "['device']")"
api -f -o /dev/null -d "{\"resume\": $print_id}" "$base/api/v1/printers/usb/print" || fail "resume"
eventually 120 state_is operational > /dev/null || fail "the resumed print never ended: $(status "")"
[ "$(status "['last_print']['state']")" = finished ] || fail "resumed print: $(status "['last_print']")"
echo "resumed print $print_id finished: $(status "['last_print']['confirmed']")/$(status "['last_print']['total']")"

# A disconnect asked for is respected: no reconnect while the device is there.
api -f -o /dev/null -X POST "$base/api/v1/printers/usb/disconnect" || fail "disconnect"
eventually 5 state_is disconnected > /dev/null || fail "disconnect: $(status "")"
sleep 3
state_is disconnected || fail "reconnected after a disconnect asked for: $(status "")"
api -f -o /dev/null -X POST "$base/api/v1/printers/usb/connect" || fail "connect"
eventually 10 state_is operational > /dev/null || fail "connect: $(status "")"

# Replugged again, then a print is exact.
unplug
eventually 10 state_is error > /dev/null || fail "not in error after the second unplug: $(status "")"
plug third.log
eventually 8 state_is operational > /dev/null || fail "did not reconnect the second time: $(status "")"
[ "$(api -o up2.json -w '%{http_code}' -F "file=@small.gcode" -F print=true "$base/api/files/local")" = 201 ] || fail "upload: $(cat up2.json)"
eventually 60 sh -c "curl -s -H 'X-Api-Key: $key' $base/api/v1/printers/usb | grep -q '\"file\": *\"small.gcode\"'" > /dev/null || true
eventually 60 state_is operational > /dev/null || fail "the print after the replug never ended"
[ "$(status "['last_print']['state']")" = finished ] || fail "print after the replug: $(status "['last_print']")"
kill -TERM "$sim"; wait "$sim" 2>/dev/null || true; sim=
same_commands small.gcode third.log

# A firmware failure is not a replug: after a thermal runaway (the board halted) the printer stays
# in error for a person to look at, although its device is there.
rm -f printer
eventually 10 state_is error > /dev/null || fail "not in error after the third unplug: $(status "")"
plug fourth.log --faults thermal-runaway-at=40
eventually 8 state_is operational > /dev/null || fail "did not reconnect the third time: $(status "")"
api -f -o /dev/null -F "file=@long.gcode;filename=runaway.gcode" -F print=true "$base/api/files/local" || fail "upload runaway"
eventually 30 state_is error > /dev/null || fail "the thermal runaway: $(status "")"
echo "thermal runaway: $(status "['error']")"
sleep 4
state_is error || fail "reconnected by itself after a firmware failure: $(status "")"
stop
grep -q "terminate called\|Aborted" daemon.log && fail "the daemon aborted"
echo "ok: unplugged mid-print → error, print interrupted and resumable; replugged → connected by itself, resumed, printed"
