#!/usr/bin/env bash
# Zeroconf as Cura and phone apps browse for OctoPrint: with [zeroconf] enabled salientd is found
# as _octoprint._tcp (and _http._tcp) with its port and OctoPrint's TXT records (path, version,
# api); a second one with the same name is renamed, not lost; a stopped one is withdrawn; one
# started before avahi-daemon is announced once avahi-daemon comes. A private D-Bus and
# avahi-daemon are started for the test (the machine's own are left alone).
#   zeroconf_e2e.sh SALIENTD WORKDIR
set -euo pipefail
salientd=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work"
. "$here/../../support/salientd.sh"
for tool in dbus-daemon avahi-daemon avahi-browse; do
  command -v "$tool" > /dev/null || { echo "skipped: $tool is not installed (deploy/install-deps.sh installs it)"; exit 77; }
done
bus_pid= avahi_pid= pid2=
cleanup() {
  for p in "$pid" "$pid2" "$avahi_pid" "$bus_pid"; do [ -n "$p" ] && kill -9 "$p" 2> /dev/null || true; done
}
trap cleanup EXIT
cat > bus.conf <<CONF
<!DOCTYPE busconfig PUBLIC "-//freedesktop//DTD D-Bus Bus Configuration 1.0//EN"
 "http://www.freedesktop.org/standards/dbus/1.0/busconfig.dtd">
<busconfig>
  <type>system</type>
  <listen>unix:path=$PWD/bus</listen>
  <auth>EXTERNAL</auth>
  <policy context="default">
    <allow user="*"/><allow own="*"/><allow send_destination="*"/><allow receive_sender="*"/>
  </policy>
</busconfig>
CONF
printf '[server]\nuse-ipv6=no\nratelimit-burst=1000\n[publish]\npublish-workstation=no\npublish-hinfo=no\n' > avahi.conf
export DBUS_SYSTEM_BUS_ADDRESS=unix:path=$PWD/bus
dbus-daemon --config-file=bus.conf --nofork > /dev/null 2>&1 &
bus_pid=$!
for _ in $(seq 100); do [ -S bus ] && break; sleep 0.05; done
[ -S bus ] || fail "the private D-Bus did not start"
start_avahi() {
  # Its pid file is /run/avahi-daemon/pid, whoever runs it: as root, a private mount there lets
  # this one run beside the machine's own.
  local private=()
  if [ "$(id -u)" = 0 ] && command -v unshare > /dev/null; then
    mkdir -p /run/avahi-daemon
    private=(unshare --mount --propagation private sh -c 'mount -t tmpfs tmpfs /run/avahi-daemon && exec "$@"' sh)
  fi
  "${private[@]}" avahi-daemon -f avahi.conf --no-drop-root --no-chroot --no-rlimits --no-proc-title > avahi.log 2>&1 &
  avahi_pid=$!
  for _ in $(seq 100); do grep -q "Server startup complete" avahi.log && return 0; sleep 0.1; done
  kill -0 "$avahi_pid" 2> /dev/null || { echo "skipped: avahi-daemon cannot run here: $(tail -3 avahi.log)"; exit 77; }
  fail "avahi-daemon did not start: $(cat avahi.log)"
}
# browse TYPE: resolved services, "name;port;txt" per line (avahi-browse's parsable output, its
# \DDD escapes of the name undone).
browse() {
  avahi-browse -rtpk "$1" 2> /dev/null | awk -F';' '$1 == "=" && $3 == "IPv4" { print $4 ";" $9 ";" $10 }' |
    perl -pe 's/\\(\d{3})/chr($1)/ge' | sort -u
}
found() {  # NAME PORT TYPE
  browse "$3" | awk -F';' -v p="$2" -v n="$1" '$1 == n && $2 == p { f = 1 } END { exit !f }'
}
zc_config() {
  cat > "$1" <<TOML
[zeroconf]
enabled = true
name = "$2"
[[printers]]
id = "sim"
kind = "sim"
sim_args = "--time-scale 0"
TOML
}

# 1. Started before avahi-daemon: no failure, announced once it comes.
name="salient e2e $$"
zc_config a.toml "$name"
start a.toml
grep -q "zeroconf: avahi-daemon is not running" daemon.log || fail "no word that avahi-daemon is missing"
curl -sf "$base/healthz" > /dev/null || fail "salientd does not serve without avahi-daemon"
start_avahi
eventually 30 found "$name" "$port" _octoprint._tcp > /dev/null || fail "not announced after avahi-daemon came: $(browse _octoprint._tcp)"
line=$(browse _octoprint._tcp | grep -F ";$port;")
for txt in '"path=/"' '"version=1.10.0"' '"api=0.1"' '"model=salientd '; do
  [[ "$line" == *"$txt"* ]] || fail "TXT record $txt missing: $line"
done
found "$name" "$port" _http._tcp || fail "not announced as _http._tcp: $(browse _http._tcp)"
grep -q "zeroconf: announced '$name'" daemon.log || fail "the announcement is not logged"
# 2. A second salientd with the same name: renamed "NAME #2", both found.
first_port=$port first_pid=$pid
"$salientd" --data data2 --listen 127.0.0.1:0 --config a.toml 2>> daemon2.log &
pid2=$!
for _ in $(seq 200); do grep -q "listening on" daemon2.log && break; sleep 0.05; done
port2=$(grep -o "http://127.0.0.1:[0-9]*" daemon2.log | tail -1); port2=${port2##*:}
eventually 30 found "$name #2" "$port2" _octoprint._tcp > /dev/null || fail "the second is not announced as '$name #2': $(browse _octoprint._tcp) $(cat daemon2.log)"
found "$name" "$first_port" _octoprint._tcp || fail "the first lost its name"
# 3. Stopped: withdrawn.
kill -TERM "$pid2"; wait "$pid2" || true; pid2=
gone() { ! found "$name #2" "$port2" _octoprint._tcp; }
eventually 30 gone > /dev/null || fail "a stopped salientd is still announced"
stop
# 4. A bad name is refused when the config is read.
zc_config bad.toml "$(head -c 64 /dev/zero | tr '\0' n)"
if "$salientd" --data data3 --listen 127.0.0.1:0 --config bad.toml 2> bad.log; then fail "a 64-byte name was accepted"; fi
grep -q "zeroconf.name" bad.log || fail "the error does not name zeroconf.name: $(cat bad.log)"
echo "zeroconf: found as _octoprint._tcp and _http._tcp with OctoPrint's TXT; announced after avahi-daemon came; a same-named second renamed '#2'; withdrawn on stop"
