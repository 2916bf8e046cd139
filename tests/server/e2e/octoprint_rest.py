"""The OctoPrint REST calls of farm managers and phone apps (FDM Monster's octoprint.client.ts,
OctoPod's OctoPrintRESTClient.swift, Cura's monitor), checked against a running salientd with a
simulated printer: the fields those clients read and OctoPrint's status codes for bad input.
    octoprint_rest.py PHASE BASE KEY [ARGS…]   (driven by octoprint_rest_e2e.sh)"""
import json, os, sys, time, urllib.error, urllib.request, uuid

phase, base, key = sys.argv[1], sys.argv[2], sys.argv[3]
args = sys.argv[4:]


def req(method, path, body=None, form=None, headers=None):
    """(status, headers, body bytes); `body` is sent as JSON, `form` as multipart
    ({name: str or (filename, bytes)})."""
    h = {"X-Api-Key": key}
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        h["Content-Type"] = "application/json"
    if form is not None:
        boundary = uuid.uuid4().hex
        parts = []
        for name, value in form.items():
            if isinstance(value, tuple):
                disp = f'form-data; name="{name}"; filename="{value[0]}"'
                parts.append(f"--{boundary}\r\nContent-Disposition: {disp}\r\n"
                             "Content-Type: application/octet-stream\r\n\r\n".encode() + value[1] + b"\r\n")
            else:
                parts.append(f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"\r\n\r\n'
                             f"{value}\r\n".encode())
        data = b"".join(parts) + f"--{boundary}--\r\n".encode()
        h["Content-Type"] = f"multipart/form-data; boundary={boundary}"
    h.update(headers or {})
    r = urllib.request.Request(base + path, data=data, method=method, headers=h)
    try:
        with urllib.request.urlopen(r, timeout=60) as resp:
            return resp.status, resp.headers, resp.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers, e.read()


def js(method, path, want, body=None, form=None, headers=None):
    status, _, data = req(method, path, body, form, headers)
    assert status == want, f"{method} {path} {body or form}: {status}, wanted {want}: {data[:300]!r}"
    return json.loads(data) if data and data[:1] in (b"{", b"[") else None


def error_status(method, path, want, body=None, form=None, words=""):
    """A refusal with OctoPrint's status and a clear message in our JSON error body."""
    status, _, data = req(method, path, body, form)
    assert status == want, f"{method} {path} {body or form}: {status}, wanted {want}: {data[:300]!r}"
    message = json.loads(data)["error"]["message"]
    assert words.lower() in message.lower(), (message, words)
    return message


def eventually(check, seconds=60, what=""):
    deadline = time.time() + seconds
    while True:
        try:
            out = check()
            if out:
                return out
        except (AssertionError, KeyError, IndexError):
            if time.time() > deadline:
                raise
        if time.time() > deadline:
            raise AssertionError("timed out: " + what)
        time.sleep(0.2)


def sim_log_has(log, lines):
    """`lines` executed by the simulator, in this order (with others between)."""
    got = [l.strip() for l in open(log)] if os.path.exists(log) else []
    i = 0
    for l in got:
        if i < len(lines) and l == lines[i]:
            i += 1
    return i == len(lines)


def upload(path_field, name, data, **extra):
    form = {"path": path_field, **extra, "file": (name, data)}
    return req("POST", "/api/files/local", form=form)


# --- phase: print — an upload into a folder, select with print (FDM Monster's way), the job ---
def phase_print():
    gcode = open(args[0], "rb").read()
    status, h, data = upload("prints", "cube.gcode", gcode)
    assert status == 201, (status, data)
    out = json.loads(data)
    assert out["files"]["local"]["path"] == "prints/cube.gcode", out
    assert out["files"]["local"]["name"] == "cube.gcode", out
    assert h["Location"].endswith("/api/files/local/prints/cube.gcode"), h["Location"]
    status, _, data = req("POST", "/api/files/local/prints/cube.gcode", {"command": "select", "print": True})
    assert status == 204, (status, data)


