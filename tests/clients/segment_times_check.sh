#!/usr/bin/env bash
# salient plan --segment and salient slice --segment time the same plan alike (within 0.5 %): plan
# times its regions with the toolpath settings slice prints with (core::region_slice_settings) on
# generic-i3, whose limits (0.1 to 0.3 mm) it is given so that both make the same plan. The
# segmented plan also has the fixed first layer (generic-i3's 0.2 mm) and a "times" block.
#   segment_times_check.sh SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salient=$1 models=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
for model in cow.obj spot.obj; do
  "$salient" plan "$models/$model" --up y --height 80 --saliency lee05 --max-layer 0.3 --segment --json \
    -o plan.json > /dev/null
  "$salient" slice "$models/$model" --up y --height 80 --saliency lee05 --segment -o slice.gcode > slice.txt
  python3 - "$model" <<'PY' || fail "$model: plan --segment and slice --segment disagree"
import json, re, sys
plan = json.load(open("plan.json"))
gcode = open("slice.gcode").read()
# PrusaSlicer's form, "1d 2h 3m 4s" with the leading parts left out when zero
d, h, m, s = (int(g or 0) for g in re.search(
    r"\n; estimated printing time \(normal mode\) = (?:(\d+)d )?(?:(\d+)h )?(?:(\d+)m )?(\d+)s\n", gcode).groups())
sliced = float(((d * 24 + h) * 60 + m) * 60 + s)
planned = plan["segmentation"]["seconds"]
print("%s: plan --segment %.0f s, slice --segment %.0f s (%+.2f %%)" % (sys.argv[1], planned, sliced, 100 * (planned / sliced - 1)))
assert abs(planned / sliced - 1) < 0.005, (planned, sliced)
heights = [float(l[3:]) for l in gcode.splitlines() if l.startswith(";Z:")]
assert plan["count"] == len(heights), (plan["count"], len(heights))
assert abs(plan["layers"][0]["height"] - 0.2) < 1e-6, plan["layers"][0]
assert abs(heights[0] - 0.2) < 1e-6, heights[0]
t = plan["times"]
assert abs(t["plan_s"] - planned) < 1e-6 and t["fine_s"] > planned and t["default_s"] > 0, t
PY
done
echo "ok: segment times"
