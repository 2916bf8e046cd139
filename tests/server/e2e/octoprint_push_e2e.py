#!/usr/bin/python3
"""OctoPrint's push socket (/sockjs/websocket) as FDM Monster uses it, against salientd printing on
the simulator (and once through SockJS's framing). FDM Monster (src/services/octoprint/octoprint-websocket.adapter.ts): passive login
for a session, open the socket, {"auth": "name:session"} then {"throttle": n}; it records a print
from `current` alone: flags.printing with job.file.path starts it, progress.completion moves it,
flags.finishing (and only that) finishes it, flags.cancelling cancels it. So this test asserts that
each of those is seen, in order, with filepos in bytes, temperatures and terminal lines, the
throttle, the events (PrintStarted, PrintDone, PrintCancelled), a wrong auth answered with
reauthRequired, garbage ignored, and the socket closed cleanly when the daemon stops.

    octoprint_push_e2e.py SALIENTD WORKDIR
"""
import atexit
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import urllib.request

import websocket  # websocket-client (Debian: python3-websocket)

salientd, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.chdir(work)


daemon = None


def fail(message):
    print("FAIL:", message)
    if daemon and daemon.poll() is None:
        daemon.kill()
    try:
        print(open("daemon.log").read()[-3000:])
    except OSError:
        pass
    sys.exit(1)


# A print of a few seconds on the simulator: 400 moves of 10 mm at 50 mm/s, at 0.05 wall s per
# printer s; comments and blank lines between them make lines, commands and bytes all differ.
lines = ["; push socket test", "G28", "M104 S0", "G90", ""]
for i in range(400):
    if i % 100 == 0:  # four layers: currentZ rises 0.2 … 0.8
        lines.append(f"G1 Z{0.2 * (i // 100 + 1):.1f} F600")
    lines.append(f"G1 X{10 + (i % 2) * 10} Y{10 + (i // 2) % 50} F3000 ; move {i}")
    if i % 7 == 0:
        lines.append("; a comment line")
lines.append("M84")
gcode = ("\n".join(lines) + "\n").encode()
open("push.gcode", "wb").write(gcode)

open("sim.toml", "w").write(
    '[[printers]]\nid = "sim"\nkind = "sim"\n'
    'sim_args = "--advanced-ok --autoreport --time-scale 0.05 --heat-time-scale 0"\n')
log = open("daemon.log", "w")
daemon = subprocess.Popen([salientd, "--data", "data", "--listen", "127.0.0.1:0", "--config", "sim.toml"],
                          stdout=subprocess.DEVNULL, stderr=log)
atexit.register(lambda: daemon.poll() is None and daemon.kill())
base = None
for _ in range(600):
    m = re.search(r"http://127\.0\.0\.1:\d+", open("daemon.log").read())
    if m:
        base = m.group(0)
        break
    time.sleep(0.05)
if not base:
    fail("salientd did not start")
key = open("data/api-key").read().strip()


def request(method, path, body=None, headers=None):
    h = {"X-Api-Key": key}
    h.update(headers or {})
    req = urllib.request.Request(base + path, data=body, method=method, headers=h)
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def upload_and_print(name):
    boundary = "----pushtest"
    body = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"print\"\r\n\r\ntrue\r\n"
            f"--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{name}\"\r\n"
            "Content-Type: application/octet-stream\r\n\r\n").encode() + gcode + f"\r\n--{boundary}--\r\n".encode()
    status, answer = request("POST", "/api/files/local", body,
                             {"Content-Type": f"multipart/form-data; boundary={boundary}"})
    if status != 201:
        fail(f"upload {name}: {status} {answer!r}")


for _ in range(200):
    if request("GET", "/api/printer")[0] == 200:
        break
    time.sleep(0.1)
else:
    fail("the printer never became operational")

status, answer = request("POST", "/api/login", b'{"passive": true}', {"Content-Type": "application/json"})
login = json.loads(answer)
if status != 200 or not login.get("name") or not login.get("session"):
    fail(f"passive login: {status} {answer!r}")

ws = websocket.create_connection(base.replace("http", "ws") + "/sockjs/websocket", timeout=10)
connected = json.loads(ws.recv())
info = connected.get("connected") or fail(f"first message is not 'connected': {connected}")
for field in ("version", "display_version", "branch", "plugin_hash", "config_hash", "debug", "safe_mode",
              "permissions"):
    if field not in info:
        fail(f"'connected' has no {field}: {info}")

# Garbage is ignored (the socket stays open); a wrong session is told to log in again.
for junk in ("not json", "[1, 2]", '{"throttle": "fast"}', '{"throttle": 0}', '{"subscribe": 7}', "{}"):
    ws.send(junk)
