# Shared by the scripts here: where salientd is and its key.
#   SALIENT_SERVER (default http://127.0.0.1:8080), SALIENT_API_KEY (default: var/api-key).
SALIENT_SERVER=${SALIENT_SERVER:-http://127.0.0.1:8080}
if [ -z "${SALIENT_API_KEY:-}" ]; then
  SALIENT_API_KEY=$(cat var/api-key 2>/dev/null) || { echo "set SALIENT_API_KEY (or run from where var/api-key is)" >&2; exit 2; }
fi
# api METHOD PATH [curl args…]: prints the body; fails (exit 22) on an HTTP error, showing it.
api() {
  local method=$1 path=$2; shift 2
  curl -sS --fail-with-body -X "$method" -H "X-Api-Key: $SALIENT_API_KEY" "$@" "$SALIENT_SERVER$path"
}