def phase_job():
    job = js("GET", "/api/job", 200)
    f = job["job"]["file"]
    assert f["path"] == "prints/cube.gcode" and f["name"] == "cube.gcode" and f["origin"] == "local", job
    assert f["size"] == os.path.getsize(args[0]) and isinstance(f["date"], int), job
    analysis = js("GET", "/api/files/local/prints/cube.gcode", 200)["gcodeAnalysis"]
    assert job["job"]["estimatedPrintTime"] == analysis["estimatedPrintTime"] > 0, job
    assert job["job"]["filament"] == analysis["filament"] and job["job"]["filament"]["tool0"]["length"] > 0, job
    assert isinstance(job["job"]["lastPrintTime"], float) and job["job"]["lastPrintTime"] >= 0, job
    assert "user" in job["job"] and job["state"] == "Operational", job
    error_status("POST", "/api/job", 409, {"command": "restart"}, words="paused")
    error_status("POST", "/api/job", 400, {"command": "explode"}, words="restart")


# --- phase: controls — tool, bed, printhead, sd, chamber, custom, as G-code on the simulator ---
def phase_controls():
    log = args[0]
    state = eventually(lambda: js("GET", "/api/printer?history=true&limit=3", 200), what="printer")
    history = eventually(lambda: js("GET", "/api/printer?history=true&limit=3", 200)["temperature"]["history"],
                         what="a temperature history")
    assert 1 <= len(history) <= 3, history
    assert {"time", "tool0", "bed"} <= set(history[-1]) and "actual" in history[-1]["tool0"], history
    assert state["state"]["text"] == "Operational" and state["state"]["error"] == "", state
    assert state["state"]["flags"]["operational"] and not state["state"]["flags"]["printing"], state
    only_state = js("GET", "/api/printer?exclude=temperature,sd", 200)
    assert set(only_state) == {"state"}, only_state
    assert "history" not in js("GET", "/api/printer", 200)["temperature"]
    # FDM Monster's poll sends "limit=limit": not a number, so OctoPrint's default (300).
    assert len(js("GET", "/api/printer?history=true&limit=limit", 200)["temperature"]["history"]) >= len(history)
    tool = js("GET", "/api/printer/tool?history=true&limit=2", 200)
    assert "tool0" in tool and "bed" not in tool and "bed" not in tool["history"][-1], tool
    bed = js("GET", "/api/printer/bed", 200)
    assert set(bed) == {"bed"}, bed
    # Bad values: 400 with a message that says what is wrong; nothing sent.
    for body, words in [({"command": "target", "targets": {"tool0": -5}}, "0 to"),
                        ({"command": "target", "targets": {"tool0": "hot"}}, "number"),
                        ({"command": "target", "targets": {"tool0": 2100}}, "0 to"),
                        ({"command": "target", "targets": {"tool1": 200}}, "one tool"),
                        ({"command": "target"}, "targets"),
                        ({"command": "offset", "offsets": {"tool0": 60}}, "-50 to 50"),
                        ({"command": "extrude", "amount": "lots"}, "number"),
                        ({"command": "extrude", "amount": 1e9}, "within"),
                        ({"command": "flowrate", "factor": 300}, "75 to 125"),
                        ({"command": "select", "tool": "../tool0"}, "tool0"),
                        ({"command": "melt"}, "must be")]:
        error_status("POST", "/api/printer/tool", 400, body, words=words)
    for body, words in [({"command": "target", "target": -1}, "0 to"),
                        ({"command": "target", "target": 1000}, "0 to"),
                        ({"command": "offset", "offset": -51}, "-50 to 50")]:
        error_status("POST", "/api/printer/bed", 400, body, words=words)
    for body, words in [({"command": "jog", "x": 1e9}, "longer move"),
                        ({"command": "jog", "x": -5, "absolute": True}, "outside"),
                        ({"command": "jog", "z": 1e9, "absolute": True}, "outside"),
                        ({"command": "jog", "x": "far"}, "number"),
                        ({"command": "jog"}, "at least one"),
                        ({"command": "jog", "x": 1, "speed": -3}, "speed"),
                        ({"command": "home", "axes": ["x", "w"]}, "axes"),
                        ({"command": "home", "axes": "xyz"}, "axes"),
                        ({"command": "feedrate", "factor": 10}, "50 to 200")]:
        error_status("POST", "/api/printer/printhead", 400, body, words=words)
    # Good values: 204, and the simulator executes exactly this G-code.
    for path, body in [("/api/printer/tool", {"command": "target", "targets": {"tool0": 200}}),
                       ("/api/printer/tool", {"command": "offset", "offsets": {"tool0": 5}}),
                       ("/api/printer/tool", {"command": "target", "targets": {"tool0": 190}}),
                       ("/api/printer/bed", {"command": "target", "target": 55.5}),
                       ("/api/printer/printhead", {"command": "home", "axes": ["x", "y"]}),
                       ("/api/printer/printhead", {"command": "jog", "x": 10, "y": -2.5}),
                       ("/api/printer/printhead", {"command": "jog", "x": 0, "y": 0, "z": 5}),  # FDM Monster's
                       ("/api/printer/printhead", {"command": "jog", "x": 100, "y": 100, "absolute": True,
                                                   "speed": 3000}),
                       ("/api/printer/printhead", {"command": "feedrate", "factor": 1.5}),
                       ("/api/printer/tool", {"command": "flowrate", "factor": 90}),
                       ("/api/printer/tool", {"command": "extrude", "amount": 5})]:
        js("POST", path, 204, body)
        time.sleep(0.3)  # the console runs one batch at a time: the order of the log is the order sent
    want = ["M104 S200", "M104 S195", "M140 S55.5", "G28 X0 Y0", "G91", "G1 X10 Y-2.5 F6000", "G90", "G91", "G1 Z5 F200", "G90", "G90",
            "G1 X100 Y100 F3000", "M220 S150", "M221 S90", "G91", "M83", "G1 E5 F300", "M82", "G90"]
    eventually(lambda: sim_log_has(log, want), 60, "the controls' G-code in the simulator's log")
    assert js("GET", "/api/printer/tool", 200)["tool0"]["offset"] == 5
    error_status("GET", "/api/printer/sd", 404, words="SD support is disabled")
    error_status("POST", "/api/printer/sd", 404, {"command": "init"}, words="SD")
    error_status("GET", "/api/printer/chamber", 409, words="chamber")
    assert js("GET", "/api/printer/command/custom", 200) == {"controls": []}


