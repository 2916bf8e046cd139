#!/usr/bin/python3
"""OctoPod (the iOS app) replayed against salientd with a simulated printer: its calls in its
order, asserting every field it reads, with the types its Swift casts demand (`as? Int` fails on
a JSON 1.5, `as! String` on a log line crashes the app on anything but a string). Sources
(gdombiak/OctoPod):
  OctoPod/Settings UI/Printers/AppKeyViewController.swift  (the application-key workflow)
  OctoPod/OctoPrint/OctoPrintRESTClient.swift   (every REST call, the status codes it expects)
  OctoPod/OctoPrint/HTTPClient.swift            (buildURL: a Location must start with the server URL)
  OctoPod/OctoPrint/OctoPrintClient.swift       (connectToServer, websocketConnected: the order)
  OctoPod/OctoPrint/WebSocketClient.swift       (handleJSONMessage: current, event, history)
  OctoPod/Model/CurrentStateEvent.swift, TempHistory.swift, PrintFile.swift (the parsers)
  octopod_replay.py SALIENTD SALIENT MODELS_DIR WORKDIR"""

import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from octoprint_clients import (Abort, Http, current_where, event_is, flags_of, job_path, main, open_push,  # noqa: E402
                               wait_operational)

NAME = "octopod-cube.gcode"


def parse_temps(c, temp, what):
    """CurrentStateEvent.parseTemps / TempHistory.Temp.parseTemps: bed, tool0 (…4), chamber:
    actual, target as Double (null tolerated: the field stays nil); time as Int."""
    for part in ("bed", "tool0"):
        if c.expect(isinstance(temp.get(part), dict), f"{what}: {part} is an object", temp):
            for k in ("actual", "target"):
                c.field(temp, f"{part}.{k}", (float, type(None)), f"{what}: {part}.{k} is a number or null")
    if "time" in temp:
        c.field(temp, "time", int, f"{what}: time is an integer (Swift `as? Int`)")


def parse_state(c, state, what):
    """CurrentStateEvent.parseState: text String; flags operational, paused, pausing, printing,
    cancelling, closedOrError as Bool."""
    c.field(state, "text", str, f"{what}: state.text")
    for f in ("operational", "paused", "pausing", "printing", "cancelling", "closedOrError"):
        c.field(state, f"flags.{f}", bool, f"{what}: state.flags.{f}")


def parse_file(c, f, what):
    """PrintFile.parse: display, name, path, type, origin String; size Int; date Double;
    gcodeAnalysis.estimatedPrintTime Double; children (folders)."""
    for k in ("display", "name", "path", "type", "origin"):
        c.field(f, k, str, f"{what}: {k} is a string")
    if f.get("type") != "folder":
        c.field(f, "size", int, f"{what}: size is an integer (Swift `as? Int`)")
        c.field(f, "date", float, f"{what}: date is a number")
    if "gcodeAnalysis" in f and f.get("type") != "folder":
        c.field(f, "gcodeAnalysis.estimatedPrintTime", float, f"{what}: gcodeAnalysis.estimatedPrintTime")


def parse_current(c, p, what):
    """WebSocketClient.handleJSONMessage, `current`."""
    if c.expect(isinstance(p.get("state"), dict), f"{what}: state", p):
        parse_state(c, p["state"], what)
    if c.expect(isinstance(p.get("job"), dict), f"{what}: job", p):
        f = p["job"].get("file")
        if isinstance(f, dict) and f.get("path") is not None:
            for k in ("name", "path", "origin", "display"):
                c.field(f, k, str, f"{what}: job.file.{k}")
            c.field(f, "size", int, f"{what}: job.file.size is an integer")
            c.field(f, "date", float, f"{what}: job.file.date is a number")
    temps = p.get("temps")
    c.expect(isinstance(temps, list), f"{what}: temps is a list", p)
    if temps:
        parse_temps(c, temps[0], f"{what}: temps[0]")
    c.field(p, "currentZ", (float, type(None)), f"{what}: currentZ is a number or null")
    if c.expect(isinstance(p.get("progress"), dict), f"{what}: progress", p):
        c.field(p, "progress.completion", (float, type(None)), f"{what}: progress.completion")
        for k in ("printTime", "printTimeLeft"):
            c.field(p, f"progress.{k}", (int, type(None)), f"{what}: progress.{k} is an integer or null (`as? Int`)")
    logs = p.get("logs")
    c.expect(isinstance(logs, list) and all(isinstance(x, str) for x in logs),
             f"{what}: logs are strings (`log as! String` crashes otherwise)", logs)


