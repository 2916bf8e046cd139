#!/usr/bin/env bash
# salientd under systemd's eyes, without systemd: a notify socket as Type=notify gives it
# (NOTIFY_SOCKET: READY=1 once it listens, STOPPING=1 at SIGTERM), and JOURNAL_STREAM naming its
# stderr as the journal (log lines without a timestamp of their own: journald stamps them).
# Inherited JOURNAL_STREAM naming another stream, or no NOTIFY_SOCKET: timestamps, and no socket.
#   systemd_notify_test.sh SALIENTD WORK_DIR
set -uo pipefail
salientd=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
pid= listener=
fail() {
  echo "FAIL: $*"
  tail -5 daemon.log 2>/dev/null
  exit 1
}
cleanup() { [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; [ -n "$listener" ] && kill "$listener" 2>/dev/null; }
trap cleanup EXIT
printf 'printers = []\n' > salientd.toml
stamped='^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:]{8}Z '

# run LOG [ENV…]: start salientd on a free loopback port with its stderr in LOG; sets $pid
run() {
  local log=$1; shift
  : > "$log"
  env "$@" "$salientd" --config salientd.toml --data data --listen 127.0.0.1:0 2>> "$log" &
  pid=$!
  for _ in $(seq 600); do
    grep -q "listening on" "$log" && return 0
    kill -0 "$pid" 2>/dev/null || fail "salientd exited: $(cat "$log")"
    sleep 0.05
  done
  fail "salientd did not start"
}
stop() {
  kill -TERM "$pid"; wait "$pid"; local status=$?; pid=
  [ "$status" = 0 ] || fail "salientd exited $status after SIGTERM"
}

# 1. Under systemd: notifications, and lines as the journal wants them.
/usr/bin/python3 "$(dirname "$0")/../support/notify_listener.py" "$work/notify.sock" 120 > notify.log 2>&1 &
listener=$!
for _ in $(seq 50); do [ -S notify.sock ] && break; sleep 0.1; done
: > journal.log
run journal.log NOTIFY_SOCKET="$work/notify.sock" JOURNAL_STREAM="$(stat -c '%d:%i' journal.log)"
for _ in $(seq 100); do grep -q READY=1 notify.log && break; sleep 0.1; done
grep -q "^READY=1 STATUS=listening on 127.0.0.1:[0-9]*$" notify.log || fail "no READY=1 with the address: $(cat notify.log)"
stop
wait "$listener"; listener=
grep -q "^STOPPING=1" notify.log || fail "no STOPPING=1: $(cat notify.log)"
grep -Eq "$stamped" journal.log && fail "a timestamp in a line for the journal: $(grep -E "$stamped" journal.log | head -1)"
grep -q "^salientd .* listening on http://127.0.0.1:" journal.log || fail "the lines for the journal: $(cat journal.log)"
echo "notify: $(tr '\n' '|' < notify.log)"
echo "journal: $(head -1 journal.log)"

# 2. JOURNAL_STREAM inherited by a salientd whose stderr goes elsewhere, and no notify socket:
# its own timestamps, and it runs as ever.
: > other.log
run daemon.log JOURNAL_STREAM="$(stat -c '%d:%i' other.log)"
stop
grep -Eq "${stamped}salientd .* listening on" daemon.log || fail "no timestamp outside the journal: $(head -1 daemon.log)"
echo "elsewhere: $(grep "listening on" daemon.log)"
echo "PASS"
