#!/usr/bin/env bash
# Hostile conditions for a farm (issue 32, item 15): its PostgreSQL frozen, stopped and started
# again under two nodes. A (printer a1, api, slicer) and B (api only), leases of 3 s, on a cluster
# of the test's own (the shared one serves other tests):
#  1. frozen 12 s in the middle of a print on a1: the print goes on (the simulator executes lines
#     meanwhile), B never shows it interrupted, and it finishes;
#  2. stopped 8 s while A slices a job, which ends meanwhile: the job is not failed for good but
#     queued again, and done after;
#  3. after the restart every request to either node works (no 500 from a connection the restart
#     broke).
#   farm_postgres_faults.sh SALIENTD MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 models=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
pid_a= pid_b= frozen=
pg_pids() { pgrep -f -- "$pg_data" || true; }
cleanup() {
  set +e
  [ -n "$frozen" ] && kill -CONT $(pg_pids) 2>/dev/null
  for p in $pid_a $pid_b; do kill -9 "$p" 2>/dev/null; done
  bash "$here/../../support/pg_cluster.sh" stop "$work/pg" >/dev/null 2>&1
  return 0
}
trap cleanup EXIT
code=0
bash "$here/../../support/pg_cluster.sh" start "$work/pg" || code=$?
if [ "$code" = 77 ]; then echo "skipped: $(cat pg/skip)"; exit 77; fi
[ "$code" = 0 ] || fail "the test's PostgreSQL did not start"
url=$(cat pg/url) pg_bin=$(cat pg/bin) pg_dir=$(cat pg/cluster)
pg_data=$pg_dir/data pg_port=${url##*:}
as_owner=()
[ "$(id -u)" != 0 ] || as_owner=(setpriv --reuid=nobody --regid=nogroup --clear-groups --)
pg_ctl() { "${as_owner[@]}" "$pg_bin/pg_ctl" -D "$pg_data" "$@" >/dev/null; }
pg_stop() { pg_ctl -m fast -w stop; }
pg_start() {
  pg_ctl -l "$pg_dir/server.log" -w -t 60 \
    -o "-p $pg_port -k $pg_dir -c listen_addresses=127.0.0.1 -c fsync=off -c max_connections=200" start
}
export PGOPTIONS="-c client_min_messages=warning"
psql -X -q "$url/postgres" -c "CREATE DATABASE farm"
database="$url/farm"

cat > a.toml <<TOML
[node]
id = "A"
lease_seconds = 3

[[printers]]
id = "a1"
kind = "sim"
sim_args = "--advanced-ok --time-scale 0.05 --heat-time-scale 0 --log $PWD/sim.log"
TOML
printf '[node]\nid = "B"\nroles = ["api"]\nlease_seconds = 3\n' > b.toml
start a.toml data-a
pid_a=$pid base_a=$base
mkdir data-b && cp data-a/api-key data-b/  # the key is in the database; the file is for curl
start b.toml data-b
pid_b=$pid base_b=$base
api() { curl -s --max-time 10 -H "X-Api-Key: $key" "$@"; }
a1_on_b() { api "$base_b/api/v1/printers/a1/prints" | field "['prints'][0]['state']" 2>/dev/null || echo "?"; }
for _ in $(seq 600); do
  [ "$(api "$base_a/api/v1/printers/a1" | field "['state']" 2>/dev/null)" = operational ] && break
  api -o /dev/null -XPOST "$base_a/api/v1/printers/a1/connect"
  sleep 0.1
done

echo "1. PostgreSQL frozen 12 s mid-print:"
# 900 moves of 10 mm at 10 mm/s: 45 s at the simulator's 20x.
python3 -c "
for i in range(900): print(f'G1 X{10 + 10 * (i % 2)} Y{20 + i % 50} F600')" > slow.gcode
api -o /dev/null -F "file=@slow.gcode;filename=slow.gcode" "$base_a/api/files/local"
status=$(api -o print.json -w '%{http_code}' -XPOST -d '{"file": "slow.gcode"}' "$base_a/api/v1/printers/a1/print")
[ "$status" = 202 ] || fail "the print on a1: $status $(cat print.json)"
for _ in $(seq 300); do [ "$(a1_on_b)" = printing ] && break; sleep 0.1; done
[ "$(a1_on_b)" = printing ] || fail "B does not see a1 printing ($(a1_on_b))"
sleep 2
frozen=1
kill -STOP $(pg_pids)
before=$(wc -l < sim.log)
sleep 12
during=$(( $(wc -l < sim.log) - before ))
kill -CONT $(pg_pids)
frozen=
echo "  the simulator executed $during lines while PostgreSQL was frozen 12 s"
[ "$during" -gt 100 ] || fail "the print stood still while the database was frozen ($during lines in 12 s)"
seen=
for _ in $(seq 100); do  # 10 s after the thaw, as B lists a1's print
  state=$(a1_on_b)
  seen="$seen $state"
  [ "$state" != interrupted ] || fail "B called the running print interrupted after the freeze:$seen"
  sleep 0.1
done
for _ in $(seq 900); do [ "$(a1_on_b)" = finished ] && break; sleep 0.1; done
[ "$(a1_on_b)" = finished ] || fail "the print did not finish after the freeze ($(a1_on_b))"
echo "  B never showed it interrupted; it finished"

echo "2. PostgreSQL stopped 8 s while A slices a job:"
# A job of a second or two: it ends, and its result is stored, while the database is away.
id=$(api -F "file=@$models/suzanne.obj" -F 'settings={"height": 30}' "$base_a/api/v1/jobs" | field "['id']")
for _ in $(seq 600); do
  [ "$(api "$base_a/api/v1/jobs/$id" | field "['state']")" = running ] && break
  sleep 0.05
done
pg_stop
sleep 8
pg_start
state=
for _ in $(seq 1800); do
  state=$(api "$base_a/api/v1/jobs/$id" | field "['state']" 2>/dev/null) || state="?"
  case $state in done) break ;; failed | cancelled) fail "the job ended $state: $(api "$base_a/api/v1/jobs/$id")" ;; esac
  sleep 0.1
done
[ "$state" = done ] || fail "the job was not done 3 minutes after PostgreSQL came back ($state)"
api "$base_a/api/v1/jobs/$id" > job.json
echo "  the job is done: attempts $(field "['attempts']" < job.json), requeues $(field "['requeues']" < job.json)"
[ "$(field "['attempts']" < job.json)" -ge 2 ] || fail "the job did not meet the outage (attempts: $(cat job.json))"

echo "3. after the restart, every request works on both nodes:"
for base in "$base_a" "$base_b"; do
  for n in $(seq 30); do
    status=$(curl -s --max-time 10 -o /dev/null -w '%{http_code}' -H "X-Api-Key: $key" "$base/api/v1/jobs?limit=5")
    [ "$status" = 200 ] || fail "request $n to $base after the restart: $status"
  done
done
echo "ok: the farm rode out PostgreSQL frozen and stopped"
