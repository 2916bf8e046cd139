#!/usr/bin/env bash
# salientd backup and restore: a backup taken while the daemon runs, slices a job and has files
# uploaded and deleted beside it, restored into a new data directory, serves every job, print and
# uploaded file of the backup, downloads byte for byte. Also: a backup with the daemon stopped,
# and the refusals (DEST exists, DEST not writable, a full disk, SRC no backup, a damaged backup,
# a running daemon's data directory), each with a clear error, a non-zero exit and nothing left.
#   backup_restore_e2e.sh SALIENTD MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 models=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
for m in "$work/ro" "$work/full"; do mountpoint -q "$m" 2>/dev/null && umount "$m"; done
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
churn=
cleanup() {
  [ -n "$churn" ] && kill "$churn" 2>/dev/null || true
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
  for m in "$work/ro" "$work/full"; do mountpoint -q "$m" 2>/dev/null && umount -l "$m"; done
  true
}
trap cleanup EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
job_state() { api "$base/api/v1/jobs/$1" | field "['state']"; }
wait_job() {
  for _ in $(seq 900); do [ "$(job_state "$1")" = done ] && return; sleep 0.2; done
  fail "job $1: $(api "$base/api/v1/jobs/$1")"
}
idle() { [ "$(api "$base/api/v1/printers/sim" | field "['state']")" = operational ]; }
# refused EXPECTED_TEXT COMMAND…: the command fails (non-zero) and says EXPECTED_TEXT.
refused() {
  local text=$1; shift
  if "$@" > refused.out 2>&1; then fail "succeeded: $* ($(cat refused.out))"; fi
  grep -q -- "$text" refused.out || fail "$*: expected '$text', got: $(cat refused.out)"
  echo "refused as expected: $(tail -1 refused.out)"
}

sim_config sim.toml "--advanced-ok --time-scale 0.02 --heat-time-scale 0"
start sim.toml data
eventually 30 idle > /dev/null || fail "the printer never became operational"
# Two sliced jobs, one of them printed; OctoPrint uploads, one printed, one in a folder.
j1=$(api -F "file=@$models/cube_binary.ply" -F 'settings={"height": 10}' "$base/api/v1/jobs" | field "['id']")
j2=$(api -F "file=@$models/spot.obj" -F 'settings={"height": 12}' "$base/api/v1/jobs" | field "['id']")
wait_job "$j1"; wait_job "$j2"
api -f -o /dev/null -d "{\"job\": \"$j1\"}" "$base/api/v1/printers/sim/print" || fail "print j1"
eventually 120 idle > /dev/null || fail "the print of j1 never ended"
printf 'G28\nG1 X10 Y10 F3000\nG1 X20\n' > small.gcode
python3 -c "print('G28'); [print(f'G1 X{i % 100} Y{i // 100}') for i in range(2000)]" > big.gcode
[ "$(api -o up.json -w '%{http_code}' -F "file=@small.gcode" -F print=true "$base/api/files/local")" = 201 ] || fail "upload: $(cat up.json)"
eventually 60 idle > /dev/null || fail "the print of small.gcode never ended"
api -f -o /dev/null -F "foldername=parts" "$base/api/files/local" || fail "folder"
api -f -o /dev/null -F "file=@big.gcode" -F path=parts "$base/api/files/local" || fail "upload into a folder"

# While the backup runs: a job being sliced, and uploads replaced and deleted (each delete
# sweeps the file it was the last reference to).
j3=$(api -F "file=@$models/stanford-bunny.obj" -F 'settings={"up": "y", "height": 30}' "$base/api/v1/jobs" | field "['id']")
(for i in $(seq 1000); do
  echo "G28 ; churn $i" > churn.gcode
  api -o /dev/null -F "file=@churn.gcode" "$base/api/files/local" || true
  api -o /dev/null -X DELETE "$base/api/files/local/churn.gcode" || true
done) &
churn=$!
sleep 0.5
"$salientd" backup live --data data > backup.out 2>&1 || { cat backup.out; fail "backup while running"; }
cat backup.out
kill "$churn" 2>/dev/null || true; wait "$churn" 2>/dev/null || true; churn=
grep -q "stored files" backup.out || fail "the backup's summary"
ls -a | grep -q "partial" && fail "a partial backup was left: $(ls -a)"