ws.send(json.dumps({"auth": login["name"] + ":not-a-session"}))
answer = json.loads(ws.recv())
if "reauthRequired" not in answer or not answer["reauthRequired"].get("reason"):
    fail(f"a wrong auth got {answer}, not reauthRequired")

# The same behind real SockJS framing (OctoPrint's own page, SockJS clients): /sockjs/info first,
# then "o", a["…"] frames of JSON strings; what the client sends is ["…"].
status, answer = request("GET", "/sockjs/info", headers={"X-Api-Key": ""})
if status != 200 or json.loads(answer).get("websocket") is not True:
    fail(f"/sockjs/info: {status} {answer!r}")
sock = websocket.create_connection(base.replace("http", "ws") + "/sockjs/012/x7pq2/websocket", timeout=10)
if sock.recv() != "o":
    fail("SockJS: the first frame is not 'o'")
frame = sock.recv()
if not frame.startswith("a[") or "connected" not in json.loads(json.loads(frame[1:])[0]):
    fail(f"SockJS: no connected in {frame[:200]!r}")
sock.send(json.dumps([json.dumps({"auth": f"{login['name']}:{login['session']}"})]))
frame = sock.recv()
if not frame.startswith("a[") or "history" not in json.loads(json.loads(frame[1:])[0]):
    fail(f"SockJS: no history after auth in {frame[:200]!r}")
sock.close()
try:
    websocket.create_connection(base.replace("http", "ws") + "/sockjs/012/x.y/websocket", timeout=10)
    fail("SockJS: a session id with a dot was accepted")
except websocket.WebSocketBadStatusException as e:
    if e.status_code != 404:
        fail(f"SockJS: a bad path got {e.status_code}, not 404")

messages = []  # (monotonic time received, message)
closed = threading.Event()


def read_all():
    try:
        while True:
            text = ws.recv()
            if not text:
                break
            messages.append((time.monotonic(), json.loads(text)))
    except Exception:  # the close at the end, or a timeout
        pass
    closed.set()


ws.settimeout(30)
ws.send(json.dumps({"auth": f"{login['name']}:{login['session']}"}))
ws.send(json.dumps({"throttle": 1}))
reader = threading.Thread(target=read_all, daemon=True)
reader.start()


