#!/usr/bin/env bash
# PrusaSlicer slices our 3MF and its layer tops (;Z:) follow our plan. PrusaSlicer fixes its
# first layer at first_layer_height and clamps the profile to its min/max layer height, so the
# plan's first layer and α/ᾱ are passed to it; with them it reproduces the plan exactly.
# Usage: peer_3mf_check.sh SALIENT MODEL UP HEIGHT WORKDIR
set -euo pipefail
salient=$1 model=$2 up=$3 height=$4 work=$5
base="$work/peer3mf_$(basename "$model")"
"$salient" plan "$model" --up "$up" --height "$height" --saliency lee05 -o "$base.json" >/dev/null
"$salient" export-3mf "$model" "$base.json" --up "$up" --height "$height" -o "$base.3mf" >/dev/null
# Our layer tops and first layer height, from the plan (docs/plan-format.md).
python3 -c 'import json, sys; print("\n".join(repr(l["z_top"]) for l in json.load(open(sys.argv[1]))["layers"]))' \
  "$base.json" >"$base.ours"
first=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["layers"][0]["height"])' "$base.json")
prusa-slicer --export-gcode "$base.3mf" --first-layer-height "$first" --min-layer-height 0.1 --max-layer-height 0.4 \
  --output "$base.gcode" >/dev/null 2>&1
sed -n 's/^;Z://p' "$base.gcode" >"$base.theirs"
ours=$(wc -l <"$base.ours") theirs=$(wc -l <"$base.theirs")
[[ $ours == "$theirs" ]] || { echo "layer count: ours $ours, PrusaSlicer $theirs"; exit 1; }
paste "$base.ours" "$base.theirs" | awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > max) max = d }
  END { printf "PrusaSlicer follows the plan: %d layers, max |dz| %.2g mm\n", NR, max; exit (max > 0.011) }'