# The daemon's view now, to compare the restored one with (the snapshot has j3 in whatever state
# it was; the restored daemon re-queues a running job and slices it to done).
wait_job "$j3"
snapshot() {  # what a daemon serves: jobs, prints, files; and artefact downloads
  api "$base/api/v1/jobs?limit=1000" | /usr/bin/python3 -c "
import json,sys; print('\n'.join(sorted(j['id'] + ' ' + j['filename'] for j in json.load(sys.stdin)['jobs'])))" > "$1.jobs"
  api "$base/api/v1/printers/sim/prints" | /usr/bin/python3 -c "
import json,sys; print('\n'.join(f\"{p['id']} {p['file']} {p['state']} {p['confirmed']}/{p['total']}\" for p in json.load(sys.stdin)['prints']))" > "$1.prints"
  api "$base/api/files/local?recursive=true" | /usr/bin/python3 -c "
import json,sys
def walk(fs):
    for f in fs:
        yield f['path'] + ' ' + f['type']
        yield from walk(f.get('children', []))
print('\n'.join(sorted(l for l in walk(json.load(sys.stdin)['files']) if 'churn' not in l)))" > "$1.files"
  mkdir -p "$1.d"
  for j in "$j1" "$j2" "$j3"; do
    for a in gcode plot.svg model.3mf saliency.ply; do api -f -o "$1.d/$j.$a" "$base/api/v1/jobs/$j/$a" || fail "$1: $j/$a"; done
  done
  api -f -o "$1.d/small.gcode" "$base/downloads/files/local/small.gcode" || fail "$1: small.gcode"
  api -f -o "$1.d/big.gcode" "$base/downloads/files/local/parts/big.gcode" || fail "$1: parts/big.gcode"
}
snapshot before
stop
"$salientd" backup stopped --data data || fail "backup with the daemon stopped"
cmp <(ls -a data) <(ls -a data) > /dev/null

# Restored into a new data directory, a daemon on it serves all of it, byte for byte.
"$salientd" restore live --data restored || fail "restore"
start sim.toml restored
[ "$key" = "$(cat data/api-key)" ] || fail "the key file was not restored"
wait_job "$j3"
snapshot after
for part in jobs prints files; do
  diff "before.$part" "after.$part" || fail "the restored daemon's $part differ"
  echo "$part: $(wc -l < "before.$part") the same"
done
diff -r before.d after.d || fail "downloads differ"
echo "downloads: $(ls before.d | wc -l) files byte-identical"
# A print on the restored daemon.
api -f -o /dev/null -d "{\"job\": \"$j2\"}" "$base/api/v1/printers/sim/print" || fail "print on the restored daemon"
eventually 120 idle > /dev/null || fail "the print on the restored daemon never ended"
[ "$(api "$base/api/v1/printers/sim" | field "['last_print']['state']")" = finished ] || fail "restored print"

# Refusals: a clear message, a non-zero exit, nothing half-written.
refused "another salientd" "$salientd" restore stopped --data restored --force
stop
refused "already exists" "$salientd" backup live --data data
refused "not empty" "$salientd" restore stopped --data restored
"$salientd" restore stopped --data restored --force > /dev/null || fail "restore --force"
refused "not a salientd backup" "$salientd" restore data --data new1
refused "not a salientd data directory" "$salientd" backup b --data nowhere
cp -r stopped damaged
obj=$(find damaged/files/objects -type f | head -1)
printf 'x' >> "$obj"
refused "other bytes" "$salientd" restore damaged --data new2
[ -e new2/salient.db ] && fail "a damaged backup was half restored"
cp -r stopped broken && dd if=/dev/urandom of=broken/salient.db bs=4096 seek=1 count=4 conv=notrunc 2>/dev/null
refused "damaged" "$salientd" restore broken --data new3
if mkdir -p ro full && mount -t tmpfs -o size=1m,ro tmpfs ro 2>/dev/null; then
  refused "cannot write in" "$salientd" backup ro/b --data data
  mount -t tmpfs -o size=256k tmpfs full
  refused "No space left" "$salientd" backup full/b --data data
  [ -z "$(ls -A full)" ] || fail "a full disk left a partial backup: $(ls -A full)"
  umount ro; umount full
else
  echo "note: no tmpfs here (not root): the read-only and full-disk cases were not run"
fi
# Restored by root into the directory of the daemon's own user: the files are that user's, and a
# daemon running as that user starts on them.
if [ "$(id -u)" = 0 ] && command -v setpriv > /dev/null; then
  mkdir owned && chown 65534:65534 owned
  "$salientd" restore live --data owned > /dev/null || fail "restore into another user's directory"
  [ -z "$(find owned ! -user 65534)" ] || fail "restored files not given to the directory's owner: $(find owned ! -user 65534)"
  setpriv --reuid=65534 --regid=65534 --clear-groups "$salientd" --data owned --listen 127.0.0.1:0 2> owned.log &
  owned_pid=$!
  for _ in $(seq 100); do grep -q "listening on" owned.log && break; sleep 0.1; done
  grep -q "listening on" owned.log || { kill "$owned_pid"; fail "the owner's daemon did not start: $(cat owned.log)"; }
  kill -TERM "$owned_pid"; wait "$owned_pid" || fail "the owner's daemon: $(tail -3 owned.log)"
  echo "restored as root into nobody's directory: nobody's files, nobody's daemon starts on them"
fi
grep -q "terminate called\|Aborted" daemon.log && fail "a daemon aborted"
echo "ok: backup while running and stopped, restore into a new directory serves everything; bad input refused"
