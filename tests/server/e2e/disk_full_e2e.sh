#!/usr/bin/env bash
# salientd on a full disk (its data directory on a small tmpfs, filled up during a print): uploads
# and jobs fail with 507 and a message that names no path, the print goes on to the end, the
# daemon keeps serving, and once space is freed a job runs to done. Needs root (mount): without it
# the test is skipped (exit 77), never passed.
#   disk_full_e2e.sh SALIENTD MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 models=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
if mountpoint -q "$work/data" 2>/dev/null; then umount "$work/data"; fi
rm -rf "$work" && mkdir -p "$work/data" && cd "$work"
. "$here/../../support/salientd.sh"
if ! mount -t tmpfs -o size=8m tmpfs "$work/data" 2>/dev/null; then
  echo "SKIP: cannot mount a tmpfs here (needs root)"
  exit 77
fi
cleanup() {
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
  sleep 0.2
  umount "$work/data" 2>/dev/null || umount -l "$work/data" 2>/dev/null || true
}
trap cleanup EXIT
api() { curl -s -H "X-Api-Key: $key" "$@"; }
printer() { api "$base/api/v1/printers/sim" | field "$1"; }

python3 - > moves.gcode <<'PY'
print("G28\nG90\nM82\nG92 E0")
for i in range(3000):
    print(f"G1 X{20 + (i % 50) * 0.5:.2f} Y{20 + (i // 50) * 0.2:.2f} E{i * 0.02:.4f} F1800")
PY
sim_config sim.toml "--advanced-ok --time-scale 0.3 --heat-time-scale 0"
start sim.toml
for _ in $(seq 100); do [ "$(printer "['state']")" = operational ] && break; sleep 0.1; done
[ "$(api -o up.json -w '%{http_code}' -F "file=@moves.gcode" -F print=true "$base/api/files/local")" = 201 ] \
  || fail "upload: $(cat up.json)"
sleep 1
# Fill the disk to the last block.
dd if=/dev/zero of=data/filler bs=64k 2>/dev/null || true
sync
echo "disk: $(df -h data | tail -1)"

# Whatever needs space fails with 507 and says so, without naming where the data lives.
status=$(api -o job.json -w '%{http_code}' -F "file=@$models/spot.obj" -F 'settings={"height": 20}' "$base/api/v1/jobs")
[ "$status" = 507 ] || fail "a job on a full disk: $status $(cat job.json)"
field "['error']['message']" < job.json | grep -q "disk is full" || fail "message: $(cat job.json)"
grep -q "$work" job.json && fail "the message leaks the data path: $(cat job.json)"
printf 'G28\nG1 X1\n' > small.gcode
status=$(api -o up2.json -w '%{http_code}' -F "file=@small.gcode" "$base/api/files/local")
[ "$status" = 507 ] || fail "an upload on a full disk: $status $(cat up2.json)"
[ "$(curl -s "$base/healthz" | field "['status']")" = ok ] || fail "healthz on a full disk"

# The print goes on to the end although its progress cannot be saved.
for _ in $(seq 1200); do [ "$(printer "['state']")" = operational ] && break; sleep 0.1; done
[ "$(printer "['last_print']['state']")" = finished ] || fail "the print on a full disk: $(printer "['last_print']")"
[ "$(printer "['last_print']['confirmed']")" = "$(printer "['last_print']['total']")" ] || fail "print cut short"
echo "print finished on a full disk: $(printer "['last_print']['confirmed']") commands"

# Space comes back: a job runs to done.
rm -f data/filler
id=$(api -F "file=@$models/cube_binary.ply" -F 'settings={"height": 10}' "$base/api/v1/jobs" | field "['id']")
for _ in $(seq 600); do [ "$(api "$base/api/v1/jobs/$id" | field "['state']")" = done ] && break; sleep 0.2; done
[ "$(api "$base/api/v1/jobs/$id" | field "['state']")" = done ] || fail "a job after space came back: $(api "$base/api/v1/jobs/$id")"
kill -TERM "$pid"
wait "$pid" || fail "salientd exited with an error"
pid=
grep -q "terminate called\|Aborted" daemon.log && fail "the daemon aborted"
echo "ok: a full disk fails what needs space (507) and nothing else"
