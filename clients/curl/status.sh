#!/usr/bin/env bash
# status.sh [JOB]: one job (state, phase, progress, result), or the newest jobs.
set -euo pipefail
. "$(dirname "$0")/common.sh"
api GET "/api/v1/jobs${1:+/$1}"
echo
