#!/usr/bin/env bash
# The farm-wide queue and prints chained to jobs, on two real simulators of one profile:
#  - five prints sent to the profile spread over both printers (auto_start: each takes the next
#    when it is done); every printer's log is exactly the files it was given, in order;
#  - a job submitted with "print": "a" is sliced, then printed on a; with {"profile": …} on
#    whichever is free; typos get 422 before any slicing; a job that fails drops its print;
#  - without auto_start, a printer whose bed holds a print takes nothing from the farm until its
#    bed is declared clear (POST …/queue/next), and the farm queue survives a restart.
#   farm_queue_e2e.sh SALIENTD SALIENT MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 salient=$2 models=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true' EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
farm_config() {  # farm_config FILE AUTO_START TAG (the simulators log to sim-ID-TAG.log)
  for id in a b; do
    cat <<TOML
[[printers]]
id = "$id"
kind = "sim"
profile = "generic-i3"
auto_start = $2
sim_args = "--advanced-ok --time-scale 0.02 --heat-time-scale 0 --log $PWD/sim-$id-$3.log"
TOML
  done > "$1"
}
state() { api "$base/api/v1/printers/$1" | field "['state']"; }
wait_idle() {
  for _ in $(seq 900); do [ "$(state a)" = operational ] && [ "$(state b)" = operational ] && return 0; sleep 0.1; done
  fail "printers never idle: $(state a) $(state b)"
}
finished() {  # finished N: both printers together finished N prints
  api "$base/api/v1/printers/a/prints" > pa.json
  api "$base/api/v1/printers/b/prints" > pb.json
  python3 - "$1" pa.json pb.json <<'PY'
import json, sys
n = sum(1 for f in sys.argv[2:] for p in json.load(open(f))["prints"] if p["state"] == "finished")
sys.exit(0 if n >= int(sys.argv[1]) else 1)
PY
}
# exact ID TAG [FIRST]: the printer's simulator (its log sim-ID-TAG.log) executed exactly what its
# prints from id FIRST on were, in order.
exact() {
  api "$base/api/v1/printers/$1/prints" > p$1.json
  python3 - "p$1.json" "${3:-0}" <<'PY' > prints-$1.txt
import json, sys
prints = [p for p in json.load(open(sys.argv[1]))["prints"] if p["id"] >= int(sys.argv[2])]
for p in sorted(prints, key=lambda p: p["id"]):
    print(("job " + p["job"]) if p["job"] else ("file " + p["file"]))
PY
  : > want-$1.gcode
  while read -r kind ref; do
    if [ "$kind" = job ]; then api "$base/api/v1/jobs/$ref/gcode" >> want-$1.gcode
    else api "$base/downloads/files/local/$ref" >> want-$1.gcode; fi
  done < prints-$1.txt
  same_commands want-$1.gcode sim-$1-$2.log
}
# F120: ~4 s a print at the simulators' 50x, long enough that a and b are still busy with f1 and f2
# while f3-f5 are sent (at F3000 a print took 0.2 s and a loaded machine saw a take f3 itself).
for n in 1 2 3 4 5; do
  python3 -c "
for i in range(200): print(f'G1 X{10 + i % 50 + $n} Y{10 + $n} F120')" > f$n.gcode
done

# 1. Five prints over two printers.
farm_config farm.toml true 1
start farm.toml
wait_idle
for n in 1 2 3 4 5; do api -o /dev/null -F "file=@f$n.gcode;filename=f$n.gcode" "$base/api/files/local"; done
for n in 1 2 3 4 5; do
  code=$(api -o s$n.json -w '%{http_code}' -XPOST -d "{\"file\":\"f$n.gcode\"}" "$base/api/v1/farm/generic-i3/print")
  [ "$code" = 202 ] || fail "farm print $n: $code $(cat s$n.json)"
done
[ "$(field "['id']" < s1.json)" = a ] && [ "$(field "['id']" < s2.json)" = b ] || fail "the first two did not start on a and b: $(cat s1.json s2.json)"
for n in 3 4 5; do
  [ "$(field "['queued']" < s$n.json)" = True ] && [ "$(field "['position']" < s$n.json)" = $((n - 2)) ] ||
    fail "print $n not queued in the farm: $(cat s$n.json)"
done
api "$base/api/v1/farm/generic-i3/queue" > fq.json
[ "$(field "['profile']" < fq.json)" = generic-i3 ] || fail "farm queue listing: $(cat fq.json)"
eventually 300 finished 5 > /dev/null || fail "five prints never finished: $(cat pa.json pb.json)"
wait_idle
exact a 1
exact b 1
[ "$(wc -l < prints-a.txt)" -ge 2 ] && [ "$(wc -l < prints-b.txt)" -ge 2 ] ||
  fail "not spread: a printed $(cat prints-a.txt | tr '\n' ' '), b $(cat prints-b.txt | tr '\n' ' ')"
api "$base/api/v1/farm/generic-i3/queue" | grep -q '"entries":\[\]' || fail "farm queue not empty"

