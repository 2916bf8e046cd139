#!/usr/bin/env bash
# Peer check of `salient export-x3g` against Debian's gpx on one model sliced for the Replicator
# 2X: both x3g files must be byte-identical, and every move must stay inside the machine's travel.
# Usage: x3g_peer_check.sh SALIENT MODEL WORKDIR SLICE-ARGS...
set -euo pipefail
salient=$1 model=$2 work=$3
shift 3
name=$(basename "$model")
name=${name%.*}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work/gpx" "$work/ours"
"$salient" slice "$model" --printer replicator2x "$@" -o "$work/$name.gcode" >/dev/null
# The same base name: 153 carries it as the build's name.
gpx -I -q -m r2x "$work/$name.gcode" "$work/gpx/$name.x3g"
"$salient" export-x3g "$work/$name.gcode" -o "$work/ours/$name.x3g" 2>"$work/warnings.txt"
if ! cmp "$work/gpx/$name.x3g" "$work/ours/$name.x3g"; then
  echo "export-x3g differs from gpx -I -q -m r2x; first differing actions (s3gdump, gpx < > ours):"
  diff <(s3gdump "$work/gpx/$name.x3g") <(s3gdump "$work/ours/$name.x3g") | head -8 || true
  exit 1
fi
if [ -s "$work/warnings.txt" ]; then
  echo "export-x3g skipped commands of our own G-code:"
  head -5 "$work/warnings.txt"
  exit 1
fi
echo "$name: $(stat -c %s "$work/gpx/$name.x3g") bytes, identical to gpx"
python3 "$here/x3g_travel_check.py" "$work/gpx/$name.x3g"
