#!/usr/bin/env bash
# Jobs across nodes, end to end: two salientd slicer nodes on one PostgreSQL with a short lease
# (2 s). A long job starts on one of them, which is then killed (-9) mid-job: the other node
# notices the lease expired, re-queues the job (the reason kept) and slices it; small jobs
# submitted through both nodes' APIs meanwhile are done too. Every job ends done exactly once:
# one "state=done" log line each across both nodes, attempts 1, and 2 for the killed one.
#   jobs_across_nodes_e2e.sh SALIENTD MODELS_DIR WORKDIR PG_DIR
# PG_DIR is the directory of the test cluster (tests/support/pg_cluster.sh); none: skipped (77).
set -euo pipefail
salientd=$1 models=$2 work=$3 pg_dir=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done' EXIT
if [ ! -s "$pg_dir/url" ]; then
  echo "skipped: $(cat "$pg_dir/skip" 2>/dev/null || echo "no test PostgreSQL in $pg_dir")"
  exit 77
fi
cluster=$(cat "$pg_dir/url")
export PGOPTIONS="-c client_min_messages=warning"
name=e2e_jobs_$$
psql -X -q "$cluster/postgres" -c "DROP DATABASE IF EXISTS $name" -c "CREATE DATABASE $name"
database="$cluster/$name"

for n in n1 n2; do
  printf '[node]\nid = "%s"\nroles = ["api", "slicer"]\nlease_seconds = 4\nmax_attempts = 3\n' "$n" > "$n.toml"
done
start n1.toml n1
pid1=$pid base1=$base
pids+=("$pid1")
mkdir -p n2 && cp n1/api-key n2/  # one farm, one key (in the database)
start n2.toml n2
pid2=$pid base2=$base
pids+=("$pid2")

job() { curl -s -H "X-Api-Key: $key" "$1/api/v1/jobs/$2"; }
submit() {  # submit BASE MODEL SETTINGS: the new job's id
  curl -s -H "X-Api-Key: $key" -F "file=@$models/$2" -F "settings=$3" "$1/api/v1/jobs" | field "['id']"
}

# The long job, and the node that runs it.
long=$(submit "$base1" stanford-bunny.obj '{"height": 40}')
for _ in $(seq 600); do
  [ "$(job "$base1" "$long" | field "['state']")" = running ] && break
  sleep 0.05
done
holder=$(job "$base1" "$long" | field "['node']")
case $holder in
  n1) victim=$pid1 survivor=$base2 ;;
  n2) victim=$pid2 survivor=$base1 ;;
  *) fail "job $long is not running on a node (node: $holder)" ;;
esac
small=()
for i in 1 2 3 4; do
  via=$base1; [ $((i % 2)) = 0 ] && via=$base2
  small+=("$(submit "$via" cube_binary.ply "{\"layers\": $((3 + i))}")")
done
sleep 1
[ "$(job "$survivor" "$long" | field "['state']")" = running ] || fail "job $long was not running when its node was killed"
kill -9 "$victim"
echo "killed node $holder (pid $victim) while it ran job $long"

base=$survivor
wait_state "$long" done
for id in "${small[@]}"; do wait_state "$id" done; done
body=$(job "$survivor" "$long")
[ "$(echo "$body" | field "['attempts']")" = 2 ] || fail "job $long: attempts $(echo "$body" | field "['attempts']"), expected 2"
[ "$(echo "$body" | field "['node']")" != "$holder" ] || fail "job $long was finished by the killed node"
reason=$(echo "$body" | field "['requeues'][0]['reason']")
[ "$reason" = "node $holder stopped renewing its lease" ] || fail "job $long: requeue reason '$reason'"
[ "$(echo "$body" | field "['requeues'][0]['node']")" = "$holder" ] || fail "job $long: requeue node"
for id in "${small[@]}"; do
  [ "$(job "$survivor" "$id" | field "['attempts']")" = 1 ] || fail "job $id ran more than once"
done
logged_done_once() { [ "$(grep -c "job id=$1 state=done" daemon.log || true)" = 1 ]; }
for id in "$long" "${small[@]}"; do  # logged just after the job's row is written: waited for
  eventually 10 logged_done_once "$id" > /dev/null ||
    fail "job $id was logged done $(grep -c "job id=$id state=done" daemon.log || true) times"
done
total=$(curl -s -H "X-Api-Key: $key" "$survivor/api/v1/jobs?state=done" | field "['total']")
[ "$total" = 5 ] || fail "$total jobs done, expected 5"
pid=$pid1; [ "$victim" = "$pid1" ] && pid=$pid2
stop
psql -X -q "$cluster/postgres" -c "DROP DATABASE $name"
echo "PASS: node $holder killed mid-job; its job re-queued (reason kept) and done by the other node, every job once"
