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
source "$(dirname "$0")/deb_helpers.sh"
deb_preconditions
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1

# 1. The package, lintian-clean, its dependencies.
build_deb "$build" "$work/pkg"
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

# 3. The admin adds a printer; the daemon runs as its unit says.
add_sim_printer
unit_start daemon.log || fail "salientd exited $status before it was ready"
echo "notify: $(head -1 notify.log)"
[ "$(stat -c '%U %a' /var/lib/salient/api-key)" = "salient 600" ] || fail "api-key: $(stat -c '%U %a' /var/lib/salient/api-key)"
grep -q "api key (shown once" daemon.log || fail "the first key is not in the log"

# 4. A job, printed on the simulated printer, with the installed CLI.
SALIENT_SERVER=$base SALIENT_API_KEY=$key timeout 600 /usr/bin/salient submit "$models/suzanne.obj" \
  --settings '{"up": "y", "height": 12}' --wait --print sim > submit.log 2>&1 || { cat submit.log; fail "submit --wait --print sim"; }
print_finished
echo "printed: $(printer_field "['last_print']['total']") lines on sim"
[ -n "$(find /var/lib/salient -newer notify.sock -user salient -print -quit)" ] || fail "nothing written as salient in /var/lib/salient"
unit_stop

# 5. Purge: nothing of the package, its user or its data is left.
purge_clean files.txt
echo "PASS"
