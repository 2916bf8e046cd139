#!/usr/bin/env bash
# The OctoPrint API as slicers use it, replayed against salientd with a simulated printer:
#  - PrusaSlicer (src/slic3r/Utils/OctoPrint.cpp): GET /api/version with X-Api-Key, accepted when
#    the JSON has "api" and "text" starts with "OctoPrint"; then POST /api/files/local, multipart
#    fields in its order: print=true, path (empty), file. The file must print on the simulator,
#    exactly.
#  - Cura's OctoPrint plugin: settings, version, passive login, printer profiles, printer and job
#    polling, an upload with select and print, the Location header, job control and commands.
#   octoprint_replay.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
sim_config sim.toml "--advanced-ok --emergency-parser --autoreport --time-scale 0 --log $PWD/sim.log"
start sim.toml
"$salient" slice "$models/cube_binary.ply" --height 10 -o cube.gcode > /dev/null
wait_idle() {  # until the printer is operational and its last print is FILE, finished
  for _ in $(seq 600); do
    s=$(curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim")
    echo "$s" | python3 -c "
import json, sys
d = json.load(sys.stdin)
p = d['last_print'] or {}
sys.exit(0 if d['state'] == 'operational' and p.get('state') == 'finished' and p.get('file') == sys.argv[1] else 1)" "$1" &&
      return 0
    sleep 0.1
  done
  fail "the printer did not finish $1: $s"
}
wait_operational() {
  for _ in $(seq 200); do
    [ "$(curl -s -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" "$base/api/printer")" = 200 ] && return 0
    sleep 0.1
  done
  fail "the printer never became operational"
}
wait_operational

# PrusaSlicer: the connection test, then the upload with print=true.
curl -s -f -A "PrusaSlicer/2.6.1" -H "X-Api-Key: $key" "$base/api/version" > version.json || fail "version"
python3 - version.json <<'PY' || fail "PrusaSlicer would reject /api/version: $(cat version.json)"
import json, sys
v = json.load(open(sys.argv[1]))
assert "api" in v and v.get("text", "OctoPrint").startswith("OctoPrint")
PY
status=$(curl -s -A "PrusaSlicer/2.6.1" -H "X-Api-Key: $key" -D headers.txt -o upload.json -w '%{http_code}' \
  -F "print=true" -F "path=" -F "file=@cube.gcode;filename=cube.gcode" "$base/api/files/local")
[ "$status" = 201 ] || fail "PrusaSlicer upload: $status $(cat upload.json)"
grep -qi "^location: http://127.0.0.1:[0-9]*/api/files/local/cube.gcode" headers.txt || fail "no Location: $(cat headers.txt)"
[ "$(field "['done']" < upload.json)" = True ] && [ "$(field "['effectivePrint']" < upload.json)" = True ] || fail "upload body"
wait_idle cube.gcode
same_commands cube.gcode sim.log
# The file as OctoPrint lists it (FDM Monster, OctoPod and Cura read gcodeAnalysis): our estimate,
# the filament the header states, and the cube's printing area; the same in the listing.
curl -s -f -H "X-Api-Key: $key" -o file.json "$base/api/files/local/cube.gcode" || fail "file details"
curl -s -f -H "X-Api-Key: $key" -o files.json "$base/api/files/local" || fail "file list"
python3 - cube.gcode file.json files.json <<'PY' || fail "gcodeAnalysis: $(cat file.json)"
import json, re, sys
text = open(sys.argv[1]).read()
a = json.load(open(sys.argv[2]))["gcodeAnalysis"]
listed = [f for f in json.load(open(sys.argv[3]))["files"] if f["name"] == "cube.gcode"][0]
assert listed["gcodeAnalysis"] == a, listed
header_mm = float(re.search(r"\n; filament used \[mm\] = ([0-9.]+)\n", text).group(1))
h, m, s = re.search(r"\n; estimated printing time \(normal mode\) = (?:(\d+)h )?(?:(\d+)m )?(\d+)s\n", text).groups()
header_s = int(h or 0) * 3600 + int(m or 0) * 60 + int(s)
top = float(re.search(r"\n; max_layer_z = ([0-9.]+)\n", text).group(1))
first = float(re.search(r"\n; first_layer_height = ([0-9.]+)\n", text).group(1))
tool0 = a["filament"]["tool0"]
assert abs(tool0["length"] - header_mm) < 0.01 * header_mm, (tool0, header_mm)
assert abs(tool0["volume"] - header_mm * 3.14159265 * 1.75 ** 2 / 4 / 1000) < 0.01 * tool0["volume"], tool0
# The whole file (start code too) against the writer's estimate of the layers: within 5 %.
assert abs(a["estimatedPrintTime"] - header_s) <= 0.05 * header_s + 1, (a["estimatedPrintTime"], header_s)
d = a["dimensions"]
assert abs(d["height"] - (top - first)) < 1e-6, (d, top, first)  # OctoPrint: extruding z, first to last
# A 10 mm cube and the skirt around it (a few mm off): OctoPrint's area takes every extrusion.
assert top <= d["width"] < top + 10 and top <= d["depth"] < top + 10, d
# The thumbnails as the readers of PrusaSlicer's blocks take them (Moonraker's metadata.py, the
# OctoPrint PrusaSlicer Thumbnails plugin): that regex, '; ' dropped, "W H LENGTH" equal to the
# data's length; then the PNG's signature and its IHDR size.
import base64, struct
blocks = re.findall(r"; thumbnail begin[;/\+=\w\s]+?; thumbnail end", text)
sizes = []
for block in blocks:
    lines = re.split(r"\r?\n", block.replace("; ", ""))
    w, hh, length = map(int, re.findall(r"\d+", lines[0]))
    data = "".join(lines[1:-1])
    assert len(data) == length, (lines[0], len(data))
    png = base64.b64decode(data, validate=True)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[12:16] == b"IHDR", png[:16]
    assert struct.unpack(">II", png[16:24]) == (w, hh), (w, hh)
    sizes.append((w, hh))
assert sizes == [(16, 16), (220, 124)], sizes
assert text.index("; thumbnail end") < text.index("\nM73 "), "thumbnails after the first command"
PY

# Cura: its sequence of calls, an upload that selects without printing, then starts the job.
for path in /api/settings /api/version /api/printerprofiles /api/printer /api/job /api/server /api/files; do
  curl -s -f -A "Cura/5.4.0" -H "X-Api-Key: $key" -o out.json "$base$path" || fail "Cura: GET $path"
  python3 -c "import json; json.load(open('out.json'))" || fail "Cura: $path is not JSON"
done
curl -s -f -H "X-Api-Key: $key" -H "Content-Type: application/json" -d '{"passive": true}' "$base/api/login" \
  | field "['name']" > /dev/null || fail "passive login"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/printerprofiles" | field "['profiles']['sim']['heatedBed']")" = True ] || fail "profiles"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/printer" | field "['state']['flags']['ready']")" = True ] || fail "printer flags"
