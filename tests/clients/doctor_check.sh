#!/usr/bin/env bash
# salient doctor against a real salientd on loopback and a simulated board on a pseudo-terminal
# behind a symlink (as /dev/serial/by-id names a printer): a good setup passes (exit 0); a wrong
# key, a port another program holds, a user who may not open the device, a device that is gone
# and a daemon that is down each fail their own line with a fix (exit 1).
#   doctor_check.sh SALIENT SALIENTD SALIENT_SIM WORKDIR
set -euo pipefail
salient=$1 salientd=$2 sim_program=$3 work=$4
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../support/salientd.sh"
sim= holder=
cleanup() {
  for p in "$holder" "$sim" "$pid"; do [ -n "$p" ] && kill -9 "$p" 2>/dev/null; done
  true
}
trap cleanup EXIT
"$sim_program" --link "$work/printer" --advanced-ok > sim.out 2>&1 &
sim=$!
for _ in $(seq 100); do [ -e printer ] && break; sleep 0.05; done
cat > doctor.toml <<TOML
[[printers]]
id = "usb"
kind = "serial"
port = "$work/printer"
TOML
start doctor.toml data
for _ in $(seq 100); do curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/usb" | grep -q operational && break; sleep 0.1; done
device=$(readlink -f printer)
# doctor EXPECTED_STATUS [ARGS…]: runs it with the daemon's address, shows and keeps its output.
doctor() {
  local want=$1 got=0; shift
  "$salient" doctor --server "$base" --device "$work/printer" --data data "$@" > doctor.out 2>&1 || got=$?
  sed 's/^/  | /' doctor.out
  [ "$got" = "$want" ] || fail "doctor $*: exit $got, expected $want"
}
# line VERDICT NAME TEXT: doctor's output has that check with that verdict and text (and a fix
# when it is not ok).
line() {
  grep -E "^$1 +$2 .*$3" doctor.out > /dev/null || fail "no '$1 $2 … $3' line"
  if [ "$1" != ok ]; then grep -E "^$1 +$2 .*— fix: ." doctor.out > /dev/null || fail "'$2' has no fix"; fi
}

echo "good setup:"
doctor 0 --key "$key"
line ok serial "$device = $work/printer present"
line ok "in use" "$device: open by .*salientd \\(pid $pid\\)"
line ok daemon "answers"
line ok key "accepted"
line ok "printer usb" "operational"
line ok clock "(0|1) s"
line ok database "sqlite answers in [0-9.]+ ms, schema [0-9]+ \\(node "
line ok disk "MB free"

echo "no key given: the data directory's api-key is found, as after apt install (/var/lib/salient):"
unset SALIENT_API_KEY
doctor 0
line ok key "accepted"

echo "a wrong key:"
doctor 1 --key "x$key"
line FAIL key "HTTP 401"
[ "$(grep -c '^FAIL' doctor.out)" = 1 ] || fail "more than the key failed"

echo "another program holds the port:"
/usr/bin/python3 -c "import os,sys,time; fd = os.open(sys.argv[1], os.O_RDWR | os.O_NOCTTY); time.sleep(60)" "$device" &
holder=$!
for _ in $(seq 50); do ls -l "/proc/$holder/fd" 2>/dev/null | grep -q "$device" && break; sleep 0.1; done
doctor 1 --key "$key"
line FAIL "in use" "python3 \(pid $holder\)"
kill "$holder"; wait "$holder" 2>/dev/null || true; holder=

if [ "$(id -u)" = 0 ] && command -v setpriv > /dev/null; then
  echo "a user who may not open the device:"
  chmod 0660 "$device"
  got=0
  setpriv --reuid=65534 --regid=65534 --clear-groups "$salient" doctor --server "$base" --key "$key" \
    --device "$work/printer" --data data > doctor.out 2>&1 || got=$?
  sed 's/^/  | /' doctor.out
  [ "$got" = 1 ] || fail "doctor as nobody: exit $got"
  line FAIL access "$device: this user is not in group"
  grep -q "usermod -aG" doctor.out || fail "the access fix does not say which group to join"
  line ok "in use" "other users' are hidden"
  echo "no key given, and this user may not read the data directory's api-key:"
  got=0
  setpriv --reuid=65534 --regid=65534 --clear-groups "$salient" doctor --server "$base" --data data \
    > doctor.out 2>&1 || got=$?
  sed 's/^/  | /' doctor.out
  [ "$got" = 1 ] || fail "doctor as nobody without a key: exit $got"
  line FAIL key "may not read data/api-key"
  grep -q "sudo salient doctor" doctor.out || fail "the key fix does not say to run it as root"
fi

echo "the printer unplugged:"
kill -9 "$sim"; wait "$sim" 2>/dev/null || true; sim=; rm -f printer
for _ in $(seq 100); do curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/usb" | grep -q '"error"' && break; sleep 0.1; done
doctor 1 --key "$key"
line FAIL serial "$work/printer: no such device"
line FAIL "printer usb" "error: .*(is gone|disconnected)"

echo "the daemon down:"
stop
doctor 1 --key "$key"
line FAIL daemon "cannot reach salientd at 127.0.0.1:$port"
echo "ok: doctor passes a good setup and names each fault with its fix"
