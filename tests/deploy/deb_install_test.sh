#!/usr/bin/env bash
# The Debian package on this machine, as an admin installs it: build it from the current build
# tree (cpack, no rebuild), check it with lintian, `dpkg -i` it, check its files, user and unit
# (systemd-analyze verify), run the unit's ExecStart line as the unit would (user salient with its
# groups, cwd /, a notify socket: READY=1, then STOPPING=1 at SIGTERM), print a job on a simulated
# printer added to the installed config, then `dpkg --purge` and find nothing left.
# Needs root and dpkg; skipped (exit 77) where the machine is not ours to change: a salient
# package or user already there. Whatever happens, the package is purged at the end.
#   deb_install_test.sh BUILD_DIR MODELS_DIR WORK_DIR
set -uo pipefail
build=$1 models=$2 work=$3

skip() { echo "SKIP: $*"; exit 77; }
[ "$(id -u)" = 0 ] || skip "needs root (dpkg -i, a system user)"
for tool in dpkg dpkg-deb cpack setpriv curl; do
  command -v "$tool" >/dev/null || skip "$tool is not installed"
done
if dpkg-query -W -f='${Status}' salient 2>/dev/null | grep -q installed; then
  skip "a salient package is installed on this machine: the test would replace and purge it"
fi
getent passwd salient >/dev/null && skip "a user 'salient' exists that no package made: the test would remove it"

rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
pid=
fail() {
  echo "FAIL: $*"
  [ -f daemon.log ] && tail -20 daemon.log
  exit 1
}
cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  if dpkg-query -W -f='${Status}' salient 2>/dev/null | grep -q installed; then
    dpkg --purge salient >/dev/null 2>&1
  fi
}
trap cleanup EXIT
field() { /usr/bin/python3 -c "import json,sys; d=json.load(sys.stdin); print(eval('d' + sys.argv[1]))" "$1"; }

# 1. The package, from the binaries already built (cpack installs them into its own staging tree).
cpack -G DEB -B "$work/pkg" --config "$build/CPackConfig.cmake" > cpack.log 2>&1 || { cat cpack.log; fail "cpack"; }
deb=$(ls "$work"/pkg/salient_*.deb) || fail "no .deb"
echo "package: $(basename "$deb")"
if command -v lintian >/dev/null; then
  lintian --fail-on error,warning "$deb" > lintian.log 2>&1 || { cat lintian.log; fail "lintian"; }
  echo "lintian: no error, no warning"
else
  echo "lintian is not installed: not checked (deploy/install-deps.sh installs it)"
fi
depends=$(dpkg-deb -f "$deb" Depends)
for dep in libjs-three libjs-chart.js adduser libsqlite3-0 libsystemd0; do
  [[ ", $depends," == *", $dep"[\ ,]* ]] || fail "Depends lacks $dep: $depends"
done

# 2. Installed: files, conffile, user and groups, data directory, unit.
dpkg -i "$deb" > dpkg.log 2>&1 || { cat dpkg.log; fail "dpkg -i"; }
dpkg -L salient > files.txt
for f in /usr/bin/salientd /usr/bin/salient /usr/bin/salient-sim; do
  [ -x "$f" ] || fail "$f is missing or not executable"
done
for f in /etc/salient/salientd.toml /lib/systemd/system/salientd.service /lib/udev/rules.d/60-salient-printers.rules \
         /usr/share/doc/salient/copyright /usr/share/man/man1/salientd.1.gz; do
  [ -f "$f" ] || fail "$f is missing"
done
dpkg-query -W -f='${Conffiles}\n' salient | grep -q "^ /etc/salient/salientd.toml " || fail "the config is not a conffile"
id -nG salient | tr ' ' '\n' | grep -qx dialout || fail "user salient is not in dialout: $(id salient)"
[ "$(stat -c '%U:%G %a' /var/lib/salient)" = "salient:salient 750" ] || fail "/var/lib/salient: $(stat -c '%U:%G %a' /var/lib/salient)"
unit=/lib/systemd/system/salientd.service
if command -v systemd-analyze >/dev/null; then
  systemd-analyze verify "$unit" > verify.log 2>&1 || { cat verify.log; fail "systemd-analyze verify $unit"; }
  [ -s verify.log ] && { cat verify.log; fail "systemd-analyze verify has remarks"; }
  echo "systemd-analyze verify: clean"
fi
# The default config serves the LAN and drives no printer.
grep -qx 'listen = "0.0.0.0:8080"' /etc/salient/salientd.toml || fail "the installed config's listen"
grep -qx 'printers = \[\]' /etc/salient/salientd.toml || fail "the installed config has printers"

