#!/usr/bin/env bash
# Step 11, minutes: per model (80 mm, spectral saliency, ρ = 0.05, generic-i3 0.1–0.3 mm, first
# layer 0.2 mm), the layers, RSMD and estimated minutes (our estimator on each G-code) of
# exact --objective time, exact --objective layers, uniform 0.1 mm and uniform 0.2 mm; the
# savings of exact(time) against both uniform plans; then exact(time) at uniform 0.2 mm's RSMD
# (ρ = that RSMD: as much visible loss as uniform 0.2 mm) and its saving against it; the means.
# Usage: tests/bench/time_saving_bench.sh [BUILD_DIR] [MODEL:UP ...]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
shift || true
models=$(cd ../shared/models && pwd)
cases=("$@")
[[ ${#cases[@]} -gt 0 ]] || cases=(stanford-bunny.obj:y spot.obj:y fandisk.obj:y cow.obj:y teapot.obj:y suzanne.obj:y igea.ply:z)
salient=$build/clients/salient
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--height 80 --saliency spectral --printer generic-i3)

# run NAME MODEL UP ARGS...: "layers rsmd minutes" of one slice, by the estimator on its G-code.
run() {
  local name=$1 model=$2 up=$3
  shift 3
  local out
  out=$("$salient" slice "$models/$model" --up "$up" "${common[@]}" "$@" -o "$work/$name.gcode")
  local layers rsmd seconds
  layers=$(sed -n 's/^[^:]*: \([0-9]*\) layers.*/\1/p' <<<"$out" | head -1)
  rsmd=$(sed -n 's/.*RSMD \([0-9.e+-]*\), for.*/\1/p' <<<"$out" | head -1)
  seconds=$("$salient" estimate "$work/$name.gcode" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["seconds"])')
  echo "$layers $rsmd $(python3 -c "print(f'{$seconds/60:.1f}')")"
}

printf '%-18s | %-22s | %-22s | %-22s | %-22s | %-9s | %-9s | %-24s\n' model "exact time (N RSMD min)" \
  "exact layers" "uniform 0.1" "uniform 0.2" "vs 0.1" "vs 0.2" "exact at 0.2's RSMD, vs 0.2"
sum01=0 sum02=0 sumeq=0 n=0
for c in "${cases[@]}"; do
  m=${c%%:*} up=${c##*:}
  read -r tl tr tm <<<"$(run t "$m" "$up" --objective time --rho 0.05)"
  read -r ll lr lm <<<"$(run l "$m" "$up" --objective layers --rho 0.05)"
  read -r al ar am <<<"$(run a "$m" "$up" --planner uniform --layer-height 0.1)"
  read -r bl br bm <<<"$(run b "$m" "$up" --planner uniform --layer-height 0.2)"
  read -r el er em <<<"$(run e "$m" "$up" --objective time --rho "$br")"
  s01=$(python3 -c "print(f'{100*(1-$tm/$am):.1f}')")
  s02=$(python3 -c "print(f'{100*(1-$tm/$bm):.1f}')")
  seq=$(python3 -c "print(f'{100*(1-$em/$bm):.1f}')")
  printf '%-18s | %4s %6.4f %8s | %4s %6.4f %8s | %4s %6.4f %8s | %4s %6.4f %8s | %7s %% | %7s %% | %4s %6.4f %8s %6s %%\n' \
    "$m" "$tl" "$tr" "$tm" "$ll" "$lr" "$lm" "$al" "$ar" "$am" "$bl" "$br" "$bm" "$s01" "$s02" "$el" "$er" "$em" "$seq"
  sum01=$(python3 -c "print($sum01 + $s01)") sum02=$(python3 -c "print($sum02 + $s02)")
  sumeq=$(python3 -c "print($sumeq + $seq)") n=$((n + 1))
done
python3 -c "print(f'mean saving of exact(time): {$sum01/$n:.1f} % against uniform 0.1 mm, {$sum02/$n:.1f} % against uniform 0.2 mm; {$sumeq/$n:.1f} % against uniform 0.2 mm at its RSMD ({$n} models)')"