# 2. Jobs that print once sliced.
for bad in 'print=zz' 'print={"profile":"nope"}'; do
  code=$(api -o bad.json -w '%{http_code}' -F "file=@$models/cube_binary.ply" -F "$bad" "$base/api/v1/jobs")
  [ "$code" = 422 ] && grep -q '"error"' bad.json || fail "$bad: $code $(cat bad.json)"
done
code=$(api -o bad.json -w '%{http_code}' -F "file=@$models/cube_binary.ply" -F 'print={"printer":1}' "$base/api/v1/jobs")
[ "$code" = 400 ] || fail "print as a number: $code $(cat bad.json)"
[ "$(api "$base/api/v1/jobs" | field "['total']")" = 0 ] || fail "a refused job was made"
settings='{"height": 8, "saliency": "uniform"}'
code=$(api -o j1.json -w '%{http_code}' -F "file=@$models/cube_binary.ply" -F "settings=$settings" -F "print=a" "$base/api/v1/jobs")
[ "$code" = 201 ] || fail "job with print: $code $(cat j1.json)"
[ "$(field "['print']['printer']" < j1.json)" = a ] && [ "$(field "['print']['queued']" < j1.json)" = True ] ||
  fail "the print does not wait for slicing: $(cat j1.json)"
job1=$(field "['id']" < j1.json)
eventually 300 finished 6 > /dev/null || fail "the sliced job never printed: $(cat pa.json)"
grep -q "\"job\":\"$job1\"" pa.json || fail "job $job1 did not print on a: $(cat pa.json)"
settings2='{"height": 9, "saliency": "uniform"}'
api -o j2.json -F "file=@$models/cube_binary.ply" -F "settings=$settings2" -F 'print={"profile":"generic-i3"}' "$base/api/v1/jobs"
job2=$(field "['id']" < j2.json)
eventually 300 finished 7 > /dev/null || fail "the job sent to the profile never printed: $(cat j2.json)"
# A job cancelled while it slices drops the print that waited for it.
api -o j3.json -F "file=@$models/stanford-bunny.obj" -F 'settings={"up": "y", "height": 60}' -F "print=b" "$base/api/v1/jobs"
job3=$(field "['id']" < j3.json)
api "$base/api/v1/printers/b/queue" | grep -q "\"job\":\"$job3\"" || fail "the print does not wait on b: $(api "$base/api/v1/printers/b/queue")"
api -o /dev/null -XDELETE "$base/api/v1/jobs/$job3"
eventually 60 sh -c "curl -s -H 'X-Api-Key: $key' $base/api/v1/printers/b/queue | grep -q '\"entries\":\[\]'" > /dev/null ||
  fail "the cancelled job's print still waits: $(api "$base/api/v1/printers/b/queue")"
wait_idle
exact a 1
exact b 1
stop

# 3. Without auto_start: full beds take nothing from the farm; the queue survives a restart.
farm_config manual.toml false 2
start manual.toml
wait_idle
for n in 1 2; do api -o m$n.json -XPOST -d "{\"file\":\"f$n.gcode\"}" "$base/api/v1/farm/generic-i3/print"; done
grep -q '"state":"printing"' m1.json && grep -q '"state":"printing"' m2.json || fail "idle printers did not start: $(cat m1.json m2.json)"
api -o m3.json -XPOST -d '{"file":"f3.gcode"}' "$base/api/v1/farm/generic-i3/print"
[ "$(field "['queued']" < m3.json)" = True ] || fail "third not queued: $(cat m3.json)"
eventually 300 finished 9 > /dev/null || fail "manual prints never finished"
wait_idle
sleep 1
[ "$(field "['position']" < <(api "$base/api/v1/farm/generic-i3/queue" | python3 -c "import json,sys; print(json.dumps(json.load(sys.stdin)['entries'][0]))"))" = 1 ] ||
  fail "a full bed took the farm's entry: $(api "$base/api/v1/farm/generic-i3/queue")"
stop
farm_config manual3.toml false 3
start manual3.toml
wait_idle
api "$base/api/v1/farm/generic-i3/queue" | grep -q '"file":"f3.gcode"' || fail "farm queue lost in a restart"
code=$(api -o nx.json -w '%{http_code}' -XPOST "$base/api/v1/printers/b/queue/next")
[ "$code" = 202 ] && [ "$(field "['started']['print']" < nx.json)" -gt 0 ] || fail "next from the farm: $code $(cat nx.json)"
first=$(field "['started']['print']" < nx.json)
eventually 300 finished 10 > /dev/null || fail "the farm entry never printed on b"
code=$(api -o e.json -w '%{http_code}' "$base/api/v1/farm/nope/queue")
[ "$code" = 404 ] || fail "unknown profile: $code $(cat e.json)"
code=$(api -o e.json -w '%{http_code}' -XDELETE "$base/api/v1/farm/generic-i3/queue/99999")
[ "$code" = 404 ] || fail "unknown farm entry: $code $(cat e.json)"
wait_idle
exact b 3 "$first"
stop
echo "farm queue: 5 prints over 2 printers exact; jobs print once sliced (printer, profile; 422 typos; a cancelled job drops its print); full beds wait; restart keeps the farm queue"