cp cube.gcode "cura cube.gcode"
status=$(curl -s -A "Cura/5.4.0" -H "X-Api-Key: $key" -D headers.txt -o upload.json -w '%{http_code}' \
  -F "path=" -F "file=@cura cube.gcode" -F "select=true" -F "print=false" "$base/api/files/local")
[ "$status" = 201 ] || fail "Cura upload: $status $(cat upload.json)"
location=$(grep -i "^location:" headers.txt | tr -d '\r' | cut -d' ' -f2)
[ "$(curl -s -H "X-Api-Key: $key" "$location" | field "['name']")" = cura_cube.gcode ] || fail "Location $location"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/job" | field "['job']['file']['name']")" = cura_cube.gcode ] || fail "selected file"
[ "$(curl -s -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" -H "Content-Type: application/json" \
  -d '{"command": "start"}' "$base/api/job")" = 204 ] || fail "POST /api/job start"
wait_idle cura_cube.gcode
[ "$(curl -s -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" -H "Content-Type: application/json" \
  -d '{"commands": ["M106 S128", "M107"]}' "$base/api/printer/command")" = 204 ] || fail "printer/command"
last_two() { tail -2 sim.log | tr '\n' ' ' | grep -q "M106 S128 M107"; }
eventually 60 last_two || fail "commands not executed: $(tail -3 sim.log)"
# What OctoPrint refuses, salientd refuses the same way.
[ "$(curl -s -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" -F "file=@$models/cube_binary.ply" "$base/api/files/local")" = 415 ] \
  || fail "a model uploaded as G-code"
[ "$(curl -s -o /dev/null -w '%{http_code}' -F "file=@cube.gcode" "$base/api/files/local")" = 403 ] || fail "upload without key (403, as OctoPrint)"
[ "$(curl -s -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" -H "Content-Type: application/json" -d '{"command": "pause", "action": "pause"}' "$base/api/job")" = 409 ] \
  || fail "pause with nothing printing"
stop
echo "ok: PrusaSlicer and Cura uploads replayed and printed"
