#!/usr/bin/env bash
# print.sh JOB [PRINTER]: prints a finished job on a printer (default: sim); prints the printer.
set -euo pipefail
. "$(dirname "$0")/common.sh"
[ $# -ge 1 ] || { echo "usage: $0 JOB [PRINTER]" >&2; exit 2; }
api POST "/api/v1/printers/${2:-sim}/print" -H "Content-Type: application/json" -d "{\"job\": \"$1\"}"
echo
