#!/usr/bin/env bash
# G-code density, side by side in one run: on the shared models at 80 mm, uniform 0.2 mm, 2 walls,
# 20 % rectilinear infill, 0.8 mm skins, generic-i3 — our lines (arcs off, and with the profile's
# arc fitting on), PrusaSlicer's lines for the same settings, their ratio, and the busiest second's
# commands of each file by `salient estimate` (the same estimator and limits for both) against what
# a 115,200-baud ping-pong link carries at that second's framed line length. PrusaSlicer slices
# our 3MF of the same placed model (its layer profile: uniform 0.2 mm), so both see one placement
# (and it reads no PLY). The layer counts show where PrusaSlicer printed fewer layers than we did
# (an open mesh: it leaves out layers it slices empty, tests/clients/peer_3mf_layers.py).
#   tests/bench/gcode_density_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=$(cd "${1:-build}" && pwd)
salient=$build/clients/salient
models=$(cd ../shared/models && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's/^arc_fitting = false.*/arc_fitting = true/' config/printers/generic-i3.toml >"$work/i3-arcs.toml"
stream() {  # FILE PROFILE -> "peak link"
  "$salient" estimate "$1" --printer "$2" --json 2>/dev/null | python3 -c '
import json, sys
s = json.load(sys.stdin)["stream"]
print("%.0f %.0f %s" % (s["peak_commands_per_second"], s["link_commands_per_second"], "starves" if s["starves"] else "fits"))'
}
lines() { grep -c '' "$1"; }
layers() { grep -c '^;Z:' "$1"; }
echo "| model | ours | ours, arcs | PrusaSlicer | ours / PrusaSlicer | arcs / PrusaSlicer | our peak cmd/s | arcs peak cmd/s | PrusaSlicer peak cmd/s | link cmd/s (ours, arcs, PrusaSlicer) | layers (ours, PrusaSlicer) |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---|"
for m in stanford-bunny.obj:y spot.obj:y fandisk.obj:y teapot.obj:y cow.obj:y suzanne.obj:y igea.ply:z; do
  file=${m%%:*} up=${m##*:}
  "$salient" plan "$models/$file" --up "$up" --height 80 --planner uniform --layer-height 0.2 -o "$work/plan.json" >/dev/null
  "$salient" export-3mf "$models/$file" "$work/plan.json" --up "$up" --height 80 -o "$work/model.3mf" >/dev/null
  "$salient" slice "$models/$file" --up "$up" --height 80 --planner uniform --layer-height 0.2 --walls 2 \
    --infill 0.2 --top-thickness 0.8 --bottom-thickness 0.8 --printer generic-i3 -o "$work/ours.gcode" >/dev/null 2>&1
  "$salient" slice "$models/$file" --up "$up" --height 80 --planner uniform --layer-height 0.2 --walls 2 \
    --infill 0.2 --top-thickness 0.8 --bottom-thickness 0.8 --printer "$work/i3-arcs.toml" -o "$work/arcs.gcode" >/dev/null 2>&1
  prusa-slicer --export-gcode "$work/model.3mf" --layer-height 0.2 \
    --first-layer-height 0.2 --perimeters 2 --fill-density 20% --fill-pattern rectilinear \
    --top-solid-min-thickness 0.8 --bottom-solid-min-thickness 0.8 --output "$work/prusa.gcode" >/dev/null 2>&1
  n_ours=$(layers "$work/ours.gcode") n_prusa=$(layers "$work/prusa.gcode")
  o=$(lines "$work/ours.gcode") a=$(lines "$work/arcs.gcode") p=$(lines "$work/prusa.gcode")
  read -r op ol os <<<"$(stream "$work/ours.gcode" generic-i3)"
  read -r ap al as <<<"$(stream "$work/arcs.gcode" "$work/i3-arcs.toml")"
  read -r pp pl ps <<<"$(stream "$work/prusa.gcode" generic-i3)"
  awk -v f="$file" -v o="$o" -v a="$a" -v p="$p" -v op="$op" -v ap="$ap" -v pp="$pp" -v ol="$ol" -v al="$al" \
    -v pl="$pl" -v nl="$n_ours" -v np="$n_prusa" -v os="$os" -v as="$as" -v ps="$ps" 'BEGIN {
    printf "| %s | %d | %d | %d | %.2f | %.2f | %d (%s) | %d (%s) | %d (%s) | %d, %d, %d | %d, %d |\n", f, o, a, p, o / p, a / p,
      op, os, ap, as, pp, ps, ol, al, pl, nl, np }'
done
