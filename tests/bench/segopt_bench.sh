#!/usr/bin/env bash
# SegOpt (paper §5) on the shared models at 80 mm with the paper's spectral saliency, generic-i3
# limits (0.1–0.3 mm): printed layers and estimated minutes without and with --segment, whether the
# best plane was kept and why, and the best plane's seam figures. Plus the made-to-be-cut case: an
# 80 mm sphere whose −x half is salient (tests/clients/segment_check.sh builds it).
#   tests/bench/segopt_bench.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=$(cd "${1:-build}" && pwd)
models=$(cd ../shared/models && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
row() {  # row NAME PLANNER ARGS…
  local name=$1 planner=$2; shift 2
  "$build/clients/salient" plan "$@" --planner "$planner" --height 80 --max-layer 0.3 --segment --json -o "$work/plan.json" > /dev/null
  python3 - "$name" "$planner" "$work/plan.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[3])); s = j["segmentation"]
whole = next((r for r in s["regions"] if r["side"] == -1 and r["z_bottom"] == 0 and len(s["regions"]) == 1), None)
plane = s.get("plane")
seam = "D %.3f, f %.3f, part %.0f%%" % (plane["difference"], plane["cost"], 100 * plane["share"]) if plane else "-"
print("| %s | %s | %d | %.1f | %.1f | %.1f | %.2f | %s | %s |" % (
    sys.argv[1], sys.argv[2], j["count"], s["whole_seconds"] / 60, s["parts_seconds"] / 60, s["seconds"] / 60,
    s["seconds"] / s["whole_seconds"], seam, s["note"]))
PY
}
echo "| model | planner | printed layers | whole min | parts min (T1+T2) | result min | result / whole | best plane | decision |"
echo "|---|---|---|---|---|---|---|---|---|"
for m in stanford-bunny.obj:y spot.obj:y fandisk.obj:y teapot.obj:y igea.ply:z suzanne.obj:y cow.obj:y; do
  file=${m%%:*} up=${m##*:}
  row "$file" exact "$models/$file" --up "$up" --saliency spectral
  # The five best planes by seam cost planned and timed (the paper times only the best).
  row "$file, 5 planes" exact "$models/$file" --up "$up" --saliency spectral --segment-planes 5
done
# The made-to-be-cut sphere, with both planners.
bash tests/clients/segment_check.sh "$build/clients/salient" "$work/sphere" > /dev/null
for p in exact adapslice; do row "sphere, salient −x half" "$p" "$work/sphere/sphere.obj" --saliency-file "$work/sphere/halves.txt"; done