# --- phase: files — folders, listing, move, copy, delete, Range, hostile paths ---
def phase_files():
    gcode = b"G28\nG1 X10 Y10 F3000\nG1 X20\n"
    out = js("POST", "/api/files/local", 201, form={"foldername": "parts"})
    assert out["folder"]["path"] == "parts" and out["done"], out
    error_status("POST", "/api/files/local", 409, form={"foldername": "parts"}, words="exists")
    assert js("POST", "/api/files/local", 201, form={"foldername": "deep", "path": "parts"})["folder"]["path"] \
        == "parts/deep"
    status, _, data = upload("parts/deep", "a.gcode", gcode)
    assert status == 201 and json.loads(data)["files"]["local"]["path"] == "parts/deep/a.gcode", data
    status, _, data = upload("", "b.gcode", gcode)
    assert status == 201, data
    listing = js("GET", "/api/files/local?recursive=true", 200)["files"]
    parts = [e for e in listing if e["name"] == "parts"][0]
    assert parts["type"] == "folder" and parts["path"] == "parts" and parts["size"] == len(gcode), parts
    deep = parts["children"][0]
    assert deep["path"] == "parts/deep" and deep["children"][0]["path"] == "parts/deep/a.gcode", deep
    assert deep["children"][0]["type"] == "machinecode" and deep["children"][0]["name"] == "a.gcode"
    assert "children" not in [e for e in js("GET", "/api/files/local", 200)["files"] if e["name"] == "parts"][0]
    folder = js("GET", "/api/files/local/parts", 200)
    assert folder["type"] == "folder" and [c["path"] for c in folder["children"]] == ["parts/deep"], folder
    assert js("GET", "/api/files/local/parts/deep/a.gcode", 200)["path"] == "parts/deep/a.gcode"
    # Hostile paths in every field: 400 and a message, never a file outside (or a crash).
    for path in ["/api/files/local/%2E%2E/etc", "/api/files/local/parts/%2E%2E/%2E%2E/x.gcode",
                 "/api/files/local/parts//a.gcode", "/downloads/files/local/%2E%2E%2Fsalient.db",
                 "/api/files/local/" + "/".join(["d"] * 17), "/api/files/local/" + "x" * 300]:
        error_status("GET", path, 400, words="'path'")
    error_status("DELETE", "/api/files/local/%2E%2E", 400, words="..")
    for form, words in [({"path": "../up", "file": ("c.gcode", gcode)}, ".."),
                        ({"path": "/abs", "file": ("c.gcode", gcode)}, "absolute"),
                        ({"path": "a\\b", "file": ("c.gcode", gcode)}, "backslash"),
                        ({"foldername": "../evil"}, ".."),
                        ({"foldername": "x", "path": "parts/../.."}, ".."),
                        ({"foldername": "/".join(["n"] * 17)}, "deeper"),
                        ({"foldername": "z.gcode"}, None)]:
        if words is None:
            error_status("POST", "/api/files/local", 409, form=form, words="file")
        else:
            error_status("POST", "/api/files/local", 400, form=form, words=words)
    for dest in ["../../x.gcode", "/etc/x.gcode", "parts/../../x"]:
        error_status("POST", "/api/files/local/b.gcode", 400, {"command": "move", "destination": dest}, words="destination")
    error_status("POST", "/api/files/local/b.gcode", 400, {"command": "move"}, words="destination")
    # Move into a folder (its own name kept), rename, conflicts, copy, a folder into itself.
    moved = js("POST", "/api/files/local/b.gcode", 201, {"command": "move", "destination": "parts"})
    assert moved["path"] == "parts/b.gcode" and moved["refs"]["download"].endswith("/downloads/files/local/parts/b.gcode")
    error_status("GET", "/api/files/local/b.gcode", 404, words="b.gcode")
    copied = js("POST", "/api/files/local/parts/b.gcode", 201, {"command": "copy", "destination": "c.gcode"})
    assert copied["path"] == "c.gcode", copied
    error_status("POST", "/api/files/local/c.gcode", 409, {"command": "copy", "destination": "parts/b.gcode"},
                 words="exists")
    error_status("POST", "/api/files/local/c.gcode", 409, {"command": "move", "destination": "parts/b.gcode"},
                 words="exists")
    error_status("POST", "/api/files/local/parts", 400, {"command": "move", "destination": "parts/deep"},
                 words="into itself")
    error_status("POST", "/api/files/local/nothing.gcode", 404, {"command": "move", "destination": "x.gcode"})
    js("POST", "/api/files/local/parts/deep", 201, {"command": "copy", "destination": "deep2"})
    assert js("GET", "/api/files/local/deep2/a.gcode", 200)["size"] == len(gcode)
    js("POST", "/api/files/local/deep2", 201, {"command": "move", "destination": "parts"})
    assert js("GET", "/api/files/local/parts/deep2/a.gcode", 200)["path"] == "parts/deep2/a.gcode"
    # Downloads with a Range (FDM Monster's resumable download).
    n = len(gcode)
    status, h, data = req("GET", "/downloads/files/local/parts/b.gcode")
    assert status == 200 and data == gcode and h["Accept-Ranges"] == "bytes", (status, h)
    for rng, first, last in [("bytes=0-9", 0, 9), ("bytes=5-", 5, n - 1), ("bytes=-4", n - 4, n - 1),
                             ("bytes=3-99999999999999999999999999", 3, n - 1), ("bytes=-999999", 0, n - 1)]:
        status, h, data = req("GET", "/downloads/files/local/parts/b.gcode", headers={"Range": rng})
        assert status == 206 and data == gcode[first:last + 1], (rng, status, data)
        assert h["Content-Range"] == f"bytes {first}-{last}/{n}", (rng, h["Content-Range"])
    for rng in [f"bytes={n}-", "bytes=99999999999999999999999-", "bytes=-0"]:
        status, h, _ = req("GET", "/downloads/files/local/parts/b.gcode", headers={"Range": rng})
        assert status == 416 and h["Content-Range"] == f"bytes */{n}", (rng, status, h)
    for rng in ["bytes=0-1,4-5", "bytes=9-2", "items=0-1", "bytes=x-y"]:  # not honoured: the whole file
        status, _, data = req("GET", "/downloads/files/local/parts/b.gcode", headers={"Range": rng})
        assert status == 200 and data == gcode, (rng, status)
    # Deletes: a file, a folder with everything in it, something that is not there.
    js("DELETE", "/api/files/local/c.gcode", 204)
    error_status("GET", "/api/files/local/c.gcode", 404)
    js("DELETE", "/api/files/local/parts", 204)
    for gone in ["parts", "parts/deep/a.gcode", "parts/b.gcode", "parts/deep2"]:
        error_status("GET", "/api/files/local/" + gone, 404)
    error_status("DELETE", "/api/files/local/parts", 404)
    assert js("GET", "/api/files/local/deep2", 404) is not None or True


