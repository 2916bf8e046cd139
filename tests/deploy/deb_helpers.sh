# Shell helpers for the package tests (sourced): preconditions, the .deb of a build tree, salientd
# started as the installed unit says, the purge check. The caller works in its own directory.
pid= listener=
fail() {
  echo "FAIL: $*"
  [ -f daemon.log ] && tail -20 daemon.log
  exit 1
}
skip() { echo "SKIP: $*"; exit 77; }
field() { /usr/bin/python3 -c "import json,sys; d=json.load(sys.stdin); print(eval('d' + sys.argv[1]))" "$1"; }
installed() { dpkg-query -W -f='${Status}' salient 2>/dev/null | grep -q "ok installed"; }

# The machine must be ours to change: root, dpkg, and no salient package or user already there.
# On exit the daemon is killed and the package purged, whatever happened.
deb_preconditions() {
  [ "$(id -u)" = 0 ] || skip "needs root (dpkg -i, a system user)"
  local tool
  for tool in dpkg dpkg-deb cpack setpriv curl; do
    command -v "$tool" >/dev/null || skip "$tool is not installed"
  done
  installed && skip "a salient package is installed on this machine: the test would replace and purge it"
  getent passwd salient >/dev/null && skip "a user 'salient' exists that no package made: the test would remove it"
  trap deb_cleanup EXIT
}
deb_cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  [ -n "$listener" ] && kill "$listener" 2>/dev/null
  # Any state but gone, a half-configured one ("install ok unpacked") too.
  if dpkg-query -W -f='${Status}' salient 2>/dev/null | grep -qv "not-installed"; then
    dpkg --purge salient > /dev/null 2>&1
  fi
}

# build_deb BUILD_DIR OUT_DIR: the package of a build tree's binaries (cpack installs them into its
# own staging tree, nothing is rebuilt); sets $deb.
build_deb() {
  cpack -G DEB -B "$2" --config "$1/CPackConfig.cmake" > cpack.log 2>&1 || { cat cpack.log; fail "cpack"; }
  deb=$(ls "$2"/salient_*.deb) || fail "no .deb in $2"
}

# add_sim_printer: what an admin does to the installed config, as its comment says (here a
# simulated printer, instant, on a free loopback port).
add_sim_printer() {
  sed -i -e '/^printers = \[\]$/d' -e 's/^listen = .*/listen = "127.0.0.1:0"/' /etc/salient/salientd.toml
  cat >> /etc/salient/salientd.toml <<'TOML'

[[printers]]
id = "sim"
kind = "sim"
sim_args = "--advanced-ok --emergency-parser --autoreport --time-scale 0"
TOML
}

# unit_start LOG [listening]: /usr/bin/salientd started as the installed unit's ExecStart, User,
# Group, SupplementaryGroups and UMask say, in / with a clean environment and a notify socket (what
# systemd would receive goes to notify.log). Returns 1 (and sets $status) if it exits before it is
# ready; else sets $pid, $base (its URL) and $key (the admin key in /var/lib/salient). Ready is
# READY=1 on the socket; with "listening", its "listening on" log line (a salientd from before
# sd_notify, which sends nothing).
unit_start() {
  local log=$1 ready="READY=1" ready_file=notify.log unit=/lib/systemd/system/salientd.service exec_start user group supplementary mask
  exec_start=$(sed -n 's/^ExecStart=//p' "$unit")
  user=$(sed -n 's/^User=//p' "$unit") group=$(sed -n 's/^Group=//p' "$unit")
  supplementary=$(sed -n 's/^SupplementaryGroups=//p' "$unit") mask=$(sed -n 's/^UMask=//p' "$unit")
  if [ "${2:-}" = listening ]; then ready="listening on" ready_file=$log; fi
  notified=$([ "${2:-}" = listening ] && echo no || echo yes)
  [ -n "$exec_start" ] && [ -n "$user" ] || fail "unit: ExecStart '$exec_start', User '$user'"
  echo "ExecStart: $exec_start (as $user:$group, groups $supplementary, umask $mask)"
  chmod 755 "$PWD"
  rm -f notify.sock notify.log
  /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/../support/notify_listener.py" "$PWD/notify.sock" > notify.log 2>&1 &
  listener=$!
  for _ in $(seq 50); do [ -S notify.sock ] && break; sleep 0.1; done
  : > "$log"
  (
    cd / && umask "${mask:-0022}" &&
      exec env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin NOTIFY_SOCKET="$OLDPWD/notify.sock" \
        setpriv --reuid="$user" --regid="$group" --groups="$group,${supplementary// /,}" -- $exec_start
  ) 2>> "$log" &
  pid=$!
  for _ in $(seq 600); do
    grep -q "$ready" "$ready_file" && break
    if ! kill -0 "$pid" 2>/dev/null; then
      wait "$pid"; status=$? pid=
      kill "$listener" 2>/dev/null; listener=
      return 1
    fi
    sleep 0.1
  done
  grep -q "$ready" "$ready_file" || fail "not ready ('$ready' in $ready_file): $(cat "$ready_file")"
  base=$(grep -o "http://127.0.0.1:[0-9]*" "$log" | tail -1)
  [ -n "$base" ] || fail "no address in $log"
  key=$(cat /var/lib/salient/api-key) || fail "no /var/lib/salient/api-key"
}
# unit_stop: SIGTERM, as systemctl stop; salientd must exit 0 having sent STOPPING=1 (if it
# notifies at all).
unit_stop() {
  kill -TERM "$pid"
  wait "$pid"; local status=$?
  pid=
  [ "$status" = 0 ] || fail "salientd exited $status after SIGTERM"
  if [ "$notified" = yes ]; then
    wait "$listener"; listener=
    grep -q "STOPPING=1" notify.log || fail "no STOPPING=1: $(cat notify.log)"
  else
    kill "$listener" 2>/dev/null; wait "$listener" 2>/dev/null; listener=
  fi
}

# print_finished: wait until the simulated printer's last print has finished, every line confirmed.
printer_field() { curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim" | field "$1"; }
print_finished() {
  for _ in $(seq 1200); do
    [ "$(printer_field "['last_print']['state'] if d['last_print'] else ''")" = finished ] && break
    sleep 0.1
  done
  [ "$(printer_field "['last_print']['state']")" = finished ] || fail "print did not finish: $(curl -s -H "X-Api-Key: $key" "$base/api/v1/printers/sim")"
  [ "$(printer_field "['last_print']['confirmed'] == d['last_print']['total']")" = True ] || fail "print not complete"
}

# purge_clean FILES: dpkg --purge, then nothing of FILES (dpkg -L before), the user, the group,
# /etc/salient or /var/lib/salient is left.
purge_clean() {
  dpkg --purge salient > purge.log 2>&1 || { cat purge.log; fail "dpkg --purge"; }
  installed && fail "still installed after purge"
  local f
  while read -r f; do
    [ -d "$f" ] && continue  # shared directories (/usr/bin, /etc) stay
    [ -e "$f" ] && fail "$f is left after purge"
  done < "$1"
  for f in /etc/salient /var/lib/salient; do [ -e "$f" ] && fail "$f is left after purge"; done
  getent passwd salient >/dev/null && fail "user salient is left after purge"
  getent group salient >/dev/null && fail "group salient is left after purge"
  echo "purged: no file, directory, user or group left"
}

# schema_version: PRAGMA user_version of the installed daemon's database.
schema_version() {
  /usr/bin/python3 -c "import sqlite3; print(sqlite3.connect('/var/lib/salient/salient.db').execute('PRAGMA user_version').fetchone()[0])"
}
