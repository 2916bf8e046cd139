#!/usr/bin/env bash
# Spectral saliency, end to end as a user runs it: `salient saliency` on the 80 mm shared models,
# wall seconds (median of 3, the whole process: load, repair, saliency) and the saliency's own
# seconds. With a second `salient` (e.g. a build from before the LAPACK solver), both run on each
# model and the largest difference of their normalised per-vertex values is printed.
#   tests/bench/saliency_bench.sh [BUILD_DIR] [REFERENCE_SALIENT]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
reference=${2:-}
models=$(cd ../shared/models && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# median wall seconds of 3 runs of "$@" (the PLY of the last run is kept in $tmp/out.ply)
median_wall() {
  local times=()
  for _ in 1 2 3; do
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >"$tmp/out.json"
    t1=$(date +%s.%N)
    times+=("$(echo "$t1 - $t0" | bc)")
  done
  printf '%s\n' "${times[@]}" | sort -n | sed -n 2p
}

# max |a - b| over the vertices' quality of two PLYs written by `salient saliency -o`
ply_difference() {
  python3 - "$1" "$2" <<'PY'
import struct, sys
def quality(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + 11
    n = int(next(l for l in data[:end].split(b'\n') if l.startswith(b'element vertex')).split()[2])
    return [struct.unpack_from('<f', data, end + 19 * i + 12)[0] for i in range(n)]
a, b = quality(sys.argv[1]), quality(sys.argv[2])
print(f"{max(abs(x - y) for x, y in zip(a, b)):.2g}" if len(a) == len(b) else "vertex counts differ")
PY
}

printf '%-20s %8s %10s %10s' model vertices "wall s" "saliency s"
[[ -n "$reference" ]] && printf ' %12s %14s' "ref wall s" "max |new-ref|"
printf '\n'
for m in stanford-bunny.obj:y spot.obj:y fandisk.obj:y teapot.obj:y igea.ply:z; do
  file=${m%%:*} up=${m##*:}
  args=(saliency "$models/$file" --up "$up" --height 80 --method spectral --json -o)
  wall=$(median_wall "$build/clients/salient" "${args[@]}" "$tmp/new.ply")
  vertices=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["vertices"])' "$tmp/out.json")
  seconds=$(python3 -c 'import json,sys; print("%.2f" % json.load(open(sys.argv[1]))["seconds"])' "$tmp/out.json")
  printf '%-20s %8s %10.2f %10s' "$file" "$vertices" "$wall" "$seconds"
  if [[ -n "$reference" ]]; then
    ref_wall=$(median_wall "$reference" "${args[@]}" "$tmp/ref.ply")
    printf ' %12.2f %14s' "$ref_wall" "$(ply_difference "$tmp/new.ply" "$tmp/ref.ply")"
  fi
  printf '\n'
done
