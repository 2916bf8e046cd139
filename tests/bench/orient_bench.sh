#!/usr/bin/env bash
# --up auto on the shared models at 80 mm (the paper's setting): the candidates' (bases, three axes) estimated
# minutes (with support), layers, TimeS, VolS, StaS and OS, the chosen one marked; and the model's
# own up axis sliced the same way (without --up auto, no support) for reference.
#   tests/bench/orient_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
models=$(cd ../shared/models && pwd)
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for m in stanford-bunny.obj:y spot.obj:y fandisk.obj:y teapot.obj:y igea.ply:z; do
  file=${m%%:*} up=${m##*:}
  echo "== $file (its own up: $up)"
  "$build/clients/salient" slice "$models/$file" --up auto --height 80 -o "$out" | sed 's/^/  /'
  "$build/clients/salient" slice "$models/$file" --up "$up" --height 80 -o "$out" | sed 's/^/  own up: /'
done
