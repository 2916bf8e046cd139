#!/usr/bin/python3
"""Cura's OctoPrint connection (the OctoPrint plugin for Cura) replayed against salientd with a
simulated printer: its calls in its order, asserting every field it reads; where the plugin
indexes a JSON document directly (json_data["x"]) a missing field is a Python KeyError inside
Cura, so those are asserted present. Sources (fieldOfView/Cura-OctoPrintPlugin):
  DiscoverOctoPrintAction.py  probeAppKeySupport, requestApiKey, _pollApiKey, testApiKey,
                              _onRequestFinished (appkeys and /api/settings)
  OctoPrintOutputDevice.py    connect, getAdditionalData, _update (printer + job polling),
                              _onRequestFinished (what it reads), _sendPrintJob (the upload),
                              _onUploadFinished (Location), _selectAndPrint, pausePrint,
                              resumePrint, cancelPrint, _sendQueuedGcode
  cura_replay.py SALIENTD SALIENT MODELS_DIR WORKDIR"""

import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from octoprint_clients import Abort, Http, main, wait_operational  # noqa: E402

AGENT = "Cura/5.7.0 OctoPrintPlugin/3.7.3"
FLAGS = ("error", "closedOrError", "paused", "pausing", "printing", "cancelling", "ready", "operational")


def printer_state(c, http, what):
    """_onRequestFinished, GET printer (200): temperature.toolN/bed actual+target (KeyError),
    state.flags (all eight read by key); returns Cura's printer state or the HTTP status."""
    r = http.get("/api/printer")
    if r.status == 409:
        return "offline (409)"
    c.expect(r.status == 200, f"{what}: GET /api/printer answers 200 or 409", r)
    doc = r.json() or {}
    temp = doc.get("temperature")
    if c.expect(isinstance(temp, dict), f"{what}: temperature", doc):
        c.expect("tool0" in temp, f"{what}: temperature.tool0 (counts the extruders)", temp)
        for part in [k for k in temp if k.startswith("tool") or k == "bed"]:
            for k in ("actual", "target"):
                c.expect(k in (temp[part] or {}), f"{what}: temperature.{part}.{k} (KeyError)", temp)
    flags = (doc.get("state") or {}).get("flags")
    if not c.expect(isinstance(flags, dict) and all(f in flags for f in FLAGS),
                    f"{what}: state.flags has {', '.join(FLAGS)} (KeyError)", doc):
        return None
    if flags["error"] or flags["closedOrError"]:
        return "error"
    if flags["paused"] or flags["pausing"]:
        return "paused"
    if flags["printing"]:
        return "printing"
    if flags["cancelling"]:
        return "aborted"
    if flags["ready"] or flags["operational"]:
        return "idle"
    return "unexpected"


def job_state(c, http, what):
    """_onRequestFinished, GET job (200): state (a string: Operational, Printing…, Pausing,
    Paused, Cancelling, Error…, Starting…, Offline…), progress.printTime, completion,
    printTimeLeft (KeyError), job.file.name (KeyError)."""
    r = http.get("/api/job")
    c.expect(r.status == 200, f"{what}: GET /api/job answers 200", r)
    doc = r.json() or {}
    state = doc.get("state")
    c.expect(isinstance(state, str), f"{what}: job state is a string", doc)
    known = state in ("Operational", "Pausing", "Paused", "Cancelling", "Connecting", "Sending file to SD") or \
        any(str(state).startswith(s) for s in ("Error", "Printing", "Starting", "Offline"))
    c.expect(known, f"{what}: job state is one Cura knows", state)
    prog = doc.get("progress")
    c.expect(isinstance(prog, dict) and all(k in prog for k in ("printTime", "completion", "printTimeLeft")),
             f"{what}: progress.printTime, completion, printTimeLeft (KeyError)", doc)
    c.expect("name" in ((doc.get("job") or {}).get("file") or {}), f"{what}: job.file.name (KeyError)", doc)
    return doc