# 3. The admin adds a printer as the config's comment says (here a simulated one, instant, on a
# free loopback port), and the daemon runs as its unit says.
sed -i -e '/^printers = \[\]$/d' -e 's/^listen = .*/listen = "127.0.0.1:0"/' /etc/salient/salientd.toml
cat >> /etc/salient/salientd.toml <<'TOML'

[[printers]]
id = "sim"
kind = "sim"
sim_args = "--advanced-ok --emergency-parser --autoreport --time-scale 0"
TOML
exec_start=$(sed -n 's/^ExecStart=//p' "$unit")
user=$(sed -n 's/^User=//p' "$unit") group=$(sed -n 's/^Group=//p' "$unit")
supplementary=$(sed -n 's/^SupplementaryGroups=//p' "$unit")
umask_value=$(sed -n 's/^UMask=//p' "$unit")
[ -n "$exec_start" ] && [ "$user" = salient ] || fail "unit: ExecStart '$exec_start', User '$user'"
echo "ExecStart: $exec_start (as $user:$group, groups $supplementary)"
chmod 755 "$work"
# The notify socket: what systemd would receive.
/usr/bin/python3 - "$work/notify.sock" > notify.log 2>&1 <<'PY' &
import os, socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1]); os.chmod(sys.argv[1], 0o666)
s.settimeout(300)
while True:
    message = s.recv(4096).decode()
    print(message.replace("\n", " "), flush=True)
    if "STOPPING=1" in message:
        break
PY
listener=$!
for _ in $(seq 50); do [ -S notify.sock ] && break; sleep 0.1; done
(
  cd / && umask "${umask_value:-0022}" &&
    exec env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin NOTIFY_SOCKET="$work/notify.sock" \
      setpriv --reuid="$user" --regid="$group" --groups="$group,${supplementary// /,}" -- $exec_start
) 2> daemon.log &
pid=$!
for _ in $(seq 600); do
  grep -q "READY=1" notify.log && break
  kill -0 "$pid" 2>/dev/null || fail "salientd exited before it was ready"
  sleep 0.1
done
grep -q "READY=1" notify.log || fail "no READY=1 on the notify socket: $(cat notify.log)"
echo "notify: $(head -1 notify.log)"
base=$(grep -o "http://127.0.0.1:[0-9]*" daemon.log | tail -1)
[ -n "$base" ] || fail "no address in the log"
key=$(cat /var/lib/salient/api-key) || fail "no /var/lib/salient/api-key"
[ "$(stat -c '%U %a' /var/lib/salient/api-key)" = "salient 600" ] || fail "api-key: $(stat -c '%U %a' /var/lib/salient/api-key)"
grep -q "api key (shown once" daemon.log || fail "the first key is not in the log"

# 4. A job, printed on the simulated printer, with the installed CLI.
SALIENT_SERVER=$base SALIENT_API_KEY=$key timeout 600 /usr/bin/salient submit "$models/suzanne.obj" \
  --settings '{"up": "y", "height": 12}' --wait --print sim > submit.log 2>&1 || { cat submit.log; fail "submit --wait --print sim"; }
printer_field() { curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim" | field "$1"; }
for _ in $(seq 1200); do
  [ "$(printer_field "['last_print']['state'] if d['last_print'] else ''")" = finished ] && break
  sleep 0.1
done
[ "$(printer_field "['last_print']['state']")" = finished ] || fail "print did not finish: $(curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim")"
[ "$(printer_field "['last_print']['confirmed'] == d['last_print']['total']")" = True ] || fail "print not complete"
echo "printed: $(printer_field "['last_print']['total']") lines on sim"
[ -n "$(find /var/lib/salient -newer notify.sock -user salient -print -quit)" ] || fail "nothing written as salient in /var/lib/salient"

kill -TERM "$pid"
wait "$pid"; status=$?
pid=
[ "$status" = 0 ] || fail "salientd exited $status after SIGTERM"
wait "$listener"
grep -q "STOPPING=1" notify.log || fail "no STOPPING=1: $(cat notify.log)"

# 5. Purge: nothing of the package, its user or its data is left.
dpkg --purge salient > purge.log 2>&1 || { cat purge.log; fail "dpkg --purge"; }
dpkg-query -W -f='${Status}' salient 2>/dev/null | grep -q installed && fail "still installed after purge"
while read -r f; do
  [ -d "$f" ] && continue  # shared directories (/usr/bin, /etc) stay
  [ -e "$f" ] && fail "$f is left after purge"
done < files.txt
for d in /etc/salient /var/lib/salient; do [ -e "$d" ] && fail "$d is left after purge"; done
getent passwd salient >/dev/null && fail "user salient is left after purge"
getent group salient >/dev/null && fail "group salient is left after purge"
echo "purged: no file, directory, user or group left"
echo "PASS"