def appkey(c, anon, admin, base):
    """AppKeyViewController: probe (204 = supported), request (expects 201 and Location), poll
    the Location (202 keep polling, 200 api_key, 404 denied)."""
    c.section("OctoPrintRESTClient.appkeyProbe: GET /plugin/appkeys/probe → 204")
    r = anon.get("/plugin/appkeys/probe")
    c.expect(r.status == 204, "probe answers 204", r)

    c.section("OctoPrintRESTClient.appkeyRequest: POST /plugin/appkeys/request {app: OctoPod} → 201 + Location")
    r = anon.post("/plugin/appkeys/request", {"app": "OctoPod"})
    c.require(r.status == 201, "request answers 201 (OctoPod expects exactly 201)", r)
    location = r.header("Location")
    c.require(bool(location), "a Location header", r.headers)
    # HTTPClient.buildURL: an absolute Location is used only when it starts with the server URL
    # the user typed; otherwise it is appended to it. A path works either way.
    c.expect(location.startswith(base + "/") or location.startswith("/"),
             "Location starts with the server URL or is a path", location)
    poll = location if location.startswith("/") else location[len(base):]
    token = poll.rstrip("/").rsplit("/", 1)[-1]

    c.section("OctoPrintRESTClient.appkeyPoll: 202 until decided")
    r = anon.get(poll)
    c.expect(r.status == 202, "poll before the decision answers 202", r)

    c.section("a person approves (decision endpoint with an admin key)")
    r = admin.post(f"/plugin/appkeys/decision/{token}", {"decision": True})
    c.expect(r.status in (200, 204), "the decision is accepted", r)

    c.section("OctoPrintRESTClient.appkeyPoll: 200 with api_key")
    r = anon.get(poll)
    c.require(r.status == 200, "poll after approval answers 200", r)
    key = (r.json() or {}).get("api_key")
    c.require(isinstance(key, str) and key, "api_key is a string", r)
    r = anon.get(poll)
    c.expect(r.status == 404, "the request is gone once the key was handed out (404)", r)
    return key


def connect_to_server(c, http, gcode):
    """OctoPrintClient.connectToServer: the socket first, then /api/printer, /api/settings,
    /api/connection (→ /api/printerprofiles), /api/version; websocketConnected → passive login
    → authenticate(user, session)."""
    c.section("OctoPrintClient.connectToServer: WebSocketClient opens /sockjs/websocket")
    ws = open_push(c, http.base)
    ws.send({})  # startHeartbeat(): "{}" right away, then every 40 s

    c.section("connectToServer: GET /api/printer (parseTemps, parseState)")
    r = http.get("/api/printer")
    c.expect(r.status == 200, "GET /api/printer answers 200 (409 = Offline)", r)
    doc = r.json() or {}
    if c.expect(isinstance(doc.get("temperature"), dict), "temperature", doc):
        parse_temps(c, doc["temperature"], "printer.temperature")
    if c.expect(isinstance(doc.get("state"), dict), "state", doc):
        parse_state(c, doc["state"], "printer")

    c.section("reviewOctoPrintSettings: GET /api/settings (updatePrinterFromSettings)")
    r = http.get("/api/settings")
    c.expect(r.status == 200, "GET /api/settings answers 200", r)
    s = r.json() or {}
    c.field(s, "feature.sdSupport", bool)
    for prof in ((s.get("temperature") or {}).get("profiles") or []):
        c.field(prof, "bed", int, "temperature profile bed is an Int")
        c.field(prof, "extruder", int, "temperature profile extruder is an Int")
    if isinstance(s.get("webcam"), dict):
        for k in ("flipH", "flipV", "rotate90"):
            c.field(s, f"webcam.{k}", bool)
    if "appearance" in s:
        c.field(s, "appearance.color", str)
    c.field(s, "plugins", dict, "plugins is an object")

    c.section("reviewPrinterProfile: GET /api/connection → current.printerProfile → GET /api/printerprofiles")
    r = http.get("/api/connection")
    c.expect(r.status == 200, "GET /api/connection answers 200", r)
    profile = c.field(r.json() or {}, "current.printerProfile", str)
    r = http.get("/api/printerprofiles")
    c.expect(r.status == 200, "GET /api/printerprofiles answers 200", r)
    profiles = (r.json() or {}).get("profiles") or {}
    c.expect(profile in profiles, "the connection's profile is listed", r)
    if profile in profiles:
        for axis in ("x", "y", "z"):
            c.field(profiles[profile], f"axes.{axis}.inverted", bool)

    c.section("connectToServer: GET /api/version → server")
    r = http.get("/api/version")
    c.expect(r.status == 200, "GET /api/version answers 200", r)
    c.field(r.json() or {}, "server", str)

    c.section("websocketConnected: POST /api/login {passive: true} (expects 200) → auth")
    r = http.post("/api/login", {"passive": True})
    c.require(r.status == 200, "passive login answers 200", r)
    login = r.json() or {}
    name = c.field(login, "name", str)
    session = c.field(login, "session", str)
    ws.send({"auth": f"{name}:{session}"})
    _, m = ws.wait_for(lambda k, p: k == "current", 15)
    c.require(m is not None, "`current` messages come once authenticated", ws.summary())
    parse_current(c, m[2], "current")
    _, h = ws.wait_for(lambda k, p: k == "history", 5)
    if c.expect(h is not None, "a `history` message", ws.summary()):
        temps = h[2].get("temps")
        c.expect(isinstance(temps, list), "history.temps is a list", h[3][:500])
        for t in (temps or [])[:20]:
            parse_temps(c, t, "history.temps[]")
    c.expect(not ws.of("reauthRequired"), "no reauthRequired", ws.summary())
    return ws