# --- phase: the events the file routes published ("files" topic, salient events files) ---
def phase_events():
    seen = [json.loads(l) for l in open(args[0]) if l.strip().startswith("{")]
    kinds = [(e["data"]["type"], e["data"]["path"]) for e in seen if e.get("type") == "files"]
    for want in [("folder_added", "parts"), ("folder_added", "parts/deep"), ("added", "parts/deep/a.gcode"),
                 ("moved", "parts/b.gcode"), ("added", "c.gcode"), ("folder_added", "deep2"),
                 ("removed", "c.gcode"), ("removed", "parts")]:
        assert want in kinds, (want, kinds)


# --- phase: settings, system, version, connection ---
def phase_settings():
    s = js("POST", "/api/settings", 200, {"appearance": {"name": "Farm 7", "color": 3}, "bogus": {"x": 1},
                                         "webcam": {"streamUrl": "http://cam/stream"},
                                         "feature": {"sdSupport": True}, "gcodeAnalysis": {"runAt": "never"},
                                         "plugins": {"firmwareupdater": {"x": 1}}})
    assert s["appearance"]["name"] == "Farm 7" and s["appearance"]["color"] == "default", s["appearance"]
    assert s["webcam"]["streamUrl"] == "http://cam/stream" and "bogus" not in s, s
    assert s["feature"]["sdSupport"] is False and s["gcodeAnalysis"]["runAt"] == "never", s
    assert s["plugins"] == {}, s["plugins"]
    error_status("POST", "/api/settings", 400, [1], words="object")
    error_status("POST", "/api/settings", 400, b"{nope", words="JSON")


