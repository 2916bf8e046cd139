#!/usr/bin/env bash
# Keys, users and roles against a running salientd with a simulated printer: a viewer reads and
# cannot print or submit (403); an operator prints and cannot make keys; a revoked key fails at
# once; OctoPrint's paths answer 403 without a key where /api/v1 answers 401; passive login and
# currentuser name the key's user; OctoPrint's application-key workflow with curl and
# `salient keys approve|deny`; the last admin key stays; a hex key of a data directory from
# before users still works after the migration; every new key is 43 URL-safe characters.
#   keys_roles_e2e.sh SALIENTD SALIENT WORKDIR
set -euo pipefail
salientd=$1 salient=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
code() { curl -s -o out.json -w '%{http_code}' "$@"; }  # the status; the body in out.json
expect() {  # expect STATUS WHAT curl-args…
  local want=$1 what=$2; shift 2
  local got; got=$(code "$@")
  [ "$got" = "$want" ] || fail "$what: HTTP $got, expected $want: $(head -c 300 out.json)"
}
eval_json() { python3 -c "import json,sys; d=json.load(sys.stdin); print(eval(sys.argv[1]))" "$1"; }
url_safe_43() { [[ "$1" =~ ^[A-Za-z0-9_-]{43}$ ]] || fail "key '$1' is not 43 URL-safe characters"; }
keys() { SALIENT_SERVER=$base SALIENT_API_KEY=$admin "$salient" keys "$@"; }
json='Content-Type: application/json'
printf 'G28\nG1 X10 Y10 F3000\n' > a.gcode
for i in $(seq 400); do echo "G1 X$((10 + i % 50)) Y20 F3000"; done >> a.gcode

sim_config s.toml "--advanced-ok --time-scale 0.05 --heat-time-scale 0"
start s.toml
url_safe_43 "$key"
admin=$key

# Keys for a viewer and an operator, made by the admin through the CLI.
viewer=$(keys create vic --role viewer --label phone) || fail "keys create vic"
operator=$(keys create otto --role operator) || fail "keys create otto"
url_safe_43 "$viewer"; url_safe_43 "$operator"
keys list | grep -q "otto *operator" || fail "keys list: $(keys list)"

# A viewer reads, and cannot print, submit or upload.
expect 200 "viewer GET /api/v1/printers" -H "X-Api-Key: $viewer" "$base/api/v1/printers"
expect 200 "viewer GET /api/job" -H "X-Api-Key: $viewer" "$base/api/job"
expect 403 "viewer uploads" -H "X-Api-Key: $viewer" -F "file=@a.gcode" "$base/api/files/local"
expect 403 "viewer prints" -H "X-Api-Key: $viewer" -H "$json" -d '{"file":"a.gcode"}' "$base/api/v1/printers/sim/print"
grep -q '"forbidden"' out.json || fail "403 body: $(cat out.json)"
expect 403 "viewer submits" -H "X-Api-Key: $viewer" -F "file=@a.gcode" "$base/api/v1/jobs"
# The nodes: a single salientd (SQLite) lists itself; there is no other node to forget.
expect 200 "viewer GET /api/v1/nodes" -H "X-Api-Key: $viewer" "$base/api/v1/nodes"
[ "$(eval_json "[(n['self'], n['live'], n['roles'], n['printers']) for n in d['nodes']]" < out.json)" = \
  "[(True, True, ['api', 'slicer', 'printers'], ['sim'])]" ] || fail "GET /api/v1/nodes: $(cat out.json)"
expect 403 "operator forgets a node" -H "X-Api-Key: $operator" -XDELETE "$base/api/v1/nodes/other"
expect 404 "forgetting a node on a single salientd" -H "X-Api-Key: $admin" -XDELETE "$base/api/v1/nodes/other"
node=$(curl -s "$base/healthz" | field "['node']")
expect 409 "forgetting this node" -H "X-Api-Key: $admin" -XDELETE "$base/api/v1/nodes/$node"
expect 403 "viewer starts /api/job" -H "X-Api-Key: $viewer" -H "$json" -d '{"command":"start"}' "$base/api/job"
expect 403 "viewer makes a key" -H "X-Api-Key: $viewer" -H "$json" -d '{"user":"vic","role":"admin"}' "$base/api/v1/keys"

