#!/usr/bin/python3
"""FDM Monster 2.x's OctoPrint client, replayed against salientd with a simulated printer: its
calls in its order, asserting every field it reads. Sources (fdm-monster/fdm-monster):
  src/services/octoprint/octoprint.client.ts          (OctoprintClient: the REST calls)
  src/services/octoprint/octoprint-api.routes.ts      (OctoprintRoutes: paths and command bodies)
  src/services/octoprint/octoprint-websocket.adapter.ts (OctoprintWebsocketAdapter: login, socket)
  src/services/octoprint.api.ts                       (OctoprintApi: what the farm's buttons call)
  src/state/printer-events.cache.ts                   (onOctoPrintSocketMessage: a print's start,
                                                       progress, finish, cancel, failure)
  src/services/validators/printer-service.validation.ts (the API key it accepts)
  src/controllers/printer.controller.ts               (adding a printer: testPrintApiConnection)
FDM Monster records a print as COMPLETED only on a `current` whose state.flags.finishing is true
while job.file.path is still set, and as cancelled only on flags.cancelling with the path set.
  fdm_monster_replay.py SALIENTD SALIENT MODELS_DIR WORKDIR"""

import os
import re
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from octoprint_clients import (Http, current_where, event_is, flags_of, job_path, main, open_push,  # noqa: E402
                               wait_operational)

FLAGS = ("operational", "printing", "cancelling", "pausing", "resuming", "finishing", "closedOrError",
         "error", "paused", "ready", "sdReady")
THROTTLE = 1  # AppConstants.defaultSocketThrottleRate (server.constants.ts), sent by afterOpened()
FOLDER, NAME = "farm", "cube.gcode"
PATH = f"{FOLDER}/{NAME}"


def check_current(c, p, what):
    """The `current` payload as printer-events.cache.ts keeps it (state, job, progress, currentZ,
    offsets, resends, temps) and reads it (flags, job.file.path, progress.completion, job's
    estimatedPrintTime and filament.tool0)."""
    c.field(p, "state.text", str, f"{what}: state.text")
    for f in FLAGS:
        c.field(p, f"state.flags.{f}", bool, f"{what}: state.flags.{f}")
    for key in ("job", "progress", "offsets"):
        c.field(p, key, dict, f"{what}: {key}")
    c.expect("currentZ" in p, f"{what}: currentZ present (null or number)", p)
    c.expect("resends" in p, f"{what}: resends present", p)
    c.field(p, "temps", list, f"{what}: temps is a list")
    c.field(p, "logs", list, f"{what}: logs is a list")
    # the rest of OctoPrint's `current` (sockjs.py on_printer_send_current_data), which FDM
    # Monster's UI shows through its own socket
    c.field(p, "serverTime", float, f"{what}: serverTime")
    c.field(p, "busyFiles", list, f"{what}: busyFiles")
    c.field(p, "messages", list, f"{what}: messages")


