#!/usr/bin/python3
"""What a client of salientd's events and of its OctoPrint surface sees, as its documents say, on a
real daemon printing on the simulator (Step 16's items 7 and 8):
  - /api/v1/events: a "jobs" subscriber gets a job's events under topic "jobs" (not "job/ID"), a
    "job/ID" subscriber under "job/ID"; every message has type, topic, time and data ("subscribed"
    with topic null); a finished job's phase is "" (not "toolpaths"), in its event and in the API;
  - POST /api/job pause on a paused print and resume on a printing one do nothing (204), and 409
    without a print; /api/files has numbers in free and total; the oldest sample of the temperature
    history has readings; the push socket sends no two `current`s less than 500 ms apart.

    event_shapes_e2e.py SALIENTD MODELS WORKDIR
"""
import atexit
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
import urllib.request

import websocket  # websocket-client (Debian: python3-websocket)

salientd, models, work = sys.argv[1], sys.argv[2], sys.argv[3]
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


# A print of about 3 s on the simulator: long enough to pause, resume and see a few currents.
lines = ["G28", "G90"] + [f"G1 X{10 + (i % 2) * 10} Y{10 + (i // 2) % 50} F3000" for i in range(300)] + ["M84"]
gcode = ("\n".join(lines) + "\n").encode()
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


def multipart(parts):
    boundary = "----shapes"
    body = b""
    for name, filename, data in parts:
        disposition = f'form-data; name="{name}"' + (f'; filename="{filename}"' if filename else "")
        body += f"--{boundary}\r\nContent-Disposition: {disposition}\r\n\r\n".encode() + data + b"\r\n"
    return body + f"--{boundary}--\r\n".encode(), {"Content-Type": f"multipart/form-data; boundary={boundary}"}


def eventually(what, predicate, seconds=30):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    fail(f"never: {what}")


def printer_state():
    status, answer = request("GET", "/api/v1/printers/sim")
    return json.loads(answer)["state"] if status == 200 else None


eventually("the printer is operational", lambda: printer_state() == "operational")


class Reader:
    """A WebSocket client keeping every message (JSON) with the time it arrived."""

    def __init__(self, url, **options):
        self.ws = websocket.create_connection(url, timeout=10, **options)
        self.messages = []
        threading.Thread(target=self.run, daemon=True).start()

    def run(self):
        try:
            while True:
                text = self.ws.recv()
                if not text:
                    break
                self.messages.append((time.monotonic(), json.loads(text)))
        except Exception:  # closed at the end
            pass

    def wait(self, what, predicate, seconds=30):
        return eventually(what, lambda: next((m for _, m in list(self.messages) if predicate(m)), None), seconds)


# --- Item 7: events' shapes.
events_url = base.replace("http", "ws") + "/api/v1/events"
jobs = Reader(events_url, subprotocols=["salient.v1", "salient-key." + key])
jobs.ws.send(json.dumps({"subscribe": ["jobs"]}))
subscribed = jobs.wait("'subscribed' for jobs", lambda m: m.get("type") == "subscribed")
if set(subscribed) != {"type", "topic", "time", "data"} or subscribed["topic"] is not None \
        or subscribed["data"]["topics"] != ["jobs"]:
    fail(f"the 'subscribed' reply is not {{type, topic: null, time, data: {{topics}}}}: {subscribed}")
body, headers = multipart([("file", "cube_binary.ply", open(os.path.join(models, "cube_binary.ply"), "rb").read()),
                           ("settings", None, b'{"height": 10}')])
status, answer = request("POST", "/api/v1/jobs", body, headers)
if status not in (200, 201, 202):
    fail(f"submitting a job: {status} {answer!r}")
job_id = json.loads(answer)["id"]
one = Reader(events_url + "?topics=job/" + job_id, subprotocols=["salient.v1", "salient-key." + key])
done = jobs.wait("the job done on 'jobs'",
                 lambda m: m.get("type") == "job" and m["data"]["id"] == job_id and m["data"]["state"] == "done", 120)
one.wait("the job done on its own topic",
         lambda m: m.get("type") == "job" and m["data"]["state"] == "done", 30)
