#!/usr/bin/env bash
# download.sh JOB [ARTEFACT] [FILE]: gets a finished job's gcode (default), plan, plot.svg,
# model.3mf or saliency.ply.
set -euo pipefail
. "$(dirname "$0")/common.sh"
[ $# -ge 1 ] || { echo "usage: $0 JOB [gcode|plan|plot.svg|model.3mf|saliency.ply] [FILE]" >&2; exit 2; }
artefact=${2:-gcode}
out=${3:-$1.${artefact/plan/plan.json}}
api GET "/api/v1/jobs/$1/$artefact" -o "$out"
echo "$out"