def appkeys(c, anon, admin, args, daemon):
    """DiscoverOctoPrintAction: probe (204), request {app: Cura} (201/202, app_token, Location),
    poll the Location (202, then 200 with api_key); the person approves with `salient keys
    approve TOKEN` (or, failing that, the decision endpoint with an admin key)."""
    c.section("DiscoverOctoPrintAction.probeAppKeySupport: GET plugin/appkeys/probe → 204")
    r = anon.get("/plugin/appkeys/probe")
    c.expect(r.status == 204, "probe answers 204", r)

    c.section("DiscoverOctoPrintAction.requestApiKey: POST plugin/appkeys/request {app: Cura}")
    r = anon.post("/plugin/appkeys/request", {"app": "Cura"})
    c.require(r.status in (201, 202), "request answers 201 or 202 (404 = no appkeys)", r)
    doc = r.json() or {}
    token = c.field(doc, "app_token", str, "app_token (KeyError)")
    location = r.header("Location")
    c.require(bool(location), "a Location header (Cura polls it)", r.headers)
    poll = location if location.startswith("http") else daemon.base + location

    c.section("DiscoverOctoPrintAction._pollApiKey: 202 while undecided")
    r = anon.get(poll)
    c.expect(r.status == 202, "poll answers 202", r)

    c.section("a person approves: salient keys approve TOKEN")
    approved = False
    try:
        out = subprocess.run([args["salient"], "keys", "approve", token, "--server", daemon.base,
                              "--key", daemon.key], capture_output=True, text=True, timeout=30)
        approved = out.returncode == 0
        print(f"salient keys approve: exit {out.returncode} {out.stdout.strip()} {out.stderr.strip()}")
    except OSError as e:
        print(f"salient keys approve: {e}")
    if not approved:
        r = admin.post(f"/plugin/appkeys/decision/{token}", {"decision": True})
        c.expect(r.status in (200, 204), "the decision endpoint (admin key) accepts", r)

    c.section("DiscoverOctoPrintAction._pollApiKey: 200 with api_key")
    r = anon.get(poll)
    c.require(r.status == 200, "poll after approval answers 200", r)
    key = (r.json() or {}).get("api_key")
    c.require(isinstance(key, str) and key, "api_key (KeyError)", r)
    return key


def test_key(c, http):
    """DiscoverOctoPrintAction.testApiKey: GET api/settings with the key; 200 = accepted."""
    c.section("DiscoverOctoPrintAction.testApiKey: GET api/settings")
    r = http.get("/api/settings")
    c.require(r.status == 200, "the new key is accepted (200; 401 = invalid)", r)
    s = r.json() or {}
    c.field(s, "feature.sdSupport", bool)
    c.expect(isinstance(s.get("webcam"), dict) and "streamUrl" in s["webcam"], "webcam.streamUrl", s.get("webcam"))
    c.field(s, "plugins", dict, "plugins (its keys are listed as installed plugins)")
    bad = Http(http.base, "x" * 43, user_agent=AGENT)
    r = bad.get("/api/settings")
    c.expect(r.status == 401 or r.status == 403, "a wrong key is refused (401 or 403)", r)


def connect(c, http):
    """OctoPrintOutputDevice.connect: _update (printer, job), settings, getAdditionalData
    (version, passive login, printerprofiles)."""
    c.section("OctoPrintOutputDevice.connect: _update → GET printer, GET job")
    state = printer_state(c, http, "connect")
    c.expect(state == "idle", "the printer is idle", state)
    job_state(c, http, "connect")

    c.section("OctoPrintOutputDevice.connect: GET settings (parseSettingsData)")
    r = http.get("/api/settings")
    c.expect(r.status == 200, "answers 200", r)

    c.section("getAdditionalData: GET version → server")
    r = http.get("/api/version")
    c.expect(r.status == 200, "answers 200", r)
    c.field(r.json() or {}, "server", str)

    c.section("getAdditionalData: POST login {passive: true} → name")
    r = http.post("/api/login", {"passive": True})
    c.expect(r.status == 200, "answers 200", r)
    c.field(r.json() or {}, "name", str)

    c.section("getAdditionalData: GET printerprofiles → the current one's name, model, axes")
    r = http.get("/api/printerprofiles")
    c.expect(r.status == 200, "answers 200", r)
    profiles = (r.json() or {}).get("profiles")
    c.require(isinstance(profiles, dict), "profiles (KeyError)", r)
    current = [p for p in profiles.values() if p.get("current", False)]
    c.expect(len(current) == 1, "one profile is current", profiles)
    for p in current:
        c.field(p, "name", str)
        c.field(p, "model", str)
        for axis in ("x", "y", "z", "e"):
            c.field(p, f"axes.{axis}.speed", (int, float))
            c.field(p, f"axes.{axis}.inverted", bool)


def monitor(c, http, name, until, timeout=120):
    """The monitor tab: GET printer and job, as _update does (every 2 s; faster here), until
    until(printer_state, job) holds. Returns the states seen, in order."""
    seen = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        ps = printer_state(c, http, f"monitor {name}")
        job = job_state(c, http, f"monitor {name}")
        seen.append((ps, job.get("state"), (job.get("progress") or {}).get("completion"),
                     (job.get("progress") or {}).get("printTime"), (job.get("progress") or {}).get("printTimeLeft"),
                     ((job.get("job") or {}).get("file") or {}).get("name")))
        if until(ps, job):
            return seen
        time.sleep(0.3)
    return seen


