#!/usr/bin/env bash
# s3g streaming to the simulated Sailfish board over a pseudo-terminal: ours (`salient print
# --protocol s3g`) against GPX's `gpx -s` on the same G-code (whose x3g is byte for byte ours) and
# the same simulator, with no line-rate limit and at an emulated 115,200 baud, against the wire's
# own packet rate. Each run's board log is checked against the x3g (every action once).
# Usage: tests/bench/s3g_bench.sh [BUILD_DIR] [LINES]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
lines=${2:-8000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
models=$(cd ../shared/models && pwd)
"$build/clients/salient" slice "$models/stanford-bunny.obj" --printer replicator2x --up y --height 15 \
  -o "$work/full.gcode" >/dev/null 2>&1
head -n "$lines" "$work/full.gcode" > "$work/f.gcode"
actions=$("$build/clients/salient" export-x3g "$work/f.gcode" -o "$work/f.x3g" | sed -n 's/.*: \([0-9]*\) actions.*/\1/p')
bytes=$(stat -c %s "$work/f.x3g")
echo "file: first $lines lines of the bunny sliced for the Replicator 2X at 15 mm: $actions actions, $bytes bytes of x3g"

sim() {  # starts the simulated board with "$@", prints its device
  "$build/protocol/salient-sim" --firmware sailfish --time-scale 0 --heat-time-scale 0 --log "$work/log" "$@" \
    > "$work/sim.out" 2>/dev/null &
  echo $! > "$work/sim.pid"
  for _ in $(seq 100); do [ -s "$work/sim.out" ] && break; sleep 0.02; done
  head -1 "$work/sim.out"
}
stop() { kill "$(cat "$work/sim.pid")"; wait "$(cat "$work/sim.pid")" 2>/dev/null || true; }
check_log() {  # the board ran the x3g (build name aside: gpx names it after the port)
  python3 - "$work/f.x3g" "$work/log" "$1" <<'PY'
import sys
want = open(sys.argv[1], "rb").read()
got = bytes.fromhex("".join(l.strip() for l in open(sys.argv[2])))
# 153's name differs (gpx: the port's base name): compare past the first action's NUL.
cut = lambda b: b[b.index(b"\0", 5) + 1:] if b[:1] == b"\x99" else b
if cut(got) != cut(want):
    sys.exit(f"{sys.argv[3]}: the board's log is not the x3g ({len(got)} vs {len(want)} bytes)")
PY
}
ours() {  # actions per second of salient print
  local dev; dev=$(sim "$@")
  "$build/clients/salient" print "$work/f.x3g" --port "$dev" --protocol s3g --json --quiet > "$work/r.json"
  stop
  check_log ours
  python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["state"]=="finished", r; print("%.0f" % (int(sys.argv[2])/r["seconds"]))' \
    "$work/r.json" "$actions"
}
peer() {  # actions per second of gpx -s, less the 2 s it sleeps after opening the port
  local dev t0 t1; dev=$(sim "$@")
  t0=$(date +%s.%N)
  gpx -s -m r2x "$work/f.gcode" "$dev" > /dev/null 2>&1
  t1=$(date +%s.%N)
  stop
  check_log gpx
  awk -v n="$actions" -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f\n", n / (b - a - 2) }'
}

o=$(ours); g=$(peer)
printf "%-46s %8s actions/s\n" "no line-rate limit: salient print --protocol s3g" "$o" "no line-rate limit: gpx -s (less its 2 s sleep)" "$g"
awk -v a="$o" -v b="$g" 'BEGIN { printf "ratio: %.1fx gpx -s\n", a / b }'
o115=$(ours --baud 115200); g115=$(peer --baud 115200)
printf "%-46s %8s actions/s\n" "115,200 baud: salient print --protocol s3g" "$o115" "115,200 baud: gpx -s (less its 2 s sleep)" "$g115"
awk -v a="$o115" -v b="$g115" 'BEGIN { printf "ratio: %.2fx gpx -s\n", a / b }'
# The wire: 11,520 bytes/s each way. A packet is its payload + 3 framing bytes; one packet is in
# flight at a time (the board reads one), so each also waits for its 4-byte reply.
awk -v n="$actions" -v b="$bytes" -v o="$o115" -v g="$g115" 'BEGIN {
  framed = b / n + 3; raw = 11520 / framed; sw = 11520 / (framed + 4)
  printf "wire: %.0f packets/s one way (%.1f bytes each), %.0f/s with each reply awaited\n", raw, framed, sw
  printf "share of the wire: ours %.0f%% of one-way, %.0f%% of reply-awaited; gpx -s %.0f%% / %.0f%%\n",
    100 * o / raw, 100 * o / sw, 100 * g / raw, 100 * g / sw }'