def version_and_login(c, http):
    # printer-service.validation.ts octoPrintApiKeySchema: 32–43 of [a-zA-Z0-9_-], else the
    # printer cannot even be added (printer.controller.ts create → validateInput).
    c.section("printer.controller.ts create: the API key FDM Monster accepts")
    c.expect(re.fullmatch(r"[A-Za-z0-9_-]{32,43}", http.key or "") is not None,
             "the daemon's key is 32–43 URL-safe characters", f"{len(http.key or '')} chars: {http.key!r}")

    # octoprint.api.ts validateConnection → getVersion → OctoprintClient.getApiVersion: reads
    # `server`; 401/403 = "Authentication failed", anything but 2xx = unreachable.
    c.section("OctoprintApi.validateConnection: GET /api/version")
    r = http.get("/api/version")
    c.require(r.status == 200, "GET /api/version answers 200", r)
    c.field(r.json() or {}, "server", str)

    # octoprint-websocket.adapter.ts setupSocketSession: passive login, then /api/currentuser.
    c.section("OctoprintWebsocketAdapter.setupSocketSession: POST /api/login {passive: true}")
    r = http.post("/api/login", {"passive": True})
    c.require(r.status == 200, "passive login answers 200 (403 = authFail)", r)
    login = r.json() or {}
    c.expect(login.get("name") not in (None, "_api"), 'name is a user, not "_api" (else: "Global API Key detected")',
             login)
    groups = (login.get("needs") or {}).get("group") or []
    c.expect(not groups or groups[0] != "guests", 'needs.group[0] is not "guests"', login)
    c.require(isinstance(login.get("session"), str) and len(login["session"]) > 0,
              "session is a non-empty string (else: Cant send auth, session is unset)", login)

    c.section("OctoprintClient.getAdminUserOrDefault: GET /api/currentuser")
    r = http.get("/api/currentuser")
    c.expect(r.status == 200, "GET /api/currentuser answers 200 (else authFail, socket aborted)", r)
    user = (r.json() or {}).get("name")
    c.expect(isinstance(user, str) and user != "", "currentuser.name is a user name", r)
    # FDM Monster would stop here without it; the replay goes on with login's name to show more.
    return user if isinstance(user, str) and user else login.get("name"), login["session"]


def poll_rest(c, http, what):
    """updateCurrentStateSafely (every 10 s): GET /api/printer?history=true; when operational,
    GET /api/job; emitted as one `current` {...printer, progress: job.progress, job: job.job}."""
    c.section(f"OctoprintWebsocketAdapter.updateCurrentStateSafely ({what})")
    r = http.get("/api/printer?history=true")
    c.expect(r.status == 200, f"{what}: GET /api/printer?history=true answers 200", r)
    doc = r.json() or {}
    operational = c.field(doc, "state.flags.operational", bool, f"{what}: printer state.flags.operational")
    c.field(doc, "temperature.history", list, f"{what}: history=true gives temperature.history")
    if not operational:
        return doc, {}
    j = http.get("/api/job")
    c.expect(j.status == 200, f"{what}: GET /api/job answers 200", j)
    job = j.json() or {}
    c.field(job, "job", dict, f"{what}: /api/job has job")
    c.field(job, "progress", dict, f"{what}: /api/job has progress")
    return doc, job


def open_socket(c, http, user, session):
    """afterOpened(): {"auth": "user:session"}, then {"throttle": 1}; onMessage: first key = type.
    OctoPrint (server/util/sockjs.py) sends `connected` on open, `history` once the auth names a
    valid session, then `current` at most every 500 ms × throttle."""
    c.section("OctoprintWebsocketAdapter.open: /sockjs/websocket, auth, throttle")
    ws = open_push(c, http.base)
    ws.send({"auth": f"{user}:{session}"})
    ws.send({"throttle": THROTTLE})
    i, m = ws.wait_for(lambda k, p: k == "connected", 10)
    c.expect(m is not None, "the server says `connected` first", ws.summary())
    c.expect(i == 0, "`connected` is the first message", ws.summary())
    _, h = ws.wait_for(lambda k, p: k == "history", 10)
    c.expect(h is not None, "a `history` message follows auth", ws.summary())
    _, cur = ws.wait_for(lambda k, p: k == "current", 10)
    c.require(cur is not None, "`current` messages follow", ws.summary())
    check_current(c, cur[2], "first current")
    c.expect(not ws.of("reauthRequired"), "a good auth gets no reauthRequired", ws.summary())
    return ws


def bad_auth(c, http):
    """onMessage: reauthRequired → setReauthRequired() → reauthSession(). Issue 18 asks for it on
    a wrong session (OctoPrint 1.x only drops to anonymous there, and FDM Monster then waits for
    messages that never come: reauthRequired is what lets it log in again)."""
    c.section("OctoprintWebsocketAdapter.onMessage: reauthRequired on a wrong session")
    ws = open_push(c, http.base)
    ws.send({"auth": "admin:not-a-session"})
    _, m = ws.wait_for(lambda k, p: k == "reauthRequired", 10)
    c.expect(m is not None, "a wrong auth gets `reauthRequired`", ws.summary())
    ws.close()