# An operator prints, and cannot make keys (not even for itself) or decide app requests.
expect 201 "operator uploads" -H "X-Api-Key: $operator" -F "file=@a.gcode" "$base/api/files/local"
for _ in $(seq 300); do
  [ "$(curl -s -H "X-Api-Key: $operator" "$base/api/v1/printers/sim" | field "['state']")" = operational ] && break
  sleep 0.1
done
expect 202 "operator prints" -H "X-Api-Key: $operator" -H "$json" -d '{"file":"a.gcode"}' "$base/api/v1/printers/sim/print"
expect 202 "operator cancels" -H "X-Api-Key: $operator" -XPOST "$base/api/v1/printers/sim/cancel"
expect 403 "operator makes an admin key" -H "X-Api-Key: $operator" -H "$json" -d '{"user":"eve","role":"admin"}' "$base/api/v1/keys"
expect 403 "operator makes a viewer key" -H "X-Api-Key: $operator" -H "$json" -d '{"user":"eve"}' "$base/api/v1/keys"
if SALIENT_SERVER=$base SALIENT_API_KEY=$operator "$salient" keys create eve --role admin 2>err.txt; then fail "CLI: operator made a key"; fi
grep -q "403" err.txt || fail "CLI error: $(cat err.txt)"

# 401 on ours, 403 on OctoPrint's, for a missing, wrong or absurd key.
for k in "" wrong "$(head -c 8000 /dev/zero | tr '\0' k)" "$viewer$viewer"; do
  expect 401 "/api/v1 with key '${k:0:10}'" -H "X-Api-Key: $k" "$base/api/v1/printers"
  curl -s -D h.txt -o /dev/null -H "X-Api-Key: $k" "$base/api/v1/printers"
  grep -qi "^WWW-Authenticate: Bearer" h.txt || fail "no WWW-Authenticate on 401"
  for path in /api/job /api/printer /api/files/local /api/currentuser /downloads/files/local/a.gcode; do
    expect 403 "$path with key '${k:0:10}'" -H "X-Api-Key: $k" "$base$path"
  done
  expect 403 "POST /api/login with key '${k:0:10}'" -H "X-Api-Key: $k" -H "$json" -d '{"passive":true}' "$base/api/login"
done

# Passive login and the current user: the key's user, a session, OctoPrint's permissions.
expect 200 "viewer login" -H "X-Api-Key: $viewer" -H "$json" -d '{"passive":true}' "$base/api/login"
[ "$(field "['name']" < out.json)" = vic ] || fail "login name: $(cat out.json)"
[[ "$(field "['session']" < out.json)" =~ ^[A-Za-z0-9_-]{32}$ ]] || fail "session: $(cat out.json)"
[ "$(field "['admin']" < out.json)" = False ] || fail "a viewer is no admin"
[ "$(eval_json "'PRINT' in d['permissions']" < out.json)" = False ] || fail "a viewer may not print"
expect 200 "admin login" -H "X-Api-Key: $admin" -H "$json" -d '{"passive":true}' "$base/api/login"
[ "$(field "['name']" < out.json)" = admin ] && [ "$(field "['admin']" < out.json)" = True ] || fail "admin login"
expect 200 "currentuser" -H "X-Api-Key: $operator" "$base/api/currentuser"
[ "$(eval_json "[d['name'], 'PRINT' in d['permissions'], 'ADMIN' in d['permissions'], d['groups']]" < out.json)" = \
  "['otto', True, False, ['users']]" ] || fail "currentuser: $(cat out.json)"