def upload_and_print(c, http, gcode):
    """_sendPrintJob with auto-print: parts path, file, select, print (in that order); 201 and
    a Location whose part after "api/" is the file's endpoint."""
    c.section("_sendPrintJob: multipart path, file, select=true, print=true → 201 + Location")
    r = http.multipart("/api/files/local", [("path", b""), ("file", ("cura-cube.gcode", gcode, "application/octet-stream")),
                                            ("select", b"true"), ("print", b"true")])
    c.require(r.status == 201, "upload answers 201", r)
    location = r.header("Location") or ""
    c.expect("api/" in location and location.split("api/", 1)[1] == "files/local/cura-cube.gcode",
             "Location's part after api/ is files/local/cura-cube.gcode", location)

    c.section("the monitor tab: printing, progress, then Operational")
    seen = monitor(c, http, "print 1", lambda ps, job: ps == "printing" and
                   (job.get("progress") or {}).get("completion") not in (None, 0))
    c.expect(seen and seen[-1][0] == "printing", "Cura shows printing", seen[-5:])
    last = seen[-1]
    c.expect(str(last[1]).startswith("Printing"), "job state starts with Printing", last)
    c.expect(last[5] == "cura-cube.gcode", "job.file.name is the upload", last)
    c.expect(isinstance(last[3], (int, float)) and last[3] >= 0, "progress.printTime: seconds printed so far", last)
    seen = monitor(c, http, "print 1 end", lambda ps, job: ps == "idle" and job.get("state") == "Operational")
    c.expect(seen and seen[-1][0] == "idle" and seen[-1][1] == "Operational", "back to idle / Operational", seen[-5:])
    c.expect(seen[-1][2] == 100, "completion 100 after a finished print (as OctoPrint keeps it)", seen[-1])


def queue_then_print(c, http, gcode):
    """_onUploadFinished when not printed in the upload (Queue job / auto-print off): the file is
    stored, then _selectAndPrint(end_point from Location) POSTs {command: select, print: true};
    pausePrint ({command: pause}), resumePrint (pause again when paused), cancelPrint."""
    c.section("_sendPrintJob without select/print, then _selectAndPrint(Location)")
    r = http.multipart("/api/files/local", [("path", b""), ("file", ("cura-queued.gcode", gcode, "application/octet-stream"))])
    c.require(r.status == 201, "upload answers 201", r)
    end_point = (r.header("Location") or "").split("api/", 1)[-1]
    c.expect(end_point == "files/local/cura-queued.gcode", "Location gives the endpoint", r.header("Location"))
    r = http.post("/api/" + end_point, {"command": "select", "print": True})
    c.require(r.status == 204, "select + print answers 204 (Cura logs 'file command accepted')", r)
    seen = monitor(c, http, "print 2", lambda ps, job: ps == "printing" and
                   (job.get("progress") or {}).get("completion") not in (None, 0))
    c.require(seen and seen[-1][0] == "printing", "printing", seen[-5:])

    c.section("pausePrint / resumePrint: POST job {command: pause} (a toggle) → 204")
    r = http.post("/api/job", {"command": "pause"})
    c.expect(r.status == 204, "pause answers 204", r)
    seen = monitor(c, http, "paused", lambda ps, job: ps == "paused" and job.get("state") == "Paused", 60)
    c.expect(seen and seen[-1][0] == "paused" and seen[-1][1] == "Paused", "paused / Paused", seen[-5:])
    r = http.post("/api/job", {"command": "pause"})
    c.expect(r.status == 204, "pause again (resume) answers 204", r)
    seen = monitor(c, http, "resumed", lambda ps, job: ps == "printing", 60)
    c.expect(seen and seen[-1][0] == "printing", "printing again", seen[-5:])

    c.section("sendCommand: POST printer/command {commands: [...]} → 204")
    r = http.post("/api/printer/command", {"commands": ["M117 Cura", "M105"]})
    c.expect(r.status == 204, "answers 204 while printing (sent into the print, as OctoPrint does)", r)

    c.section("cancelPrint: POST job {command: cancel} → 204, then Operational")
    r = http.post("/api/job", {"command": "cancel"})
    c.expect(r.status == 204, "cancel answers 204", r)
    seen = monitor(c, http, "cancelled", lambda ps, job: ps == "idle" and job.get("state") == "Operational", 60)
    c.expect(seen and seen[-1][1] == "Operational", "Operational after the cancel", seen[-8:])


def run(c, daemon, gcode, args):
    admin = Http(daemon.base, daemon.key, user_agent=AGENT)
    anon = Http(daemon.base, None, user_agent=AGENT)
    c.section("the simulated printer connects")
    c.require(wait_operational(admin) is not None, "the printer becomes operational")
    try:
        key = appkeys(c, anon, admin, args, daemon)
    except Abort:  # recorded; go on with the admin's key to show what else Cura would meet
        key = daemon.key
    http = Http(daemon.base, key, user_agent=AGENT)
    test_key(c, http)
    connect(c, http)
    upload_and_print(c, http, gcode)
    queue_then_print(c, http, gcode)
    c.section("the command sent during the print reached the printer")
    log = os.path.join(args["work"], "sim.log")
    deadline = time.monotonic() + 30  # the simulator writes its log when idle
    while time.monotonic() < deadline and not (os.path.exists(log) and "M117 Cura" in open(log).read()):
        time.sleep(0.2)
    c.expect(os.path.exists(log) and "M117 Cura" in open(log).read(), "the simulator executed M117 Cura")


if __name__ == "__main__":
    sys.exit(main(run, "Cura"))