def controls(c, http):
    """octoprint.client.ts: settings, connection, printhead, bed, command, profiles, system."""
    c.section("OctoprintClient.getSettings / updatePrinterNameSetting")
    r = http.get("/api/settings")
    c.expect(r.status == 200, "GET /api/settings answers 200", r)
    r = http.post("/api/settings", {"appearance": {"name": "Farm printer 7"}})
    c.expect(200 <= r.status < 300, "POST /api/settings {appearance: {name}} succeeds", r)
    r = http.get("/api/settings")
    c.expect(((r.json() or {}).get("appearance") or {}).get("name") == "Farm printer 7",
             "appearance.name reads back as written", r)

    c.section("OctoprintApi.getReprintState: GET /api/connection → current.state")
    r = http.get("/api/connection")
    c.expect(r.status == 200, "GET /api/connection answers 200", r)
    c.field(r.json() or {}, "current.state", str)

    c.section("OctoprintClient: printhead, bed, command (farm buttons)")
    for path, body in (("/api/printer/printhead", {"command": "home", "axes": ["x", "y"]}),
                       ("/api/printer/printhead", {"command": "jog", "x": 1, "y": 0, "z": 0}),
                       ("/api/printer/bed", {"command": "target", "target": 0}),
                       ("/api/printer/command", {"command": "M115"})):
        r = http.post(path, body)
        c.expect(r.status == 204, f"POST {path} {body} answers 204", r)

    c.section("OctoprintClient: printerprofiles, system info and commands, server")
    for path in ("/api/printerprofiles", "/api/system/info", "/api/system/commands", "/api/server"):
        r = http.get(path)
        c.expect(r.status == 200 and isinstance(r.json(), dict), f"GET {path} answers 200 with an object", r)


def files(c, http, gcode):
    """uploadFileAsMultiPart (no print: only the `file` part), createFolder (`path`,
    `foldername`), moveFileOrFolder ({command: move, destination}), getLocalFiles, getFile."""
    c.section("OctoprintClient.uploadFileAsMultiPart (startPrint false): file only")
    r = http.multipart("/api/files/local", [("file", (NAME, gcode, "application/octet-stream"))])
    c.require(r.status == 201, "upload answers 201", r)

    c.section("OctoprintClient.createFolder: multipart path + foldername")
    r = http.multipart("/api/files/local", [("path", ""), ("foldername", FOLDER)])
    c.expect(r.status == 201, "folder creation answers 201", r)

    c.section("OctoprintClient.moveFileOrFolder: {command: move, destination}")
    r = http.post(f"/api/files/local/{NAME}", {"command": "move", "destination": FOLDER})
    c.expect(r.status == 201, "move answers 201 (as OctoPrint)", r)

    c.section("OctoprintClient.getLocalFiles(recursive=false): files[] path/name, size, date, type")
    r = http.get("/api/files/local?recursive=false")
    c.expect(r.status == 200, "GET /api/files/local?recursive=false answers 200", r)
    items = (r.json() or {}).get("files")
    c.require(isinstance(items, list), "files is a list", r)
    folder = [f for f in items if f.get("name") == FOLDER]
    c.expect(len(folder) == 1 and folder[0].get("type") == "folder", f"{FOLDER} is listed as a folder", items)

    c.section("flattenOctoPrintFiles(recursive=true): name, type folder/machinecode, size, date, children")
    r = http.get("/api/files/local?recursive=true")
    items = (r.json() or {}).get("files") or []
    folder = [f for f in items if f.get("name") == FOLDER]
    c.require(len(folder) == 1, f"{FOLDER} in the recursive listing", r)
    kids = folder[0].get("children")
    c.require(isinstance(kids, list), "the folder has children", folder[0])
    mine = [f for f in kids if f.get("name") == NAME]
    c.require(len(mine) == 1, f"{NAME} is in {FOLDER}'s children", kids)
    f = mine[0]
    c.expect(f.get("type") == "machinecode", "type machinecode (else flattenOctoPrintFiles drops it)", f)
    c.expect(f.get("size") == len(gcode), "size is the file's bytes", f)
    c.field(f, "date", int, "date is an integer (seconds)")
    c.expect(f.get("path") == PATH, "path is folder/name", f)

    c.section("OctoprintClient.getLocalFiles(startDir=farm): children of the folder")
    r = http.get(f"/api/files/local/{FOLDER}?recursive=false")
    c.expect(r.status == 200, f"GET /api/files/local/{FOLDER} answers 200", r)
    doc = r.json() or {}
    kids = doc.get("files") or doc.get("children") or []
    c.expect(any(k.get("path") == PATH for k in kids), "the folder lists the file by path", r)

    c.section("OctoprintClient.getFile: path, size, date, type")
    r = http.get(f"/api/files/local/{PATH}")
    c.expect(r.status == 200, "GET /api/files/local/PATH answers 200", r)
    doc = r.json() or {}
    c.expect(doc.get("path") == PATH and doc.get("size") == len(gcode) and doc.get("type") == "machinecode",
             "path, size, type", doc)

    c.section("OctoprintClient.getFileChunk: Range bytes=0-99")
    r = http.get(f"/downloads/files/local/{PATH}", headers={"Range": "bytes=0-99"})
    c.expect(r.status == 206 and r.body == gcode[:100], "206 with the first 100 bytes", r)