# The WebSocket events take the new keys (header, ?apikey=, subprotocol); a wrong one is refused.
/usr/bin/python3 - "$port" "$viewer" <<'PY' || fail "events socket with a viewer key"
import json, sys, websocket
port, key = sys.argv[1], sys.argv[2]
for kw in ({"subprotocols": ["salient.v1", "salient-key." + key]}, {"header": ["X-Api-Key: " + key]}):
    ws = websocket.create_connection(f"ws://127.0.0.1:{port}/api/v1/events?topics=printers", timeout=10, **kw)
    assert json.loads(ws.recv())["type"], "no first message"
    ws.close()
ws = websocket.create_connection(f"ws://127.0.0.1:{port}/api/v1/events?apikey={key}", timeout=10)
ws.close()
try:
    websocket.create_connection(f"ws://127.0.0.1:{port}/api/v1/events", timeout=10,
                                subprotocols=["salient-key." + ("y" if key[0] == "x" else "x") + key[1:]])
    sys.exit("a wrong key was accepted")
except websocket.WebSocketBadStatusException as e:
    assert e.status_code == 401, e.status_code
PY

# Revoked: refused at once, everywhere; the last admin key stays (409).
vic_id=$(curl -s -H "X-Api-Key: $viewer" "$base/api/v1/keys" | field "['keys'][0]['id']")
keys revoke "$vic_id" > /dev/null || fail "keys revoke"
expect 401 "revoked key on /api/v1" -H "X-Api-Key: $viewer" "$base/api/v1/printers"
expect 403 "revoked key on /api/job" -H "X-Api-Key: $viewer" "$base/api/job"
if keys revoke "$vic_id" 2>/dev/null; then fail "revoking twice succeeded"; fi
admin_id=$(curl -s -H "X-Api-Key: $admin" "$base/api/v1/keys" | field "['you']['key']")
expect 409 "revoke the last admin key" -H "X-Api-Key: $admin" -XDELETE "$base/api/v1/keys/$admin_id"
expect 200 "the admin key still works" -H "X-Api-Key: $admin" "$base/api/v1/keys"
expect 400 "an unknown role" -H "X-Api-Key: $admin" -H "$json" -d '{"user":"x","role":"root"}' "$base/api/v1/keys"
expect 400 "a bad user name" -H "X-Api-Key: $admin" -H "$json" -d '{"user":"_api"}' "$base/api/v1/keys"
expect 409 "another role for otto" -H "X-Api-Key: $admin" -H "$json" -d '{"user":"otto","role":"admin"}' "$base/api/v1/keys"
expect 404 "revoke key 'abc'" -H "X-Api-Key: $admin" -XDELETE "$base/api/v1/keys/abc"
expect 404 "operator revokes the admin's key" -H "X-Api-Key: $operator" -XDELETE "$base/api/v1/keys/$admin_id"

# OctoPrint's application keys: probe, request, poll 202, approve with the CLI, poll 200 once.
expect 204 "probe" "$base/plugin/appkeys/probe"
curl -s -D h.txt -o out.json -H "$json" -d '{"app":"Cura"}' "$base/plugin/appkeys/request"
grep -q "^HTTP/1.1 201" h.txt || fail "request: $(head -1 h.txt) $(cat out.json)"
app_token=$(field "['app_token']" < out.json)
url_safe_43 "$app_token"
location=$(grep -i "^location:" h.txt | tr -d '\r' | cut -d' ' -f2)
[ "$location" = "$base/plugin/appkeys/request/$app_token" ] || fail "Location: $location"
expect 202 "poll before the decision" "$location"
token=$(keys requests --json | field "['requests'][0]['token']")
keys requests | grep -q "Cura" || fail "keys requests: $(keys requests)"
expect 403 "an operator decides" -H "X-Api-Key: $operator" -H "$json" -d '{"decision":true}' \
  "$base/plugin/appkeys/decision/$token"
expect 403 "a decision without a key" -H "$json" -d '{"decision":true}' "$base/plugin/appkeys/decision/$token"
keys approve "$token" > /dev/null || fail "keys approve"
expect 200 "poll after the approval" "$location"
app_key=$(field "['api_key']" < out.json)
url_safe_43 "$app_key"
expect 404 "the key is handed out once" "$location"
expect 200 "the app's key" -H "X-Api-Key: $app_key" "$base/api/currentuser"
[ "$(eval_json "[d['name'], 'PRINT' in d['permissions'], 'ADMIN' in d['permissions']]" < out.json)" = \
  "['apps', True, False]" ] || fail "the app's user: $(cat out.json)"
