#!/usr/bin/env bash
# The package's udev rule as udev reads it: `udevadm test` parses every rules file and names each
# key it cannot read (systemd 252 has no `udevadm verify`). The rule goes to /run/udev/rules.d for
# the run and is removed after; a copy with one broken key must be reported, or the check proves
# nothing. Which devices it matches needs the boards themselves: not tested here.
# Needs root and udevadm (skipped with exit 77 otherwise).
#   udev_rules_test.sh RULES_FILE
set -uo pipefail
rules=$1
[ "$(id -u)" = 0 ] || { echo "SKIP: needs root (a rules file in /run/udev/rules.d)"; exit 77; }
command -v udevadm >/dev/null || { echo "SKIP: udevadm is not installed (Debian's udev)"; exit 77; }
device=$(ls -d /sys/class/tty/tty1 /sys/class/tty/* 2>/dev/null | head -1)
[ -n "$device" ] || { echo "SKIP: no tty device in /sys to run udevadm test on"; exit 77; }
name=$(basename "$rules") broken=61-salient-test-broken.rules
log=$(mktemp)
trap 'rm -f "/run/udev/rules.d/$name" "/run/udev/rules.d/$broken" "$log"' EXIT
mkdir -p /run/udev/rules.d
cp "$rules" "/run/udev/rules.d/$name"
sed 's/^GROUP="dialout", MODE="0660"$/GRUOP="dialout", MODE="0660"/' "$rules" > "/run/udev/rules.d/$broken"
cmp -s "$rules" "/run/udev/rules.d/$broken" && { echo "FAIL: the broken copy is not broken"; exit 1; }
udevadm test --action=add "$device" > "$log" 2>&1
grep -q "Reading rules file: /run/udev/rules.d/$name" "$log" || { cat "$log"; echo "FAIL: udevadm did not read $name"; exit 1; }
if grep "/run/udev/rules.d/$name" "$log" | grep -v "Reading rules file"; then
  echo "FAIL: udevadm reports the lines above in $name"; exit 1
fi
grep -q "/run/udev/rules.d/$broken:[0-9]* Invalid key 'GRUOP'" "$log" ||
  { grep "$broken" "$log"; echo "FAIL: the broken copy's key was not reported: the check cannot fail"; exit 1; }
echo "udevadm test: $name read without a remark; a misspelt key in a copy is reported"
echo "PASS"