def watch_print(c, http, ws, gcode, start):
    """printer-events.cache.ts onOctoPrintSocketMessage, message by message, for one print."""
    c.section("printer-events.cache: markStarted (flags.printing + job.file.path)")
    i, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and job_path(p) == PATH), 30, start)
    c.require(m is not None, f"a current with printing and job.file.path {PATH}", ws.summary(start))
    p = m[2]
    check_current(c, p, "printing current")
    c.expect(p["job"]["file"].get("name") == NAME, "job.file.name", p["job"])
    c.expect(p["job"]["file"].get("origin") == "local", "job.file.origin local", p["job"])
    c.expect(p["job"]["file"].get("size") == len(gcode), "job.file.size is the file's bytes", p["job"])
    c.field(p, "job.file.date", int, "job.file.date is an integer")
    est = c.field(p, "job.estimatedPrintTime", (int, float), "job.estimatedPrintTime (metadata fallback)")
    c.expect(est is not None and est > 0, "estimatedPrintTime > 0", p["job"])
    c.field(p, "job.filament.tool0.length", (int, float), "job.filament.tool0.length")
    c.field(p, "job.filament.tool0.volume", (int, float), "job.filament.tool0.volume")
    c.field(p, "progress.completion", (int, float), "progress.completion is a number (markProgress)")
    c.field(p, "progress.filepos", int, "progress.filepos (bytes)")
    c.field(p, "progress.printTime", (int, type(None)), "progress.printTime")
    c.field(p, "progress.printTimeLeft", (int, type(None)), "progress.printTimeLeft")
    _, e = ws.wait_for(event_is("PrintStarted"), 5, start)
    c.expect(e is not None and (e[2].get("payload") or {}).get("path") == PATH,
             "event PrintStarted with payload.path", ws.summary(start))

    c.section("printer-events.cache: markProgress (progress.completion, 0–100, rising)")
    # the REST poll of updateCurrentStateSafely during the print, as it runs every 10 s
    doc, job = poll_rest(c, http, "during the print")
    c.expect(flags_of(doc).get("printing") is True, "/api/printer: flags.printing while printing", doc)
    c.expect(job_path(job) == PATH, "/api/job: job.file.path while printing", job)
    # triggerFileAnalysis → print-file-downloader.service.ts: GET /downloads/files/local/PATH
    r = http.get(f"/downloads/files/local/{PATH}")
    c.expect(r.status == 200 and r.body == gcode, "the printing file downloads whole", r)
    r = http.delete(f"/api/files/local/{PATH}")
    c.expect(r.status == 409, "DELETE of the printing file answers 409 (as OctoPrint)", r)

    c.section("printer-events.cache: markFinished — only flags.finishing with job.file.path")
    j, fin = ws.wait_for(current_where(lambda p: flags_of(p)["finishing"] and job_path(p) == PATH), 120, i)
    c.expect(fin is not None, f"a current with flags.finishing and job.file.path {PATH} "
             "(without it FDM Monster never completes the job)", ws.summary(i))
    printing = [m[2] for m in ws.of("current", i) if job_path(m[2]) == PATH and flags_of(m[2]).get("printing")]
    comps = [p["progress"].get("completion") for p in printing if isinstance(p.get("progress"), dict)]
    comps = [x for x in comps if isinstance(x, (int, float))]
    c.expect(len(comps) >= 3, "several progress updates while printing", comps)
    c.expect(comps == sorted(comps) and all(0 <= x <= 100 for x in comps),
             "completion rises within 0–100", comps)
    c.expect(any(0 < x < 100 for x in comps), "a completion strictly between 0 and 100", comps)
    if fin:
        c.expect(abs(fin[2]["progress"].get("completion", 0) - 100) < 1e-6, "completion 100 when finishing",
                 fin[2]["progress"])
    _, e = ws.wait_for(event_is("PrintDone"), 30, start)
    c.expect(e is not None and (e[2].get("payload") or {}).get("path") == PATH, "event PrintDone with payload.path",
             ws.summary(start))
    _, op = ws.wait_for(current_where(lambda p: flags_of(p)["operational"] and not flags_of(p)["printing"]
                                      and not flags_of(p)["finishing"]), 30, j or i)
    c.expect(op is not None, "then a current: operational, not printing, not finishing", ws.summary(i))

    c.section("OctoPrint's pace: current at most every 500 ms × throttle (sockjs.py _base_rate_limit)")
    # A change of state may go out at once (so that finishing and cancelling are never coalesced
    # away, which OctoPrint's hold-back could do); the rest keeps the pace.
    cur = ws.of("current", start)
    gaps = [round(b[0] - a[0], 3) for a, b in zip(cur, cur[1:])
            if (a[2].get("state") or {}).get("text") == (b[2].get("state") or {}).get("text")]
    c.expect(gaps and min(gaps) >= 0.5 * THROTTLE * 0.8,
             f"gaps between currents of one state ≥ {0.5 * THROTTLE} s (20 % slack)", gaps)
    temps = [m[2].get("temps") for m in ws.of("current", start)]
    nonempty = [t for t in temps if t]
    c.expect(nonempty and all(isinstance(x.get("time"), int) and "tool0" in x and "bed" in x
                              for t in nonempty for x in t),
             "temps entries: time (int), tool0, bed", nonempty[:2])
    logs = [entry for m in ws.of("current", start) for entry in (m[2].get("logs") or [])]
    c.expect(any(str(x).startswith("Send: ") for x in logs) and any(str(x).startswith("Recv: ") for x in logs),
             'logs carry "Send: …" and "Recv: …" lines', logs[:6])


