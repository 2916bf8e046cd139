#!/usr/bin/env bash
# An upgrade and a downgrade of the Debian package, with data. The previous version is the commit
# FROM (an older database schema): the packaging did not exist then, so its salientd and
# salient-sim are built from `git archive FROM` (those targets alone: the test never runs the CLI,
# so the old package keeps today's `salient` rather than compile clients/ cold) and put into
# today's package under FROM's version number (0.1.0+git<commits>.<hash>, lower than today's). Then:
#   install it, add a printer to the config, slice and print a job with FROM's salientd;
#   install today's package over it: the config keeps the printer, the database is migrated to
#   today's schema, the job, its G-code, the print and the key are all there;
#   install FROM's package again (a downgrade): its salientd refuses the newer database, exits
#   non-zero with a message that says so, and writes nothing; today's package reads it again;
#   purge: nothing left.
# FROM's salientd predates sd_notify: it is taken as ready when it logs "listening on" (under
# systemd, a Type=notify unit would wait for it in vain; the releases to come all notify).
# Needs root, dpkg and git (skipped with exit 77 otherwise, or where a salient package or user is
# there already). FROM's build stays in WORK_DIR/old-build (built once, then reused).
#   deb_upgrade_test.sh BUILD_DIR SOURCE_DIR MODELS_DIR WORK_DIR FROM
set -uo pipefail
build=$1 source_dir=$2 models=$3 work=$4 from=$5
source "$(dirname "$0")/deb_helpers.sh"
deb_preconditions
[ -n "$from" ] || skip "no commit to upgrade from (CMake's SALIENT_UPGRADE_FROM is empty)"
command -v git >/dev/null || skip "git is not installed"
git -C "$source_dir" cat-file -e "$from^{commit}" 2>/dev/null || skip "commit $from is not in this clone (a shallow one?)"
mkdir -p "$work" && cd "$work" || exit 1
find . -mindepth 1 -maxdepth 1 ! -name old-build ! -name old-src -exec rm -rf {} +

# 1. FROM's binaries, and its package.
from_version="0.1.0+git$(git -C "$source_dir" rev-list --count "$from").$(git -C "$source_dir" rev-parse --short=8 "$from")"
if [ ! -x old-build/server/salientd ]; then
  rm -rf old-src old-build && mkdir old-src
  git -C "$source_dir" archive "$from" | tar -x -C old-src || fail "git archive $from"
  start=$SECONDS
  { cmake -S old-src -B old-build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSALIENT_TESTS=OFF -DSALIENT_BENCH=OFF &&
      cmake --build old-build --target salientd salient-sim; } > old-build.log 2>&1 ||
    { tail -30 old-build.log; fail "building $from"; }
  echo "built $from's salientd and salient-sim in $((SECONDS - start)) s"
fi
build_deb "$build" "$work/pkg"
new_deb=$deb new_version=$(dpkg-deb -f "$deb" Version)
dpkg-deb -R "$new_deb" old-tree || fail "dpkg-deb -R"
for program in salientd salient-sim; do
  path=old-build/server/$program
  [ "$program" = salient-sim ] && path=old-build/protocol/salient-sim
  install -m 0755 "$path" "old-tree/usr/bin/$program" && strip "old-tree/usr/bin/$program" || fail "$path"
done
# FROM's conffile is today's without the sections FROM did not know (it refuses unknown keys).
awk '/^\[zeroconf\]/ { skip = 1; next } skip && /^(\[|# A printer)/ { skip = 0 } !skip' \
  old-tree/etc/salient/salientd.toml > old.toml && mv old.toml old-tree/etc/salient/salientd.toml
sed -i "s/^Version: .*/Version: $from_version/" old-tree/DEBIAN/control
(cd old-tree && find . -path ./DEBIAN -prune -o -type f -printf '%P\n' | sort | xargs md5sum > DEBIAN/md5sums)
old_deb=$work/salient_${from_version}_old.deb
dpkg-deb --root-owner-group -b old-tree "$old_deb" > /dev/null || fail "dpkg-deb -b"
dpkg --compare-versions "$from_version" lt "$new_version" || fail "$from_version is not older than $new_version"
echo "old: $from_version, new: $new_version"

