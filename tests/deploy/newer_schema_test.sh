#!/usr/bin/env bash
# A downgrade, without packages: salientd started on a database a newer salientd wrote (its
# user_version beyond this one's migrations) exits non-zero at once with a message that says so,
# and leaves the database as it was (schema, rows).
#   newer_schema_test.sh SALIENTD WORK_DIR
set -uo pipefail
salientd=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail() { echo "FAIL: $*"; tail -5 daemon.log; exit 1; }
printf 'printers = []\n' > salientd.toml
sql() { /usr/bin/python3 -c "import sqlite3, sys; c = sqlite3.connect('data/salient.db'); r = c.execute(sys.argv[1]).fetchone(); c.commit(); print(r[0] if r else '')" "$1"; }

# A database as this salientd makes it, then as a newer one would leave it.
"$salientd" --config salientd.toml --data data --listen 127.0.0.1:0 2> daemon.log &
pid=$!
for _ in $(seq 600); do grep -q "listening on" daemon.log && break; sleep 0.05; done
grep -q "listening on" daemon.log || fail "salientd did not start"
kill -TERM "$pid"; wait "$pid" || fail "salientd did not stop cleanly"
ours=$(sql "PRAGMA user_version")
[ "$ours" -ge 1 ] || fail "schema version $ours"
newer=$((ours + 1))
sql "PRAGMA user_version = $newer" > /dev/null
sql "CREATE TABLE from_the_future (x)" > /dev/null
before=$(sql "SELECT group_concat(name) FROM sqlite_master")

timeout 60 "$salientd" --config salientd.toml --data data --listen 127.0.0.1:0 2> daemon.log
status=$?
[ "$status" = 124 ] && fail "salientd kept running on a newer database"
[ "$status" != 0 ] || fail "salientd exited 0 on a newer database"
grep -q "^salientd: error: the database has schema version $newer, newer than this salientd ($ours)" daemon.log ||
  fail "no clear message: $(cat daemon.log)"
grep -q "listening on" daemon.log && fail "it listened before refusing"
[ "$(sql "PRAGMA user_version")" = "$newer" ] || fail "the schema version changed to $(sql "PRAGMA user_version")"
[ "$(sql "SELECT group_concat(name) FROM sqlite_master")" = "$before" ] || fail "the tables changed"
echo "refused (exit $status): $(cat daemon.log)"
echo "PASS"