def controls(c, http):
    """PrinterSubpanel / MoveSubpanel / TempControl: OctoPrintRESTClient's POSTs (expected 204)."""
    c.section("OctoPrintRESTClient: temperatures, extrude, flow, commands, head (expected 204)")
    calls = [("/api/printer/bed", {"command": "target", "target": 0}),
             ("/api/printer/tool", {"command": "target", "targets": {"tool0": 0}}),
             ("/api/printer/tool", {"command": "select", "tool": "tool0"}),
             ("/api/printer/tool", {"command": "flowrate", "factor": 100}),
             ("/api/printer/command", {"command": "M105"}),
             ("/api/printer/printhead", {"command": "home", "axes": ["x", "y", "z"]}),
             ("/api/printer/printhead", {"command": "jog", "x": 5.0}),
             ("/api/printer/printhead", {"command": "jog", "z": 1.0}),
             ("/api/printer/printhead", {"command": "feedrate", "factor": 100})]
    for path, body in calls:
        r = http.post(path, body)
        c.expect(r.status == 204, f"POST {path} {body} answers 204", r)

    c.section("OctoPrintRESTClient.systemCommands: GET /api/system/commands")
    r = http.get("/api/system/commands")
    c.expect(r.status == 200, "answers 200", r)
    doc = r.json() or {}
    for src in ("core", "custom"):
        entries = doc.get(src)
        c.expect(isinstance(entries, list), f"{src} is a list", doc)
        for e in entries or []:
            for k in ("action", "name", "source"):
                c.field(e, k, str, f"{src}[]: {k}")

    c.section("OctoPrintRESTClient.customControls: GET /api/printer/command/custom")
    r = http.get("/api/printer/command/custom")
    c.expect(r.status == 200 and isinstance((r.json() or {}).get("controls"), list), "200 with controls[]", r)


def files_and_print(c, http, ws, gcode):
    """uploadFileToOctoPrint (multipart `file`, expects 201), files(recursive=true), printFile
    (select + print, expects 204), then the socket as the app shows the print."""
    c.section("OctoPrintRESTClient.uploadFileToOctoPrint: multipart file → 201")
    r = http.multipart("/api/files/local", [("file", (NAME, gcode, "application/octet-stream"))])
    c.require(r.status == 201, "upload answers 201", r)

    c.section("OctoPrintRESTClient.files: GET /api/files/local?recursive=true (PrintFile.parse)")
    r = http.get("/api/files/local?recursive=true")
    c.expect(r.status == 200, "answers 200", r)
    listed = [f for f in (r.json() or {}).get("files", []) if f.get("name") == NAME]
    c.require(len(listed) == 1, "the upload is listed", r)
    parse_file(c, listed[0], "files[]")
    c.expect(listed[0].get("size") == len(gcode), "size is the file's bytes", listed[0])

    c.section("OctoPrintRESTClient.printFile: {command: select, print: true} → 204")
    start = ws.count()
    r = http.post(f"/api/files/local/{NAME}", {"command": "select", "print": True})
    c.require(r.status == 204, "select + print answers 204 (OctoPod expects exactly 204)", r)

    c.section("WebSocketClient: PrinterStateChanged PRINTING, currents, PrintDone, OPERATIONAL")
    _, e = ws.wait_for(lambda k, p: k == "event" and p.get("type") == "PrinterStateChanged"
                       and (p.get("payload") or {}).get("state_id") == "PRINTING", 30, start)
    c.expect(e is not None, "PrinterStateChanged {state_id: PRINTING, state_string}", ws.summary(start))
    if e:
        c.field(e[2], "payload.state_string", str)
    i, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and job_path(p) == NAME
                                     and 0 < p["progress"]["completion"] < 100), 30, start)
    c.require(m is not None, "a printing current with progress", ws.summary(start))
    parse_current(c, m[2], "printing current")
    c.expect(m[2]["job"]["file"].get("size") == len(gcode), "job.file.size is the file's bytes", m[2]["job"])
    _, done = ws.wait_for(event_is("PrintDone"), 120, start)
    c.expect(done is not None, "event PrintDone", ws.summary(start))
    _, e = ws.wait_for(lambda k, p: k == "event" and p.get("type") == "PrinterStateChanged"
                       and (p.get("payload") or {}).get("state_id") == "OPERATIONAL", 30, i)
    c.expect(e is not None, "PrinterStateChanged OPERATIONAL after the print", ws.summary(i))

    c.section("OctoPrintRESTClient.currentJobInfo: GET /api/job after the print")
    r = http.get("/api/job")
    c.expect(r.status == 200, "answers 200", r)
    doc = r.json() or {}
    c.expect(doc.get("state") == "Operational", "state Operational", doc)
    c.expect(job_path(doc) == NAME, "the last job's file stays selected (Print again)", doc)


