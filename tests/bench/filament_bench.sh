#!/usr/bin/env bash
# Filament at 20 % infill, ours against PrusaSlicer's at the same settings, per shared model:
# uniform 0.2 mm layers (first layer too), 2 walls, 20 % rectilinear, 0.8 mm top and bottom skins,
# 80 mm tall. PrusaSlicer slices our own 3MF of the placed model (same mesh, same orientation).
# Ours is measured with the profile's small-solid area (generic-i3: 70 mm², PrusaSlicer's default)
# and with it off (0), so the effect of that rule alone shows. Filament: `salient estimate` on our
# G-code, PrusaSlicer's "; filament used [mm]" on its own. The last column is PrusaSlicer at its
# own defaults but for layer height and density (3 perimeters, its skins, gap fill…): what "the
# same 20 %" costs when only the density is set.
# Usage: tests/bench/filament_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
salient="$build/clients/salient"
models=$(cd ../shared/models && pwd)
command -v prusa-slicer >/dev/null || { echo "prusa-slicer not installed: deploy/install-deps.sh --peers"; exit 0; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's/^solid_below_area = .*/solid_below_area = 0.0/' config/printers/generic-i3.toml >"$work/no-small-solid.toml"
filament_of() { "$salient" estimate "$1" --json | sed -n 's/.*"filament_mm": \([0-9.e+-]*\).*/\1/p'; }
printf "%-20s %12s %16s %14s %8s %16s %18s\n" model "ours mm" "ours, no small" "PrusaSlicer mm" ratio "ratio, no small" \
  "PrusaSlicer dflt mm"
for case in stanford-bunny.obj:y spot.obj:y fandisk.obj:y; do
  model=${case%%:*} up=${case##*:}
  common=(--up "$up" --height 80 --planner uniform --layer-height 0.2 --min-layer 0.1 --max-layer 0.3)
  toolpaths=(--walls 2 --infill 0.2 --top-thickness 0.8 --bottom-thickness 0.8)
  "$salient" slice "$models/$model" "${common[@]}" "${toolpaths[@]}" --printer generic-i3 -o "$work/ours.gcode" >/dev/null
  "$salient" slice "$models/$model" "${common[@]}" "${toolpaths[@]}" --printer "$work/no-small-solid.toml" \
    -o "$work/ours0.gcode" >/dev/null
  "$salient" plan "$models/$model" "${common[@]}" -o "$work/plan.json" >/dev/null
  "$salient" export-3mf "$models/$model" "$work/plan.json" --up "$up" --height 80 -o "$work/model.3mf" >/dev/null
  prusa-slicer --export-gcode "$work/model.3mf" --layer-height 0.2 --first-layer-height 0.2 --perimeters 2 \
    --fill-density 20% --fill-pattern rectilinear --top-solid-layers 0 --bottom-solid-layers 0 \
    --top-solid-min-thickness 0.8 --bottom-solid-min-thickness 0.8 --output "$work/prusa.gcode" >/dev/null 2>&1
  prusa-slicer --export-gcode "$work/model.3mf" --layer-height 0.2 --first-layer-height 0.2 --fill-density 20% \
    --output "$work/prusa-defaults.gcode" >/dev/null 2>&1
  ours=$(filament_of "$work/ours.gcode") ours0=$(filament_of "$work/ours0.gcode")
  prusa=$(sed -n 's/^; filament used \[mm\] = //p' "$work/prusa.gcode" | head -1)
  prusa_defaults=$(sed -n 's/^; filament used \[mm\] = //p' "$work/prusa-defaults.gcode" | head -1)
  awk -v m="$model" -v a="$ours" -v a0="$ours0" -v b="$prusa" -v d="$prusa_defaults" \
    'BEGIN { printf "%-20s %12.1f %16.1f %14.1f %8.3f %16.3f %18.1f\n", m, a, a0, b, a / b, a0 / b, d }'
done