# 2. FROM's package, its data: a job sliced and printed.
dpkg -i "$old_deb" < /dev/null > dpkg-old.log 2>&1 || { cat dpkg-old.log; fail "dpkg -i (old)"; }
dpkg -L salient > files.txt
add_sim_printer
unit_start old.log listening || fail "the old salientd exited $status before it was ready"
old_key=$key
curl -s -f -o job.json -H "X-Api-Key: $key" -F "file=@$models/suzanne.obj" -F 'settings={"up": "y", "height": 12}' \
  "$base/api/v1/jobs" || fail "submit (old)"
job=$(field "['id']" < job.json)
for _ in $(seq 1200); do
  state=$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$job" | field "['state']")
  case $state in done) break;; failed|cancelled) fail "job $job $state";; esac
  sleep 0.1
done
[ "$state" = done ] || fail "job $job never finished (old)"
curl -s -f -o old.gcode -H "X-Api-Key: $key" "$base/api/v1/jobs/$job/gcode" || fail "G-code (old)"
curl -s -f -o /dev/null -H "X-Api-Key: $key" -d "{\"job\": \"$job\"}" "$base/api/v1/printers/sim/print" || fail "print (old)"
print_finished
old_print=$(printer_field "['last_print']['id']")
unit_stop
old_schema=$(schema_version)
echo "old salientd: job $job done, print $old_print finished, schema $old_schema"

# 3. Today's package over it.
# The shipped conffile changed since FROM and the admin edited theirs: as apt does unattended
# (--force-confdef --force-confold), the admin's is kept; the new keys have their defaults.
dpkg -i --force-confdef --force-confold "$new_deb" < /dev/null > dpkg-new.log 2>&1 ||
  { cat dpkg-new.log; fail "dpkg -i (upgrade)"; }
[ "$(dpkg-query -W -f='${Version}' salient)" = "$new_version" ] || fail "the upgrade did not install $new_version"
grep -qx 'id = "sim"' /etc/salient/salientd.toml || fail "the upgrade lost the admin's printer in the config"
unit_start new.log || fail "the new salientd exited $status before it was ready: $(cat new.log)"
[ "$key" = "$old_key" ] || fail "the key changed"
new_schema=$(schema_version)
[ "$new_schema" -gt "$old_schema" ] || fail "schema $new_schema after the upgrade, was $old_schema"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$job" | field "['state']")" = done ] || fail "job $job after the upgrade"
curl -s -f -o new.gcode -H "X-Api-Key: $key" "$base/api/v1/jobs/$job/gcode" || fail "G-code after the upgrade"
cmp -s old.gcode new.gcode || fail "the G-code changed in the upgrade"
[ "$(printer_field "['last_print']['id']")" = "$old_print" ] || fail "the print after the upgrade: $(printer_field "['last_print']")"
unit_stop
echo "upgraded: schema $old_schema -> $new_schema, job, G-code, print, key and config kept"

# 4. A downgrade: FROM's salientd refuses today's database and leaves it as it was.
jobs_before=$(/usr/bin/python3 -c "import sqlite3; c = sqlite3.connect('/var/lib/salient/salient.db'); print(c.execute('select count(*) from jobs').fetchone()[0])")
dpkg -i --force-confdef --force-confold "$old_deb" < /dev/null > dpkg-down.log 2>&1 || { cat dpkg-down.log; fail "dpkg -i (downgrade)"; }
unit_start down.log listening && fail "the old salientd started on a newer database"
[ "$status" != 0 ] || fail "the old salientd exited 0 on a newer database"
grep -q "newer than this salientd" down.log || fail "no clear message: $(cat down.log)"
echo "downgrade refused (exit $status): $(grep -o "error: .*" down.log | head -1)"
[ "$(schema_version)" = "$new_schema" ] || fail "the refused downgrade changed the schema to $(schema_version)"
dpkg -i --force-confdef --force-confold "$new_deb" < /dev/null > dpkg-again.log 2>&1 || { cat dpkg-again.log; fail "dpkg -i (again)"; }
unit_start again.log || fail "today's salientd after the refused downgrade: $(cat again.log)"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs" | field "['total']")" = "$jobs_before" ] ||
  fail "jobs lost after the refused downgrade"
[ "$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$job" | field "['state']")" = done ] || fail "job $job after the refused downgrade"
unit_stop

# 5. Purge.
purge_clean files.txt
echo "PASS"