def cancel_print(c, http, ws):
    """OctoprintApi.startPrint then cancelPrint ({command: cancel}); printer-events.cache marks
    the job failed "Cancelled" on flags.cancelling with job.file.path."""
    c.section("OctoprintApi.startPrint again, then cancelPrint")
    start = ws.count()
    r = http.post(f"/api/files/local/{PATH}", {"command": "select", "print": True})
    c.require(r.status == 204, "select + print answers 204", r)
    # At once, as a person at FDM Monster's cancel button can: the print may still wait behind the
    # commands sent before it (here the farm buttons' home), and the cancel must be its own.
    i, m = ws.wait_for(current_where(lambda p: flags_of(p)["printing"] and job_path(p) == PATH), 30, start)
    c.require(m is not None, "printing again", ws.summary(start))
    r = http.post("/api/job", {"command": "cancel"})
    c.expect(r.status == 204, "POST /api/job {command: cancel} answers 204", r)
    _, cm = ws.wait_for(current_where(lambda p: flags_of(p)["cancelling"] and job_path(p) == PATH), 30, i)
    c.expect(cm is not None, "a current with flags.cancelling and job.file.path (markFailed 'Cancelled')",
             ws.summary(i))
    _, e = ws.wait_for(event_is("PrintCancelled"), 30, i)
    c.expect(e is not None and (e[2].get("payload") or {}).get("path") == PATH,
             "event PrintCancelled with the file's path", ws.summary(i))
    c.expect(not ws.wait_for(event_is("PrintDone"), 0.1, i)[1], "no PrintDone after the cancel", ws.summary(i))
    fins = [m for m in ws.of("current", i) if flags_of(m[2]).get("finishing")]
    c.expect(not fins, "a cancelled print never shows flags.finishing (it would be marked COMPLETED)",
             [x[3] for x in fins[:1]])
    _, op = ws.wait_for(current_where(lambda p: flags_of(p)["operational"] and not flags_of(p)["printing"]
                                      and not flags_of(p)["cancelling"]), 60, i)
    c.expect(op is not None, "then operational again", ws.summary(i))