def job_control(c, http, ws):
    """JobInfoViewController: pause, resume, restart (when paused), cancel ({command: …}, 204)."""
    c.section("job: print, pause, resume, pause, restart, cancel (expected 204 each)")
    start = ws.count()
    r = http.post(f"/api/files/local/{NAME}", {"command": "select", "print": True})
    c.require(r.status == 204, "print again answers 204", r)
    i, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and p["progress"]["completion"] > 0), 30, start)
    c.require(m is not None, "printing", ws.summary(start))
    r = http.post("/api/job", {"command": "pause", "action": "pause"})
    c.expect(r.status == 204, "pause answers 204", r)
    i2, m = ws.wait_for(current_where(lambda p: flags_of(p)["paused"]), 30, i)
    c.expect(m is not None, "a current with flags.paused", ws.summary(i))
    r = http.post("/api/job", {"command": "pause", "action": "resume"})
    c.expect(r.status == 204, "resume answers 204", r)
    i3, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and not flags_of(p)["paused"]), 30, i2 or i)
    c.expect(m is not None, "printing again after resume", ws.summary(i))
    r = http.post("/api/job", {"command": "pause", "action": "pause"})
    c.expect(r.status == 204, "pause again answers 204", r)
    i4, _ = ws.wait_for(current_where(lambda p: flags_of(p)["paused"]), 30, i3 or i)
    r = http.post("/api/job", {"command": "restart"})
    c.expect(r.status == 204, "restart (while paused) answers 204", r)
    i5, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and not flags_of(p)["paused"]), 30, i4 or i)
    c.expect(m is not None, "printing from the start after restart", ws.summary(i))
    r = http.post("/api/job", {"command": "cancel"})
    c.expect(r.status == 204, "cancel answers 204", r)
    _, e = ws.wait_for(event_is("PrintCancelled"), 60, i5 or i)
    c.expect(e is not None, "event PrintCancelled", ws.summary(i))
    _, e = ws.wait_for(lambda k, p: k == "event" and p.get("type") == "PrinterStateChanged"
                       and (p.get("payload") or {}).get("state_id") == "OPERATIONAL", 60, i5 or i)
    c.expect(e is not None, "PrinterStateChanged OPERATIONAL after the cancel", ws.summary(i))

    c.section("OctoPrintRESTClient.deleteFile: DELETE /api/files/local/NAME (expected 204)")
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        r = http.delete(f"/api/files/local/{NAME}")
        if r.status != 409:
            break
        time.sleep(0.2)
    c.expect(r.status == 204, "delete answers 204 once idle", r)


def run(c, daemon, gcode, _args):
    admin = Http(daemon.base, daemon.key, user_agent="OctoPod/3.40")
    anon = Http(daemon.base, None, user_agent="OctoPod/3.40")
    c.section("the simulated printer connects")
    c.require(wait_operational(admin) is not None, "the printer becomes operational")
    try:
        key = appkey(c, anon, admin, daemon.base)
    except Abort:  # recorded; go on with the admin's key to show what else the app would meet
        key = daemon.key
    http = Http(daemon.base, key, user_agent="OctoPod/3.40")
    ws = connect_to_server(c, http, gcode)
    controls(c, http)
    files_and_print(c, http, ws, gcode)
    job_control(c, http, ws)
    ws.close()


if __name__ == "__main__":
    sys.exit(main(run, "OctoPod"))
