#!/usr/bin/env bash
# Runs every benchmark and the peer comparisons in one go; prints the figures BENCHMARKS.md
# records. Usage: tests/bench/run_benchmarks.sh [BUILD_DIR] (after `make bench` built them; peers need
# `deploy/install-deps.sh --peers`).
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
models=$(cd ../shared/models && pwd)
echo "== machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "== mesh loading (parse; parse + repair), median of 7"
"$build/tests/bench/mesh_load_bench" "$models"/stanford-bunny.obj "$models"/igea.ply "$models"/fandisk.obj \
  "$models"/spot.obj "$models"/Spider_binary.stl
echo "== planners (area metric)"
"$build/tests/bench/planner_bench" "$models"/stanford-bunny.obj:y "$models"/spot.obj:y "$models"/fandisk.obj:y \
  "$models"/igea.ply:z
echo "== planners (paper metric)"
"$build/tests/bench/planner_bench" --metric paper "$models"/stanford-bunny.obj:y "$models"/igea.ply:z
echo "== saliency (median of 3; peak resident memory from /usr/bin/time)"
for method in spectral lee05; do
  for m in stanford-bunny.obj igea.ply; do
    /usr/bin/time -f "   peak %M KB" "$build/tests/bench/saliency_bench" "$method" "$models/$m" 2>&1
  done
done
echo "== spectral saliency end to end: salient saliency at 80 mm, wall seconds (median of 3)"
bash tests/bench/saliency_bench.sh "$build"
echo "== eigen-decomposition of the working mesh's Laplacian: Eigen dense (all pairs) vs Spectra (part)"
"$build/tests/bench/eigen_bench" "$models"/stanford-bunny.obj 500 1000 2000
echo "== compare with spectral saliency (seconds exclude the saliency itself; --peers: Cura's adaptive layers as a row)"
for m in stanford-bunny.obj:y spot.obj:y fandisk.obj:y cow.obj:y teapot.obj:y suzanne.obj:y igea.ply:z; do
  "$build/clients/salient" compare "$models/${m%%:*}" --up "${m##*:}" --height 80 --saliency spectral --peers
done
echo "== Step 11: the layer time model against our estimator on real G-code (calibration)"
"$build/tests/bench/time_model_bench" "$models"/stanford-bunny.obj:y "$models"/spot.obj:y "$models"/fandisk.obj:y \
  "$models"/cow.obj:y "$models"/teapot.obj:y "$models"/suzanne.obj:y "$models"/igea.ply:z
echo "== Step 11: minutes — exact(time), exact(layers), uniform 0.1 and 0.2 mm (spectral, 80 mm, generic-i3)"
bash tests/bench/time_saving_bench.sh "$build"
echo "== automatic orientation (--up auto) on the shared models"
bash tests/bench/orient_bench.sh "$build"
echo "== SegOpt (--segment) on the shared models and a half-salient sphere"
bash tests/bench/segopt_bench.sh "$build"
echo "== daemon: wrk on the printer status (idle, while slicing), idle memory, 200 WebSocket subscribers"
bash tests/bench/daemon_bench.sh "$build"
echo "== farm: job claims per second with the lease scheme (PostgreSQL fsync off/on, SQLite), K = 1, 2, 4, 8"
bash tests/bench/claims_bench.sh "$build"
echo "== farm: status requests PostgreSQL vs SQLite, transactions per printer/job/node, forwarded requests, claims, event latency (fsync on)"
bash tests/bench/farm_bench.sh "$build"
echo "== printer link: lines per second to salient-sim, ours vs printcore; share of a 250,000 baud wire"
bash tests/bench/link_bench.sh "$build"
echo "== s3g: actions per second to the simulated Sailfish board, ours vs gpx -s; share of a 115,200 baud wire"
bash tests/bench/s3g_bench.sh "$build"
if command -v prusa-slicer >/dev/null; then
  echo "== G-code density: lines and the busiest second, ours (arcs off and on) vs PrusaSlicer"
  bash tests/bench/gcode_density_bench.sh "$build"
fi
if command -v hyperfine >/dev/null && command -v prusa-slicer >/dev/null; then
  echo "== peer: model info, salient vs PrusaSlicer (whole process, hyperfine)"
  for m in stanford-bunny.obj fandisk.obj Spider_binary.stl; do
    md=$(mktemp)
    hyperfine -N -i --warmup 2 --runs 10 --export-markdown "$md" \
      "$build/clients/salient info $models/$m" "prusa-slicer --info $models/$m" >/dev/null 2>&1
    cat "$md"
    rm -f "$md"
  done
  echo "== peer: model to G-code, bunny at uniform 0.1 mm (2 walls, 20 % rectilinear, 0.8 mm skins)"
  md=$(mktemp)
  hyperfine -N -i --warmup 1 --runs 5 --export-markdown "$md" \
    "$build/clients/salient slice $models/stanford-bunny.obj --up y --height 80 --planner uniform --layer-height 0.1 --min-layer 0.1 --max-layer 0.3 --printer generic-i3 -o /tmp/salient_bench_ours.gcode" \
    "prusa-slicer --export-gcode $models/stanford-bunny.obj --rotate-x 90 --scale-to-fit 300,300,80 --layer-height 0.1 --first-layer-height 0.1 --perimeters 2 --fill-density 20% --fill-pattern rectilinear --top-solid-min-thickness 0.8 --bottom-solid-min-thickness 0.8 --output /tmp/salient_bench_prusa.gcode" \
    >/dev/null 2>&1
  cat "$md"
  rm -f "$md"
  echo "== peer: our estimate of PrusaSlicer's own G-code against its estimate"
  grep "estimated printing time (normal mode)" /tmp/salient_bench_prusa.gcode
  "$build/clients/salient" estimate /tmp/salient_bench_prusa.gcode
  echo "== peer: filament at 20 % infill, ours against PrusaSlicer at the same walls and skins"
  bash tests/bench/filament_bench.sh "$build"
else
  echo "== peer comparison skipped: install with deploy/install-deps.sh --peers"
fi
