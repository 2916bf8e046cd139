#!/usr/bin/env bash
# export-x3g and gpx -I -q -m r2x on one G-code file: byte-identical x3g.
# Usage: x3g_file_peer_check.sh SALIENT FILE.gcode WORKDIR
set -euo pipefail
salient=$1 src=$2 work=$3
name=$(basename "$src" .gcode)
rm -rf "$work" && mkdir -p "$work/gpx" "$work/ours"
gpx -I -q -m r2x "$src" "$work/gpx/$name.x3g"
"$salient" export-x3g "$src" -o "$work/ours/$name.x3g" >/dev/null 2>"$work/warnings.txt"
if ! cmp "$work/gpx/$name.x3g" "$work/ours/$name.x3g"; then
  diff <(s3gdump "$work/gpx/$name.x3g") <(s3gdump "$work/ours/$name.x3g") | head -8 || true
  exit 1
fi
echo "$name: identical to gpx ($(wc -l <"$work/warnings.txt") commands skipped by both)"
