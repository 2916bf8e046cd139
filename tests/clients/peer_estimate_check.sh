#!/usr/bin/env bash
# Cross-check `salient estimate` against the estimate PrusaSlicer writes into G-code it makes:
# time within 3 %, filament within 1 %. PrusaSlicer is told to write its machine limits (M201-M205)
# into the file, so both estimate with the same accelerations and jerk. Usage: peer_estimate_check.sh SALIENT MODEL WORKDIR
set -euo pipefail
salient=$1 model=$2 work=$3
gcode="$work/peer_$(basename "$model").gcode"
prusa-slicer --export-gcode "$model" --scale-to-fit 150,150,60 --layer-height 0.2 --gcode-flavor marlin2 --machine-limits-usage emit_to_gcode --output "$gcode" >/dev/null 2>&1
theirs=$(sed -n 's/^; estimated printing time (normal mode) = //p' "$gcode" | head -1)
filament=$(sed -n 's/^; filament used \[mm\] = //p' "$gcode" | head -1)
# "1h 2m 3s" / "2m 3s" / "45s" to seconds
secs=0
for part in $theirs; do
  n=${part%[dhms]}
  case $part in *d) secs=$((secs + n * 86400)) ;; *h) secs=$((secs + n * 3600)) ;; *m) secs=$((secs + n * 60)) ;; *s) secs=$((secs + n)) ;; esac
done
ours=$("$salient" estimate "$gcode" --json)
our_secs=$(grep -o '"seconds": [0-9.e+-]*' <<<"$ours" | head -1 | awk '{print $2}')
our_fil=$(grep -o '"filament_mm": [0-9.e+-]*' <<<"$ours" | awk '{print $2}')
awk -v a="$our_secs" -v b="$secs" -v fa="$our_fil" -v fb="$filament" 'BEGIN {
  dt = (a - b) / b; df = (fa - fb) / fb;
  printf "time: ours %.0f s, PrusaSlicer %d s (%+.1f%%); filament: ours %.1f mm, PrusaSlicer %.1f mm (%+.2f%%)\n", a, b, 100*dt, fa, fb, 100*df;
  exit (dt < -0.03 || dt > 0.03 || df < -0.01 || df > 0.01) ? 1 : 0 }'
