#!/usr/bin/env bash
# The plan format (docs/plan-format.md), every writer → every reader: `salient plan -o`, `plan
# --segment -o` (a sphere whose halves differ, so that it is cut) and salientd's /plan of a plain
# and of a segmented job each validate against docs/plan.schema.json and are read by export-3mf
# into a 3MF with their layers; a plan from before version 1 (`salient plan -o`'s old shape) is
# still read; an old daemon /plan and a newer version are refused by name.
#   plan_format_check.sh SALIENTD SALIENT SOURCE_DIR MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 src=$3 models=$4 work=$5
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
count() { field "['count']" < "$1"; }
# reads FILE MODEL MESH-ARGS…: export-3mf reads the plan into a 3MF with as many layers.
reads() {
  local plan=$1 model=$2; shift 2
  "$salient" export-3mf "$model" "$plan" "$@" -o "$plan.3mf" > "$plan.out" 2>&1 || fail "export-3mf $plan: $(cat "$plan.out")"
  grep -q ": $(count "$plan") layers -> " "$plan.out" || fail "export-3mf $plan: $(cat "$plan.out") (plan: $(count "$plan") layers)"
  grep -aq 'Slic3r_PE_layer_heights_profile.txt' "$plan.3mf" || fail "$plan.3mf has no layer profile"
}
python3 - <<'PY'
import math
rings, segs, r = 24, 48, 40.0
v = [(0, 0, r)] + [(r * math.sin(math.pi * i / rings) * math.cos(2 * math.pi * j / segs),
                    r * math.sin(math.pi * i / rings) * math.sin(2 * math.pi * j / segs),
                    r * math.cos(math.pi * i / rings)) for i in range(1, rings) for j in range(segs)] + [(0, 0, -r)]
f = [(0, 1 + j, 1 + (j + 1) % segs) for j in range(segs)]
for i in range(rings - 2):
    for j in range(segs):
        a, b = 1 + i * segs + j, 1 + i * segs + (j + 1) % segs
        f += [(a, a + segs, b), (b, a + segs, b + segs)]
last = len(v) - 1
f += [(1 + (rings - 2) * segs + j, last, 1 + (rings - 2) * segs + (j + 1) % segs) for j in range(segs)]
with open("sphere.obj", "w") as out:
    out.writelines("v %.6f %.6f %.6f\n" % p for p in v)
    out.writelines("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1) for t in f)
with open("halves.txt", "w") as out:
    out.writelines("1\n" if p[0] < 0 else "0.02\n" for p in v)
PY
suzanne=$models/suzanne.obj

# The CLI's writers.
"$salient" plan "$suzanne" --up y --height 20 -o cli-plain.json > /dev/null
"$salient" plan sphere.obj --saliency-file halves.txt --max-layer 0.3 --segment -o cli-segment.json > /dev/null
[ "$(field "['segmentation']['cut']" < cli-segment.json)" = True ] || fail "the sphere was not cut: $(field "['segmentation']['note']" < cli-segment.json)"

# The daemon's: a plain and a segmented job, their /plan.
start
job() {  # job NAME SETTINGS: submits suzanne, waits for it, saves its /plan as NAME.json
  local id s
  id=$(curl -s -f -H "X-Api-Key: $key" -F "file=@$suzanne" -F "settings=$2" "$base/api/v1/jobs" | field "['id']")
  for _ in $(seq 1200); do
    s=$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$id" | field "['state']")
    [ "$s" = done ] && break
    case $s in failed|cancelled) fail "job $2: $s";; esac
    sleep 0.1
  done
  curl -s -f -H "X-Api-Key: $key" -o "$1.json" "$base/api/v1/jobs/$id/plan" || fail "GET /plan of job $2"
  curl -s -f -H "X-Api-Key: $key" "$base/api/v1/jobs/$id" > "$1.job"
}
job daemon-plain '{"up": "y", "height": 20}'
job daemon-segment '{"up": "y", "height": 20, "segment": true}'
# The job's result carries the same SegOpt report as its plan.
python3 - <<'PY' || fail "the job's result.segmentation differs from its plan's"
import json
assert json.load(open("daemon-segment.job"))["result"]["segmentation"] == json.load(open("daemon-segment.json"))["segmentation"]
assert json.load(open("daemon-plain.job"))["result"]["segmentation"] is None
PY

# Every writer's output: valid, and read by export-3mf.
python3 "$src/tests/support/validate_json.py" "$src/docs/plan.schema.json" cli-plain.json cli-segment.json \
  daemon-plain.json daemon-segment.json || fail "a plan does not validate against docs/plan.schema.json"
reads cli-plain.json "$suzanne" --up y --height 20
reads cli-segment.json sphere.obj
reads daemon-plain.json "$suzanne" --up y --height 20
reads daemon-segment.json "$suzanne" --up y --height 20

# Before version 1: `salient plan -o` wrote the same fields without format, version, model and
# segmentation; still read. The daemon's old /plan shape and a newer version are refused by name.
python3 - <<'PY'
import json
j = json.load(open("cli-plain.json"))
for k in ("format", "version", "model", "segmentation"):
    del j[k]
json.dump(j, open("old-plain.json", "w"), indent=2)
json.dump({"model": "suzanne.obj", "z": [l["z_top"] for l in j["layers"]], "layers": j["count"]}, open("old-daemon.json", "w"))
j = json.load(open("cli-plain.json"))
j["version"] = 2
json.dump(j, open("v2.json", "w"))
PY
reads old-plain.json "$suzanne" --up y --height 20
"$salient" export-3mf "$suzanne" old-daemon.json --up y --height 20 -o never.3mf > refused.txt 2>&1 && fail "an old daemon plan was read"
grep -q "old-daemon.json: has no field 'format'" refused.txt || fail "old daemon plan refusal: $(cat refused.txt)"
"$salient" export-3mf "$suzanne" v2.json --up y --height 20 -o never.3mf > refused.txt 2>&1 && fail "a version 2 plan was read"
grep -q "v2.json: is a salient-plan of version 2; this salient reads up to version 1" refused.txt || fail "v2 refusal: $(cat refused.txt)"
echo "ok: 4 writers, each valid and read by export-3mf; the old plan -o shape read, others refused"