for reader, asked in ((jobs, "jobs"), (one, "job/" + job_id)):
    topics = {m["topic"] for _, m in list(reader.messages) if m.get("type") == "job"}
    if topics != {asked}:
        fail(f"a subscriber to {asked} got job events under {sorted(topics)}")
    for _, m in list(reader.messages):
        if set(m) != {"type", "topic", "time", "data"}:
            fail(f"a message without the four fields: {m}")
if done["data"]["phase"] != "":
    fail(f"the done event says phase {done['data']['phase']!r}")
status, answer = request("GET", "/api/v1/jobs/" + job_id)
if status != 200 or json.loads(answer)["phase"] != "":
    fail(f"the finished job says phase {json.loads(answer).get('phase')!r}")

# --- Item 8: OctoPrint's shapes.
status, answer = request("GET", "/api/files")
listing = json.loads(answer)
if status != 200 or not all(isinstance(listing.get(k), int) and listing[k] > 0 for k in ("free", "total")) \
        or listing["free"] > listing["total"]:
    fail(f"/api/files free and total: {status} {listing.get('free')!r} {listing.get('total')!r}")

status, answer = request("POST", "/api/job", b'{"command": "pause", "action": "pause"}',
                         {"Content-Type": "application/json"})
if status != 409:
    fail(f"pause without a print: {status} {answer!r}, not 409")



def has_temperatures():
    status, answer = request("GET", "/api/printer")
    return status == 200 and json.loads(answer).get("temperature", {}).get("tool0", {}).get("actual") is not None


eventually("the printer's first temperature report", has_temperatures, 10)  # a history to read
status, answer = request("POST", "/api/login", b'{"passive": true}', {"Content-Type": "application/json"})
login = json.loads(answer)
push = Reader(base.replace("http", "ws") + "/sockjs/websocket")
push.ws.send(json.dumps({"auth": f"{login['name']}:{login['session']}"}))
history = push.wait("history", lambda m: "history" in m)["history"]
if not history["temps"]:
    fail("the push socket's history has no temperatures")
oldest = history["temps"][0]
if any(oldest[t]["actual"] is None for t in ("tool0", "bed")):
    fail(f"the oldest sample of the push history has no readings: {oldest}")
status, answer = request("GET", "/api/printer?history=true&limit=10000")
printer_history = json.loads(answer)["temperature"]["history"]
if status != 200 or not printer_history or printer_history[0]["tool0"]["actual"] is None \
        or printer_history[0]["bed"]["actual"] is None:
    fail(f"the oldest sample of /api/printer's history: {printer_history[:1]}")

body, headers = multipart([("print", None, b"true"), ("file", "shapes.gcode", gcode)])
status, answer = request("POST", "/api/files/local", body, headers)
if status != 201:
    fail(f"upload and print: {status} {answer!r}")
eventually("printing", lambda: printer_state() == "printing")


def job_command(action):
    return request("POST", "/api/job", json.dumps({"command": "pause", "action": action}).encode(),
                   {"Content-Type": "application/json"})


for action in ("resume", "pause", "pause", "resume", "resume"):  # resume on printing, pause on paused: nothing
    before = printer_state()
    status, answer = job_command(action)
    if status != 204:
        fail(f"{action} while {before}: {status} {answer!r}, not 204")
    want = "paused" if action == "pause" else "printing"
    eventually(f"{want} after {action}", lambda: printer_state() == want, 10)
eventually("the print's end", lambda: printer_state() == "operational", 60)
time.sleep(1)
currents = [t for t, m in list(push.messages) if "current" in m]
if len(currents) < 4:
    fail(f"only {len(currents)} currents during a print")
gaps = [b - a for a, b in zip(currents, currents[1:])]
if min(gaps) < 0.4:  # 500 ms on the server; a loaded machine may deliver one a little early
    fail(f"two currents {min(gaps):.3f} s apart: OctoPrint sends at most two a second")
print(f"jobs topic ok, phase '' when done, free {listing['free']}, {len(currents)} currents, "
      f"smallest gap {min(gaps):.3f} s")
daemon.terminate()
daemon.wait(15)