def phase_settings_kept():
    s = js("GET", "/api/settings", 200)
    assert s["appearance"]["name"] == "Farm 7" and s["webcam"]["streamUrl"] == "http://cam/stream", s
    assert s["api"]["enabled"] and "plugins" in s and s["serial"]["port"] == "VIRTUAL", s


def phase_system():
    version = js("GET", "/api/version", 200)
    server = js("GET", "/api/server", 200)
    assert version["server"] == server["version"] and version["text"].startswith("OctoPrint " + server["version"])
    info = js("GET", "/api/system/info", 200)["systeminfo"]
    assert info["octoprint.version"] == server["version"] and info["systeminfo.generator"], info
    assert js("GET", "/api/system/commands", 200) == {"core": [], "custom": []}
    assert js("GET", "/api/system/commands/core", 200) == []
    error_status("GET", "/api/system/commands/plugins", 404, words="source")
    error_status("POST", "/api/system/commands/core/restart", 404, words="restart")
    error_status("POST", "/api/system/commands/core/shutdown", 404, words="shutdown")


def phase_connection():
    c = js("GET", "/api/connection", 200)
    assert c["current"]["state"] == "Operational" and c["current"]["port"] == "VIRTUAL", c
    assert c["current"]["printerProfile"] == "sim" and c["current"]["baudrate"] in c["options"]["baudrates"], c
    assert c["options"]["ports"] == ["VIRTUAL"] and c["options"]["printerProfiles"][0]["id"] == "sim", c
    error_status("POST", "/api/connection", 400, {"command": "connect", "port": "/dev/ttyEVIL"}, words="port")
    error_status("POST", "/api/connection", 400, {"command": "connect", "baudrate": 12345}, words="baudrate")
    error_status("POST", "/api/connection", 400, {"command": "connect", "printerProfile": "other"}, words="profile")
    error_status("POST", "/api/connection", 400, {"command": "reboot"}, words="command")
    js("POST", "/api/connection", 204, {"command": "fake_ack"})
    js("POST", "/api/connection", 204, {"command": "disconnect"})
    eventually(lambda: js("GET", "/api/connection", 200)["current"]["state"] == "Closed", 30, "Closed")
    assert js("GET", "/api/connection", 200)["current"]["port"] is None
    error_status("GET", "/api/printer", 409, words="not operational")
    error_status("POST", "/api/printer/tool", 409, {"command": "target", "targets": {"tool0": 200}})
    error_status("POST", "/api/printer/printhead", 409, {"command": "home", "axes": ["x"]})
    js("POST", "/api/connection", 204, {"command": "connect", "port": "VIRTUAL", "baudrate": 115200,
                                        "printerProfile": "sim"})
    eventually(lambda: js("GET", "/api/connection", 200)["current"]["state"] == "Operational", 60, "Operational")


