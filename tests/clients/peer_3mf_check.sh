#!/usr/bin/env bash
# PrusaSlicer slices our 3MF and its layer tops (;Z:) follow our plan. PrusaSlicer fixes its
# first layer at first_layer_height and clamps the profile to its min/max layer height, so the
# plan's first layer and α/ᾱ are passed to it; with them it reproduces the plan exactly. On an
# open mesh it may leave layers out: peer_3mf_layers.py accepts only those it reports empty and
# where the mesh is open wider than it closes.
# Usage: peer_3mf_check.sh SALIENT MODEL UP HEIGHT WORKDIR [SALIENCY (lee05)]
set -euo pipefail
salient=$1 model=$2 up=$3 height=$4 work=$5 saliency=${6:-lee05}
base="$work/peer3mf_$(basename "$model")"
"$salient" plan "$model" --up "$up" --height "$height" --saliency "$saliency" -o "$base.json" >/dev/null
"$salient" export-3mf "$model" "$base.json" --up "$up" --height "$height" -o "$base.3mf" >/dev/null
first=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["layers"][0]["height"])' "$base.json")
prusa-slicer --export-gcode "$base.3mf" --first-layer-height "$first" --min-layer-height 0.1 --max-layer-height 0.4 \
  --support-material-contact-distance 0 --perimeters 1 --fill-density 0 --top-solid-layers 0 --bottom-solid-layers 0 \
  --output "$base.gcode" >"$base.log" 2>&1
python3 "$(dirname "$0")/peer_3mf_layers.py" "$base.json" "$base.3mf" "$base.gcode" "$base.log"
