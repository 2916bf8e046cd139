# Shell helpers for the tests that run salientd (sourced): start and stop it on a free loopback
# port, write a config with a simulated printer, compare a simulator's log with a G-code file.
# The caller sets $salientd and works in its own directory; logs go to daemon.log there.
pid=
fail() { echo "FAIL: $*"; tail -20 daemon.log; exit 1; }
field() { python3 -c "import json,sys; d=json.load(sys.stdin); print(eval('d' + sys.argv[1]))" "$1"; }

# start [CONFIG] [DATA]: salientd on a free port; sets $pid, $base, $port and $key. With $database
# set, on that store (--database).
start() {
  local before data=${2:-data}
  before=$(grep -c "listening on" daemon.log 2>/dev/null || true)
  "$salientd" --data "$data" --listen 127.0.0.1:0 ${1:+--config "$1"} ${database:+--database "$database"} 2>>daemon.log &
  pid=$!
  for _ in $(seq 600); do  # a sanitizer build starts slowly
    [ "$(grep -c "listening on" daemon.log 2>/dev/null || true)" -gt "${before:-0}" ] && break
    sleep 0.05
  done
  [ "$(grep -c "listening on" daemon.log)" -gt "${before:-0}" ] || fail "salientd did not start"
  base=$(grep -o "http://127.0.0.1:[0-9]*" daemon.log | tail -1)
  port=${base##*:}
  key=$(cat "$data/api-key")
}
stop() { kill -TERM "$pid"; wait "$pid" || true; pid=; }

# wait_state ID STATE: until job ID is in STATE (a job ending in another state fails the test).
wait_state() {  # wait_state ID STATE
  for _ in $(seq 1200); do
    s=$(curl -s -H "X-Api-Key: $key" "$base/api/v1/jobs/$1" | field "['state']")
    [ "$s" = "$2" ] && return 0
    case $s in done|failed|cancelled) fail "job $1 ended $s, expected $2";; esac
    sleep 0.1
  done
  fail "job $1 never reached $2"
}

# sim_config FILE SIM_ARGS: one simulated printer "sim" with these salient-sim arguments.
sim_config() {
  cat > "$1" <<TOML
[[printers]]
id = "sim"
kind = "sim"
sim_args = "$2"
TOML
}

# eventually SECONDS COMMAND…: retry COMMAND (quietly) every 0.2 s until it succeeds or SECONDS have
# passed; then its last run's output is shown and its status returned. Under sanitizers and a
# loaded machine, "soon" can be many seconds.
eventually() {
  local deadline=$((SECONDS + $1)); shift
  until "$@" > eventually.out 2>&1; do
    if [ "$SECONDS" -ge "$deadline" ]; then cat eventually.out; return 1; fi
    sleep 0.2
  done
  cat eventually.out
}

# same_commands GCODE LOG: the G-code's commands (comments and blank lines gone) against what the
# simulator executed, without what the host adds on its own (M110 numbering, M115 handshake,
# M155/M105 temperatures). The simulator writes its log when idle: it is waited for.
same_commands() { eventually 120 commands_match "$1" "$2" || fail "the simulator's log differs from $1"; }
commands_match() {
  python3 - "$1" "$2" <<'PY'
import sys
want = [l.split(';')[0].strip() for l in open(sys.argv[1])]
want = [l for l in want if l]
host = ('M110', 'M115', 'M155', 'M105')
got = [l.strip() for l in open(sys.argv[2]) if l.strip() and l.split()[0] not in host]
if got != want:
    i = next((i for i, (a, b) in enumerate(zip(got, want)) if a != b), min(len(got), len(want)))
    print(f"{len(got)} executed, {len(want)} in the file; first difference at {i}: "
          f"{got[i] if i < len(got) else None!r} vs {want[i] if i < len(want) else None!r}")
    sys.exit(1)
print(f"{sys.argv[1]}: {len(got)} commands executed, exactly the file's")
PY
}
