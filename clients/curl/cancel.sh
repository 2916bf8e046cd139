#!/usr/bin/env bash
# cancel.sh job JOB      cancels a queued or running job (removes a finished one)
# cancel.sh print [PRINTER]   cancels the print on a printer (default: sim)
set -euo pipefail
. "$(dirname "$0")/common.sh"
case "${1:-}" in
  job) [ $# -eq 2 ] || { echo "usage: $0 job JOB" >&2; exit 2; }; api DELETE "/api/v1/jobs/$2" ;;
  print) api POST "/api/v1/printers/${2:-sim}/cancel" ;;
  *) echo "usage: $0 job JOB | $0 print [PRINTER]" >&2; exit 2 ;;
esac
echo
