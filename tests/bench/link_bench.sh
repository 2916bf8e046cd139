#!/usr/bin/env bash
# Streaming throughput to salient-sim over a pseudo-terminal: ours (ping-pong and ADVANCED_OK
# send-ahead) against Printrun's printcore on the same file and simulator, then at an emulated
# 250,000 baud against the wire's own line rate. Usage: tests/bench/link_bench.sh [BUILD_DIR] [LINES]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
lines=${2:-20000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
models=$(cd ../shared/models && pwd)
"$build/clients/salient" slice "$models/stanford-bunny.obj" --height 15 -o "$work/full.gcode" >/dev/null 2>&1
head -n "$lines" "$work/full.gcode" > "$work/f.gcode"
commands=$(sed 's/;.*//' "$work/f.gcode" | grep -c '[^[:space:]]')
echo "file: first $lines lines of the bunny sliced at 15 mm ($commands commands)"

sim() {  # starts salient-sim with "$@", prints its device
  "$build/protocol/salient-sim" "$@" > "$work/sim.out" 2>/dev/null &
  echo $! > "$work/sim.pid"
  for _ in $(seq 100); do [ -s "$work/sim.out" ] && break; sleep 0.02; done
  head -1 "$work/sim.out"
}
stop() { kill "$(cat "$work/sim.pid")"; wait "$(cat "$work/sim.pid")" 2>/dev/null || true; }
ours() {  # lines per second of `salient print` against a simulator started with "$@"
  local dev; dev=$(sim "$@")
  "$build/clients/salient" print "$work/f.gcode" --port "$dev" --json --quiet |
    python3 -c 'import json,sys; r=json.load(sys.stdin); assert r["state"]=="finished", r; print("%.0f" % (r["total"]/r["seconds"]))'
  stop
}
peer() {
  local dev; dev=$(sim "$@")
  /usr/bin/python3 tests/bench/link/printcore_stream.py "$dev" "$work/f.gcode" | awk '{printf "%.0f\n", $1/$2}'
  stop
}

pp=$(ours); ao=$(ours --advanced-ok); ao16=$(ours --advanced-ok --bufsize 16)
printf "%-44s %10s lines/s\n" "salient print, ping-pong" "$pp" "salient print, ADVANCED_OK (BUFSIZE 4)" "$ao" \
  "salient print, ADVANCED_OK (BUFSIZE 16)" "$ao16"
if /usr/bin/python3 -c 'import printrun.printcore' 2>/dev/null; then
  pc=$(peer)
  printf "%-44s %10s lines/s\n" "printcore (Printrun), ping-pong" "$pc"
  awk -v a="$pp" -v b="$ao" -v c="$pc" 'BEGIN { printf "ratio: ping-pong %.1fx, send-ahead %.1fx printcore\n", a / c, b / c }'
else
  echo "printcore not installed: deploy/install-deps.sh --peers"
fi

# The wire: 25,000 bytes/s; a line costs its framed bytes "N<n> <command>*<sum>\n".
wire=$(python3 - "$work/f.gcode" <<'PY'
import functools, sys
n = total = 0
for line in open(sys.argv[1]):
    c = line.split(";")[0].strip()
    if not c:
        continue
    n += 1
    s = "N%d %s" % (n, c)
    total += len(s) + len("*%d\n" % functools.reduce(lambda a, b: a ^ b, s.encode(), 0))
print("%.0f" % (25000 / (total / n)))
PY
)
bp=$(ours --baud 250000); ba=$(ours --baud 250000 --advanced-ok)
printf "%-44s %10s lines/s\n" "wire at 250,000 baud (8N1, framed lines)" "$wire" "salient print at 250,000, ping-pong" "$bp" \
  "salient print at 250,000, ADVANCED_OK" "$ba"
awk -v w="$wire" -v a="$bp" -v b="$ba" 'BEGIN { printf "share of the wire: ping-pong %.1f %%, send-ahead %.1f %%\n", 100 * a / w, 100 * b / w }'
