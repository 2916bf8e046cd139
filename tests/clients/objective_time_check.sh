#!/usr/bin/env bash
# exact --objective time never takes longer than --objective layers, by our estimator on the
# G-code each writes (generic-i3, ρ = 0.05). Usage: objective_time_check.sh SALIENT MODEL UP HEIGHT WORKDIR
set -euo pipefail
salient=$1 model=$2 up=$3 height=$4 work=$5
base="$work/objective_$(basename "$model")_$height"
seconds() {
  "$salient" slice "$model" --up "$up" --height "$height" --printer generic-i3 --objective "$1" -o "$base.$1.gcode" >/dev/null
  "$salient" estimate "$base.$1.gcode" --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["seconds"])'
}
t=$(seconds time) l=$(seconds layers)
python3 - "$t" "$l" <<'PY'
import sys
t, l = map(float, sys.argv[1:])
print(f"objective time {t:.0f} s, layers {l:.0f} s ({100 * (t / l - 1):+.2f} %)")
sys.exit(0 if t <= l else 1)
PY