def wait_for(what, predicate, seconds=60, since=0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        for _, m in list(messages[since:]):
            if predicate(m):
                return m
        time.sleep(0.05)
    fail(f"never saw {what}; events: {[m['event'] for _, m in messages if 'event' in m]}; "
         f"states: {[m['current']['state']['text'] for _, m in messages if 'current' in m]}")


def event(kind):
    return lambda m: m.get("event", {}).get("type") == kind


history = wait_for("history", lambda m: "history" in m)["history"]
for field in ("state", "job", "progress", "temps", "logs", "serverTime"):
    if field not in history:
        fail(f"history has no {field}: {history}")
if not isinstance(history["temps"], list) or not isinstance(history["logs"], list):
    fail(f"history's temps and logs are not lists: {history}")

# --- A print that finishes.
upload_and_print("push.gcode")
wait_for("PrintDone", event("PrintDone"))
started = wait_for("PrintStarted", event("PrintStarted"))["event"]["payload"]
done = wait_for("PrintDone", event("PrintDone"))["event"]["payload"]
added = wait_for("FileAdded", event("FileAdded"))["event"]["payload"]
if added.get("path") != "push.gcode" or added.get("storage") != "local":
    fail(f"FileAdded payload: {added}")
wait_for("UpdatedFiles", event("UpdatedFiles"))
if started.get("path") != "push.gcode" or done.get("path") != "push.gcode" or not isinstance(done.get("time"), (int, float)):
    fail(f"event payloads: {started} {done}")
first_print = [(t, m["current"]) for t, m in messages if "current" in m]


def flags(c):
    return c["state"]["flags"]


def check_print_sequence(currents, end_flag):
    """printing (with the file) … end_flag … operational, in this order; returns the printing ones."""
    i = next((k for k, (_, c) in enumerate(currents)
              if flags(c)["printing"] and not flags(c)[end_flag] and c["job"]["file"]["path"] == "push.gcode"),
             None)
    if i is None:
        fail("no current with flags.printing and job.file.path")
    j = next((k for k in range(i, len(currents)) if flags(currents[k][1])[end_flag]), None)
    if j is None:
        fail(f"no current with flags.{end_flag} after printing: {[c['state']['text'] for _, c in currents]}")
    k = next((k for k in range(j, len(currents)) if flags(currents[k][1])["ready"]), None)
    if k is None or flags(currents[k][1])["printing"] or not flags(currents[k][1])["operational"]:
        fail(f"no operational current after {end_flag}: {[c['state']['text'] for _, c in currents]}")
    return currents[i:j]


printing = check_print_sequence(first_print, "finishing")
completions = [c["progress"]["completion"] for _, c in printing]
if sorted(completions) != completions or len(set(completions)) < 3 or not 0 < completions[-2] < 100:
    fail(f"completion does not rise through the print: {completions}")
for _, c in printing:
    pos = c["progress"]["filepos"]
    if not isinstance(pos, int) or not 0 <= pos <= len(gcode) or (pos > 0 and gcode[pos - 1:pos] != b"\n"):
        fail(f"filepos {pos} is not a byte offset at a line's start in {len(gcode)} bytes")
    if c["job"]["file"]["size"] != len(gcode):
        fail(f"job.file.size {c['job']['file']['size']} != {len(gcode)}")
heights = [c["currentZ"] for _, c in printing]
while heights and heights[0] is None:  # not known before the first confirmed command, as OctoPrint's
    heights.pop(0)
if (not all(isinstance(z, (int, float)) for z in heights) or sorted(heights) != heights
        or len(set(heights)) < 2 or not 0 <= heights[0] and heights[-1] <= 0.8 + 1e-9):
    fail(f"currentZ does not follow the file's heights (G28 then 0.2 … 0.8): {heights}")
if max(c["progress"]["filepos"] for _, c in printing) <= len(lines):
    fail("filepos never passed the number of lines: it counts lines, not bytes")
if not any(t.get("tool0", {}).get("actual") is not None for _, c in first_print for t in c["temps"]):
    fail("no current carried temperatures")
logs = [line for _, c in first_print for line in c["logs"]]
if not any(line.startswith("Send: ") for line in logs) or not any(line.startswith("Recv: ") for line in logs):
    fail(f"no Send:/Recv: terminal lines in the currents: {logs[:5]}")


def check_throttle(currents, throttle):
    """No two currents closer than 500 ms × throttle, except one that carries a change of state,
    and that one not closer than 500 ms either (OctoPrint sends at most two a second)."""
    for (t0, a), (t1, b) in zip(currents, currents[1:]):
        if a["state"]["text"] == b["state"]["text"] and t1 - t0 < 0.5 * throttle - 0.15:
            fail(f"two currents {t1 - t0:.3f} s apart with throttle {throttle}")
        if t1 - t0 < 0.35:
            fail(f"two currents {t1 - t0:.3f} s apart ({a['state']['text']} -> {b['state']['text']})")


check_throttle(first_print, 1)

# --- A print that is cancelled, with a slower throttle.
ws.send(json.dumps({"throttle": 2}))
time.sleep(0.3)
mark = len(messages)
upload_and_print("push.gcode")
wait_for("progress in the second print",
         lambda m: "current" in m and flags(m["current"])["printing"] and (m["current"]["progress"]["completion"] or 0) > 5,
         since=mark)
status, answer = request("POST", "/api/job", b'{"command": "cancel"}', {"Content-Type": "application/json"})
if status != 204:
    fail(f"cancel: {status} {answer!r}")
cancelled = wait_for("PrintCancelled", event("PrintCancelled"), since=mark)["event"]["payload"]
if cancelled.get("path") != "push.gcode":
    fail(f"PrintCancelled payload: {cancelled}")
time.sleep(1.5)
second = [(t, m["current"]) for t, m in messages[mark:] if "current" in m]
check_print_sequence(second, "cancelling")
check_throttle(second, 2)
states = [m["event"]["payload"]["state_id"] for _, m in messages if event("PrinterStateChanged")(m)]
for a, b in (("PRINTING", "FINISHING"), ("FINISHING", "OPERATIONAL"), ("PRINTING", "CANCELLING"),
             ("CANCELLING", "OPERATIONAL")):
    if not any(x == a and y == b for x, y in zip(states, states[1:])):
        fail(f"PrinterStateChanged never went {a} -> {b}: {states}")

# --- The daemon stops: the socket is closed by the server (a close frame), the daemon exits 0.
stop_asked = time.monotonic()
daemon.send_signal(signal.SIGTERM)
if not closed.wait(15):
    fail("the push socket was not closed when the daemon stopped")
if daemon.wait(15) != 0:
    fail("salientd did not stop cleanly")
print(f"stopped in {time.monotonic() - stop_asked:.2f} s (this client left its TCP end open)")
print(f"push socket: {len(first_print)} currents in the first print ({len(printing)} printing, completion "
      f"{completions[0]:.1f}..{completions[-1]:.1f} %), {len(second)} in the cancelled one; states {states}")
