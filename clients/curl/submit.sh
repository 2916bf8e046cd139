#!/usr/bin/env bash
# submit.sh MODEL [SETTINGS-JSON]: sends a model to slice; prints the job (its "id" is what the
# other scripts take).   e.g. submit.sh ../shared/models/stanford-bunny.obj '{"up": "y", "height": 40}'
# (settings matter: a model in metres or without "up" may come out a few mm tall; the job warns)
set -euo pipefail
. "$(dirname "$0")/common.sh"
[ $# -ge 1 ] || { echo "usage: $0 MODEL [SETTINGS-JSON]" >&2; exit 2; }
api POST /api/v1/jobs -F "file=@$1" ${2:+-F "settings=$2"}
echo
