#!/usr/bin/env bash
# `salient print FILE.x3g --protocol s3g` end to end against salient-sim --firmware sailfish:
#   print_s3g_check.sh SALIENT SIM WORKDIR MODE
# The x3g is GPX's (gpx -I -q -m r2x) for slicer-shaped G-code. The simulator logs each executed
# action's payload in hex: the log is compared with the file's bytes.
# MODE full: noise both ways and lost replies; the whole file runs, each action once.
# MODE gcode: the G-code file itself, translated on the fly: the board runs what gpx wrote.
# MODE interrupt: Ctrl-C mid-print: exit 130, the last actions are heaters off and motors off.
# MODE reset: the board resets mid-print: exit 1 with a --resume-from count; resuming on a fresh
#   board prints exactly the rest of the file after the resume prelude.
set -euo pipefail
salient=$1 sim=$2 work=$3 mode=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work"
{
  printf 'M73 P0\nM104 S210 T0\nG162 X Y F2500\nG161 Z F1100\nG92 X152 Y75 Z0 A0 B0\nM109 S210 T0\nG1 Z0.3 F1000\n'
  for i in $(seq 1 3000); do echo "G1 X$((i % 60 - 30)) Y$((i % 37 - 18)) E$((i / 100)).$((i % 100)) F3000"; done
  printf 'M73 P100\nM104 S0 T0\nM18\n'
} > p.gcode
gpx -I -q -m r2x p.gcode p.x3g
# The file's actions, one hex payload a line, as the simulator logs them.
python3 - > actions.txt <<'PY'
import struct
data = open('p.x3g', 'rb').read()
fixed = {131: 8, 132: 8, 133: 5, 134: 2, 135: 6, 137: 2, 139: 25, 140: 21, 141: 6, 142: 26, 144: 2,
         150: 3, 154: 2, 155: 32, 152: 2, 145: 3, 146: 6, 147: 6, 148: 5, 151: 2, 156: 1, 157: 12, 158: 5}
i = 0
while i < len(data):
    a = data[i]
    if a == 136: n = 4 + data[i + 3]
    elif a == 153: n = data.index(0, i + 5) - i + 1
    elif a == 149: n = data.index(0, i + 5) - i + 1
    else: n = fixed[a]
    print(data[i:i + n].hex()); i += n
PY
simargs=(--firmware sailfish --log sim.log --time-scale 0.0001 --heat-time-scale 0.001)
case $mode in
  full) simargs+=(--faults noise=0.02,reply-noise=0.02,drop-reply=0.002,full-storm=0.01,seed=5) ;;
  interrupt) simargs=(--firmware sailfish --log sim.log --time-scale 0.02 --heat-time-scale 0.001) ;;
  reset) simargs=(--firmware sailfish --log sim.log --time-scale 0.1 --heat-time-scale 0.001 --faults reset-at=1500) ;;
esac
"$sim" "${simargs[@]}" > sim.out 2>/dev/null &
simpid=$!
trap 'kill $simpid 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -s sim.out ] && break; sleep 0.05; done
dev=$(head -1 sim.out)
status=0
total=$(wc -l < actions.txt)
case $mode in
  full)
    "$salient" print p.x3g --port "$dev" --protocol s3g --quiet --timeout 0.25 > out.txt || status=$?
    [ $status -eq 0 ] || { echo "exit $status"; cat out.txt; exit 1; }
    sleep 0.3; kill $simpid; wait $simpid || true
    diff -q sim.log actions.txt
    grep -q "printed $total commands" out.txt ;;
  gcode)
    "$salient" print p.gcode --port "$dev" --protocol s3g --quiet > out.txt || status=$?
    [ $status -eq 0 ] || { echo "exit $status"; cat out.txt; exit 1; }
    sleep 0.3; kill $simpid; wait $simpid || true
    diff -q sim.log actions.txt
    grep -q "printed $(grep -cv '^ *$' p.gcode) commands" out.txt ;;
  interrupt)
    "$salient" print p.x3g --port "$dev" --protocol s3g --quiet > out.txt &
    pid=$!
    sleep 1.5
    kill -INT $pid
    wait $pid || status=$?
    [ $status -eq 130 ] || { echo "exit $status, expected 130"; cat out.txt; exit 1; }
    grep -q "cancelled after" out.txt
    sleep 0.3; kill $simpid; wait $simpid || true
    tail -n 3 sim.log | tr '\n' '|' | grep -qx '880003020000|88001f020000|891f|'
    n=$(($(wc -l < sim.log) - 3))
    head -n $n sim.log | diff -q - <(head -n $n actions.txt) ;;
  reset)
    "$salient" print p.x3g --port "$dev" --protocol s3g --quiet > out.txt || status=$?
    [ $status -eq 1 ] || { echo "exit $status, expected 1"; cat out.txt; exit 1; }
    grep -q "failed after .* commands were confirmed: the printer reset" out.txt
    from=$(grep -Eo -- "--protocol s3g --resume-from [0-9]+" out.txt | grep -Eo '[0-9]+$')
    [ "$from" -gt 0 ] && [ "$from" -le 1500 ]
    kill $simpid; wait $simpid || true
    "$sim" --firmware sailfish --log resumed.log --time-scale 0.0001 --heat-time-scale 0.001 > sim2.out 2>/dev/null &
    sim2=$!
    for _ in $(seq 100); do [ -s sim2.out ] && break; sleep 0.05; done
    "$salient" print p.x3g --port "$(head -1 sim2.out)" --protocol s3g --quiet --resume-from "$from" > out2.txt
    sleep 0.3; kill $sim2; wait $sim2 || true
    tail -n +$((from + 1)) actions.txt > rest.txt
    tail -n "$(wc -l < rest.txt)" resumed.log | diff -q - rest.txt
    head -n 3 resumed.log | grep -qx '88000302d200'  # the prelude set the nozzle to 210 °C again
    grep -q "printed $total commands" out2.txt ;;
esac
echo "ok: $mode"