# Denied, through the CLI and through OctoPrint's decision: the poll answers 404.
app2=$(curl -s -H "$json" -d '{"app":"OctoPod","user":"otto"}' "$base/plugin/appkeys/request" | field "['app_token']")
token=$(keys requests --json | field "['requests'][0]['token']")
keys deny "$token" > /dev/null || fail "keys deny"
expect 404 "poll after a denial" "$base/plugin/appkeys/request/$app2"
app3=$(curl -s -H "$json" -d '{"app":"FDM Monster"}' "$base/plugin/appkeys/request" | field "['app_token']")
token=$(curl -s -H "X-Api-Key: $admin" "$base/api/v1/keys/requests" | field "['requests'][0]['token']")
expect 204 "OctoPrint's decision: deny" -H "X-Api-Key: $admin" -H "$json" -d '{"decision":false}' \
  "$base/plugin/appkeys/decision/$token"
expect 404 "poll after OctoPrint's denial" "$base/plugin/appkeys/request/$app3"
expect 404 "a decision on no request" -H "X-Api-Key: $admin" -H "$json" -d '{"decision":true}' \
  "$base/plugin/appkeys/decision/nothing"
if keys approve "no/such" 2>/dev/null; then fail "approve of a bad token succeeded"; fi
# Bounded: a fourth request from one address within a minute waits; a big body is not read.
expect 429 "a fourth request in a minute" -H "$json" -d '{"app":"spam"}' "$base/plugin/appkeys/request"
head -c 100000 /dev/zero | tr '\0' a > big.txt
expect 413 "a 100 KB request without a key" -H "$json" --data-binary @big.txt "$base/plugin/appkeys/request"
stop

# A data directory from before users (schema 3) with a hex key: the admin's after the migration.
start s.toml old
stop
hex=$(head -c 32 /dev/urandom | od -An -tx1 | tr -d ' \n')
/usr/bin/python3 - old/salient.db "$hex" <<'PY'
import hashlib, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.executescript("DROP INDEX api_keys_by_user; ALTER TABLE api_keys DROP COLUMN user; DROP TABLE users;"
                 "DROP TABLE folders; DROP TABLE settings;"
                 "ALTER TABLE prints DROP COLUMN filament_mm; ALTER TABLE prints DROP COLUMN paused_seconds;"
                 "DROP INDEX jobs_by_node; ALTER TABLE jobs DROP COLUMN node; ALTER TABLE jobs DROP COLUMN lease_until;"
                 "ALTER TABLE jobs DROP COLUMN cancel_requested; ALTER TABLE jobs DROP COLUMN requeues;"
                 "DROP TABLE event_payloads; DROP TABLE sessions; DROP TABLE app_key_requests; DROP TABLE nodes; DROP TABLE farm_printers; DROP TABLE printer_requests;"
                 "DELETE FROM api_keys; PRAGMA user_version = 3;")
db.execute("INSERT INTO api_keys (key_digest, label, created_at) VALUES (?, 'first start', 1)",
           (hashlib.sha256(sys.argv[2].encode()).hexdigest(),))
db.commit()
PY
echo "$hex" > old/api-key
start s.toml old
expect 200 "the hex key after the migration" -H "X-Api-Key: $hex" "$base/api/currentuser"
[ "$(eval_json "[d['name'], 'ADMIN' in d['permissions']]" < out.json)" = "['admin', True]" ] || fail "hex key: $(cat out.json)"
new=$(SALIENT_SERVER=$base SALIENT_API_KEY=$hex "$salient" keys create ada --role admin) || fail "create with the hex key"
url_safe_43 "$new"
stop
echo "keys and roles: viewer reads only, operator prints, admin manages keys; 401/403; login; appkeys; migration"