def connection(c, http):
    """OctoprintApi.disconnect / connect ({command: disconnect|connect}); updateCurrentStateSafely
    treats 409 from /api/printer as 'USB disconnected' and reads the body's `error`."""
    c.section("OctoprintApi.disconnect, then connect")
    r = http.post("/api/connection", {"command": "disconnect"})
    c.expect(r.status == 204, "disconnect answers 204", r)
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        r = http.get("/api/printer?history=true")
        if r.status == 409:
            break
        time.sleep(0.2)
    c.expect(r.status == 409, "/api/printer answers 409 when disconnected", r)
    c.expect("error" in (r.json() or {}), "the 409 body has `error`", r)
    r = http.post("/api/connection", {"command": "connect"})
    c.expect(r.status == 204, "connect answers 204", r)
    r = wait_operational(http)
    c.expect(r is not None and r.status == 200, "operational again after connect", r)


def run(c, daemon, gcode, _args):
    http = Http(daemon.base, daemon.key, user_agent="axios/1.16.1")  # FDM Monster's HTTP client
    c.section("the simulated printer connects")
    c.require(wait_operational(http) is not None, "the printer becomes operational")
    user, session = version_and_login(c, http)
    poll_rest(c, http, "before printing")
    ws = open_socket(c, http, user, session)
    bad_auth(c, http)
    controls(c, http)
    files(c, http, gcode)
    c.section("OctoprintApi.startPrint: POST /api/files/local/PATH {command: select, print: true}")
    start = ws.count()
    r = http.post(f"/api/files/local/{PATH}", {"command": "select", "print": True})
    c.require(r.status == 204, "select + print answers 204", r)
    watch_print(c, http, ws, gcode, start)
    cancel_print(c, http, ws)
    c.section("OctoprintClient.deleteFileOrFolder after the print")
    r = http.delete(f"/api/files/local/{PATH}")
    c.expect(r.status == 204, "DELETE answers 204 when idle", r)
    r = http.delete(f"/api/files/local/{FOLDER}")
    c.expect(r.status == 204, "folder DELETE answers 204", r)
    connection(c, http)
    ws.close()


if __name__ == "__main__":
    sys.exit(main(run, "FDM Monster"))
