#!/usr/bin/env bash
# `salient print` end to end against salient-sim on a pseudo-terminal:
#   print_check.sh SALIENT SIM WORKDIR MODE
# MODE full: a sliced model prints completely and the simulator executed exactly its commands.
# MODE interrupt: Ctrl-C mid-print cancels: exit 130, and the last commands run are the cancel
#   G-code (heaters off, head lifted, motors off).
# MODE disconnect: the cable is pulled; exit 4 and the message gives the --resume-from count;
#   resuming with it on a fresh printer runs the prelude and then exactly the rest of the file.
set -euo pipefail
salient=$1 sim=$2 work=$3 mode=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work"
printf 'M104 S200\nG28 ; home\n;LAYER_CHANGE\n' > p.gcode
for i in $(seq 1 3000); do echo "G1 X$((i % 100)) Y$((i % 37)) E0.01 F3000"; done >> p.gcode
simargs=(--log sim.log)
case $mode in
  interrupt) simargs+=(--time-scale 0.2) ;;  # 3000 short moves: several seconds
  disconnect) simargs+=(--faults disconnect-after=1000) ;;
esac
"$sim" "${simargs[@]}" > sim.out 2>/dev/null &
simpid=$!
trap 'kill $simpid 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -s sim.out ] && break; sleep 0.05; done
dev=$(head -1 sim.out)
status=0
case $mode in
  full)
    "$salient" print p.gcode --port "$dev" --quiet > out.txt || status=$?
    [ $status -eq 0 ] || { echo "exit $status"; cat out.txt; exit 1; }
    kill $simpid; wait $simpid || true
    sed 's/;.*//;s/ *$//' p.gcode | grep -v '^$' > expected.txt
    tail -n +3 sim.log | diff -q - expected.txt
    grep -q "printed 3002 commands" out.txt ;;
  interrupt)
    "$salient" print p.gcode --port "$dev" --quiet > out.txt &
    pid=$!
    sleep 1.5
    kill -INT $pid
    wait $pid || status=$?
    [ $status -eq 130 ] || { echo "exit $status, expected 130"; cat out.txt; exit 1; }
    grep -q "cancelled after" out.txt
    kill $simpid; wait $simpid || true
    tail -n 7 sim.log | tr '\n' '|' | grep -qx 'M104 S0|M140 S0|M107|G91|G1 Z5 F600|G90|M84|' ;;
  disconnect)
    "$salient" print p.gcode --port "$dev" --quiet > out.txt || status=$?
    [ $status -eq 4 ] || { echo "exit $status, expected 4"; cat out.txt; exit 1; }
    grep -Eq "disconnected after 99[0-9] of 3002 commands were confirmed" out.txt
    from=$(grep -Eo -- "--resume-from [0-9]+" out.txt | cut -d' ' -f2)
    "$sim" --log resumed.log > sim2.out 2>/dev/null &
    sim2=$!
    for _ in $(seq 100); do [ -s sim2.out ] && break; sleep 0.05; done
    "$salient" print p.gcode --port "$(head -1 sim2.out)" --quiet --resume-from "$from" > out2.txt
    kill $sim2; wait $sim2 || true
    sed 's/;.*//;s/ *$//' p.gcode | grep -v '^$' | tail -n +$((from + 1)) > rest.txt
    tail -n "$(wc -l < rest.txt)" resumed.log | diff -q - rest.txt
    grep -q "^M109 S200$" resumed.log  # the prelude heated up again before going on
    grep -q "printed 3002 commands" out2.txt ;;
esac
echo "ok: $mode"
