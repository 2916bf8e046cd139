#!/usr/bin/env bash
# salient plan/slice --segment on a model made to be cut: a sphere (80 mm) whose -x half is salient
# (a saliency file) and whose +x half is not. The plan is cut between the halves and saves time;
# the G-code prints the regions' heights and nothing else; a layer count with --segment is refused.
#   segment_check.sh SALIENT WORKDIR
set -euo pipefail
salient=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
python3 - <<'PY'
import math
rings, segs, r = 40, 80, 40.0
v = [(0, 0, r)]
for i in range(1, rings):
    t = math.pi * i / rings
    for j in range(segs):
        p = 2 * math.pi * j / segs
        v.append((r * math.sin(t) * math.cos(p), r * math.sin(t) * math.sin(p), r * math.cos(t)))
v.append((0, 0, -r))
f = []
for j in range(segs):
    f.append((0, 1 + j, 1 + (j + 1) % segs))
for i in range(rings - 2):
    for j in range(segs):
        a, b = 1 + i * segs + j, 1 + i * segs + (j + 1) % segs
        f.append((a, a + segs, b)); f.append((b, a + segs, b + segs))
last = len(v) - 1
for j in range(segs):
    a, b = 1 + (rings - 2) * segs + j, 1 + (rings - 2) * segs + (j + 1) % segs
    f.append((a, last, b))
with open("sphere.obj", "w") as out:
    for p in v: out.write("v %.6f %.6f %.6f\n" % p)
    for t in f: out.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
with open("halves.txt", "w") as out:
    for p in v: out.write("1\n" if p[0] < 0 else "0.02\n")
PY
# The printer's limits (generic-i3: 0.1 to 0.3 mm), so that slice makes the same plan.
"$salient" plan sphere.obj --saliency-file halves.txt --max-layer 0.3 --segment --json -o plan.json --svg plan.svg > /dev/null
python3 - <<'PY' || fail "plan --segment did not cut the sphere between its halves"
import json
j = json.load(open("plan.json"))
s = j["segmentation"]
assert s["cut"], s["note"]
assert abs(s["plane"]["ny"]) < 0.1, s["plane"]
assert s["seconds"] < s["whole_seconds"], (s["seconds"], s["whole_seconds"])
sides = {r["side"] for r in s["regions"]}
assert {0, 1} <= sides, sides
for r in s["regions"]:
    assert r["E"] <= r["epsilon"] * (1 + 1e-9), r
print("plan: %s; %.0f -> %.0f min" % (s["note"], s["whole_seconds"] / 60, s["seconds"] / 60))
PY
grep -q "2 regions\|regions," plan.svg || fail "the SVG does not show the regions"
"$salient" slice sphere.obj --saliency-file halves.txt --segment -o sphere.gcode > slice.txt
grep -q "^segmentation: cut" slice.txt || fail "slice --segment: $(cat slice.txt)"
python3 - <<'PY' || fail "the G-code does not print the regions' heights"
import json
want = set()
for r in json.load(open("plan.json"))["segmentation"]["regions"]:
    want |= {round(z, 3) for z in r["boundaries"][1:]}
printed = [round(float(l[3:]), 3) for l in open("sphere.gcode") if l.startswith(";Z:")]
assert printed == sorted(printed), "heights out of order"
assert set(printed) <= want, sorted(set(printed) - want)[:5]
assert len(printed) >= 0.9 * len(want), (len(printed), len(want))
print("slice: %d printed heights, all of them the regions'" % len(printed))
PY
if "$salient" plan sphere.obj --segment --layers 100 > refused.txt 2>&1; then fail "--segment --layers was accepted"; fi
grep -q -- "--segment.*quality target" refused.txt || fail "refusal does not say why: $(cat refused.txt)"
echo "ok: segment"