# --- phase: busy — a long print: 409 for deleting or moving it, queued prints, restart ---
def phase_busy():
    long_file = open(args[0], "rb").read()
    status, _, data = upload("farm", "long.gcode", long_file, select="true", print="true")
    assert status == 201 and json.loads(data)["effectivePrint"] is True, data
    printing = lambda: js("GET", "/api/job", 200)["state"] == "Printing"
    eventually(printing, 30, "printing")
    # (A pause or cancel in the first moments of a print, before the link streams it, is lost:
    # the printer's race, not the API's — requests wait until it streams.)
    streaming = lambda: js("GET", "/api/v1/printers/sim", 200)["print"]["confirmed"] > 20
    eventually(streaming, 30, "streaming")
    first = js("GET", "/api/v1/printers/sim", 200)["print"]["id"]
    error_status("DELETE", "/api/files/local/farm/long.gcode", 409, words="being printed")
    error_status("DELETE", "/api/files/local/farm", 409, words="being printed")
    error_status("POST", "/api/files/local/farm/long.gcode", 409, {"command": "move", "destination": "x.gcode"},
                 words="in use")
    status, _, data = upload("farm", "long.gcode", long_file)
    assert status == 409, (status, data)  # overwriting the file being printed
    # A print asked for on the busy printer is queued, and the answer says so (never 409).
    status, _, data = upload("", "next.gcode", b"G1 X1\n", print="true")
    out = json.loads(data)
    assert status == 201 and out["effectivePrint"] is False and out["queued"]["position"] == 1, (status, out)
    out = js("POST", "/api/files/local/next.gcode", 202, {"command": "select", "print": True})
    assert out["effectivePrint"] is False and out["queued"]["position"] == 2, out
    error_status("POST", "/api/files/local/next.gcode", 409, {"command": "select"}, words="printing")
    queue = js("GET", "/api/v1/printers/sim/queue", 200)["entries"]
    assert [e["position"] for e in queue] == [1, 2], queue
    for e in queue:
        js("DELETE", f"/api/v1/printers/sim/queue/{e['entry']}", 200)
    # Restart: only while paused; the same file again from its start.
    error_status("POST", "/api/job", 409, {"command": "restart"}, words="paused")
    js("POST", "/api/job", 204, {"command": "pause", "action": "pause"})
    eventually(lambda: js("GET", "/api/job", 200)["state"] == "Paused", 30, "paused")
    # OctoPrint's docs: pausing a paused print does nothing (204), it was 409 here (issue 32, item 8).
    js("POST", "/api/job", 204, {"command": "pause", "action": "pause"})
    assert js("GET", "/api/job", 200)["state"] == "Paused"
    js("POST", "/api/job", 204, {"command": "restart"})
    again = eventually(lambda: js("GET", "/api/v1/printers/sim", 200)["print"], 30, "a print again")
    assert again["id"] != first and again["file"] == "farm/long.gcode" and again["state"] == "printing", again
    job = js("GET", "/api/job", 200)
    assert job["state"] == "Printing" and job["job"]["file"]["path"] == "farm/long.gcode", job
    eventually(streaming, 30, "streaming")
    js("POST", "/api/job", 204, {"command": "cancel"})
    eventually(lambda: js("GET", "/api/job", 200)["state"] == "Operational", 60, "cancelled")
    js("DELETE", "/api/files/local/farm", 204)


globals()["phase_" + phase]()
print("ok:", phase)
