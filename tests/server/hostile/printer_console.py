#!/usr/bin/env python3
# Hostile clients at the printer's console, its queue and its downloads (issue 32, items 2, 5, 12, 16):
# moves and homing sent into a running print (refused 409 unless forced, over REST and the CLI),
# line-number commands (M110, "N…") in the console and in files (refused, naming the line), a
# cancel that always works, a deleted job's queue entries, and stalled downloads of a large file
# (memory bounded: files are streamed from disk).
#
#   printer_console.py SALIENTD SALIENT SALIENT_SIM WORKDIR
#
# Standard library only, loopback only; starts (and kills) its own salientd with a simulated
# printer. Prints PASS/FAIL per check; exit status 1 if any failed.
import hashlib
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

HOST = "127.0.0.1"
TETRA_OBJ = b"v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
# Moves of 100 mm at 50 mm/s (2 s each), 50 times faster than real: a print of minutes, cancelled.
CONFIG = """[[printers]]
id = "sim"
kind = "sim"
sim_args = "--advanced-ok --emergency-parser --autoreport --time-scale 0.02 --heat-time-scale 0"
"""

failures = []


def check(ok, what, seen=""):
    print(("PASS " if ok else "FAIL ") + what + ("" if ok else f": {seen}"), flush=True)
    if not ok:
        failures.append(what)
    return ok


class Daemon:
    def __init__(self, salientd, sim, work):
        self.dir = work
        self.data = os.path.join(work, "data")
        self.log_path = os.path.join(work, "daemon.log")
        config = os.path.join(work, "salientd.toml")
        with open(config, "w") as f:
            f.write(CONFIG)
        with open(self.log_path, "wb") as log:
            self.proc = subprocess.Popen(
                [salientd, "--data", self.data, "--listen", HOST + ":0", "--config", config],
                stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=dict(os.environ, SALIENT_SIM=sim),
                start_new_session=True)
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with open(self.log_path, "rb") as f:
                m = re.search(rb"listening on http://127\.0\.0\.1:(\d+)", f.read())
            if m:
                self.port = int(m.group(1))
                with open(os.path.join(self.data, "api-key")) as f:
                    self.key = f.read().strip()
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise RuntimeError("salientd did not start")

    def url(self):
        return f"http://{HOST}:{self.port}"

    def rss_mb(self):
        with open(f"/proc/{self.proc.pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
        return 0.0

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


def call(d, method, target, body=None, headers=None, timeout=30):
    """(status, headers, body bytes); a JSON body for a dict or list."""
    h = {"X-Api-Key": d.key}
    h.update(headers or {})
    if isinstance(body, (dict, list)):
        body = json.dumps(body).encode()
        h["Content-Type"] = "application/json"
    c = http.client.HTTPConnection(HOST, d.port, timeout=timeout)
    try:
        c.request(method, target, body=body, headers=h)
        r = c.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        c.close()


def js(d, method, target, body=None):
    status, _, data = call(d, method, target, body)
    try:
        return status, json.loads(data) if data else None
    except ValueError:
        return status, data


def message(doc):
    return doc.get("error", {}).get("message", "") if isinstance(doc, dict) else repr(doc)


def multipart(parts, boundary="consoleBoundary5c2Xq"):
    out = b""
    for name, filename, data in parts:
        out += b"--" + boundary.encode() + b"\r\n"
        out += b'Content-Disposition: form-data; name="' + name.encode() + b'"'
        if filename is not None:
            out += b'; filename="' + filename.encode() + b'"'
        out += b"\r\n\r\n" + data + b"\r\n"
    return "multipart/form-data; boundary=" + boundary, out + b"--" + boundary.encode() + b"--\r\n"


def upload(d, target, filename, data):
    ctype, body = multipart([("file", filename, data)])
    status, _, out = call(d, "POST", target, body, {"Content-Type": ctype}, timeout=120)
    return status, json.loads(out) if out else None


def printer(d):
    return js(d, "GET", "/api/v1/printers/sim")[1]


def wait_for(what, ok, limit=20.0):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if ok():
            return True
        time.sleep(0.05)
    return check(ok(), what, "timed out")


def long_gcode(moves):
    lines = ["G28", "G90", "M82", "G92 E0"]
    lines += [f"G1 X{10 if i % 2 else 110} Y20 E{i * 0.01:.2f} F3000" for i in range(moves)]
    return ("\n".join(lines) + "\n").encode()


def start_long_print(d):
    status, doc = js(d, "POST", "/api/v1/printers/sim/print", {"file": "long.gcode"})
    check(status == 202, "a long print starts", f"{status} {doc}")
    wait_for("the long print streams", lambda: (printer(d).get("print") or {}).get("confirmed", 0) > 5)


def cancel_print(d):
    status, doc = js(d, "POST", "/api/v1/printers/sim/cancel")
    check(status == 202, "cancel answers 202", f"{status} {doc}")
    wait_for("the printer is idle after the cancel", lambda: printer(d)["state"] == "operational")


def console(d, salient, sim):
    cmd = "/api/v1/printers/sim/command"
    status, doc = upload(d, "/api/files/local", "long.gcode", long_gcode(3000))
    check(status == 201, "a long G-code file uploads", f"{status} {doc}")
    start_long_print(d)
    for move in (["G28"], ["M117 before", "G1 X5 Y5"], ["G92 E0"], ["M84"]):
        status, doc = js(d, "POST", cmd, {"commands": move})
        code = move[-1].split()[0]
        check(status == 409 and code in message(doc) and "force" in message(doc),
              f"{move} during a print: 409 naming {code} and how to force", f"{status} {doc}")
    status, doc = js(d, "POST", cmd, {"commands": ["G28"], "force": "yes"})
    check(status == 400, "a 'force' that is not true/false: 400", f"{status} {doc}")
    status, doc = js(d, "POST", cmd, {"commands": ["M220 S100"]})
    check(status == 202, "a command that does not move goes into the print", f"{status} {doc}")
    status, doc = js(d, "POST", cmd, {"commands": ["G1 X60 Y20 F3000"], "force": True})
    check(status == 202, "a forced move goes", f"{status} {doc}")
    base = ["--server", d.url(), "--key", d.key]
    r = subprocess.run([salient, "send", "sim", "G28"] + base, capture_output=True, text=True, timeout=30)
    check(r.returncode != 0 and "G28" in r.stderr and "force" in r.stderr,
          "salient send sim G28 during a print: refused, saying how to force", f"{r.returncode} {r.stderr!r}")
    r = subprocess.run([salient, "send", "sim", "M105"] + base, capture_output=True, text=True, timeout=30)
    check(r.returncode == 0, "salient send sim M105 during a print goes", f"{r.returncode} {r.stderr!r}")
    r = subprocess.run([salient, "send", "--force", "sim", "G1 X50 Y20"] + base, capture_output=True, text=True,
                       timeout=30)
    check(r.returncode == 0, "salient send --force sends a move", f"{r.returncode} {r.stderr!r}")

    # Line numbers belong to the host: the console and files refuse them, mid-print and idle.
    for line in ("M110 N0", "m110", "N5 M105"):
        for target in (cmd, "/api/printer/command"):
            status, doc = js(d, "POST", target, {"commands": [line]})
            check(status == 422 and "salientd" in message(doc),
                  f"{line!r} at {target} during a print: 422", f"{status} {doc}")
    # Whatever was sent, the print can be cancelled.
    cancel_print(d)
    status, doc = js(d, "POST", cmd, {"commands": ["M110 N0"]})
    check(status == 422, "M110 N0 at the console of an idle printer: 422", f"{status} {doc}")
    status, doc = js(d, "POST", cmd, {"commands": ["G28"]})
    check(status == 202, "G28 at the console of an idle printer goes", f"{status} {doc}")
    wait_for("the idle G28 is done", lambda: printer(d)["state"] == "operational")
    for name, bad in (("m110.gcode", b"G28\nG1 X10 F3000\nM110 N0 ; reset\nG1 X20\n"),
                      ("numbered.gcode", b"G28\n; a comment\nN3 G1 X10*99\n")):
        status, doc = upload(d, "/api/files/local", name, bad)
        check(status == 422 and "line 3" in message(doc), f"an upload of {name}: 422 naming line 3",
              f"{status} {doc}")


def deleted_job_leaves_the_queue(d):
    status, doc = upload(d, "/api/v1/jobs", "tetra.obj", TETRA_OBJ)
    if not check(status in (200, 201, 202) and isinstance(doc, dict), "a small model is submitted", f"{status} {doc}"):
        return
    job = doc["id"]
    wait_for("the job is sliced", lambda: js(d, "GET", f"/api/v1/jobs/{job}")[1]["state"] == "done", 60)
    start_long_print(d)
    status, doc = js(d, "POST", "/api/v1/printers/sim/print", {"job": job})
    check(status == 202 and doc.get("queued"), "the job queues behind the print", f"{status} {doc}")
    status, _, _ = call(d, "DELETE", f"/api/v1/jobs/{job}")
    check(status == 204, "the queued job is deleted", str(status))
    entries = js(d, "GET", "/api/v1/printers/sim/queue")[1]["entries"]
    check(all(e.get("job") != job for e in entries), "the deleted job's queue entry is gone with it", entries)
    cancel_print(d)


def stalled_downloads(d, work):
    # 24 MB of G-code; 12 clients ask for it and read nothing. Held whole per response, that was
    # 12 copies (290 MB); streamed from disk it is a chunk and the socket's buffers per client.
    line = b"G1 X100.000 Y100.000 E12.34567 F3000 ; a line of forty-odd bytes\n"
    data = line * (24 * (1 << 20) // len(line))
    status, doc = upload(d, "/api/files/local", "big.gcode", data)
    if not check(status == 201, "a 24 MB file uploads", f"{status} {doc}"):
        return
    status, headers, body = call(d, "GET", "/downloads/files/local/big.gcode", timeout=60)
    check(status == 200 and hashlib.sha256(body).digest() == hashlib.sha256(data).digest(),
          "the download is the file, byte for byte", f"{status}, {len(body)} of {len(data)} bytes")
    status, headers, body = call(d, "GET", "/downloads/files/local/big.gcode", headers={"Range": "bytes=1000-1999"})
    check(status == 206 and body == data[1000:2000] and headers.get("content-range") == f"bytes 1000-1999/{len(data)}",
          "a Range is those bytes", f"{status} {headers.get('content-range')} {len(body)}")
    status, headers, body = call(d, "HEAD", "/downloads/files/local/big.gcode")
    check(status == 200 and body == b"" and headers.get("content-length") == str(len(data)),
          "HEAD tells the length and sends no body", f"{status} {headers.get('content-length')} {len(body)}")
    time.sleep(0.5)
    before = d.rss_mb()
    request = (f"GET /downloads/files/local/big.gcode HTTP/1.1\r\nHost: x\r\nX-Api-Key: {d.key}\r\n\r\n").encode()
    stalled = []
    for _ in range(12):
        s = socket.create_connection((HOST, d.port), timeout=10)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        s.sendall(request)
        stalled.append(s)
    time.sleep(2.0)
    after = d.rss_mb()
    check(after - before < 48, "12 stalled downloads of 24 MB hold memory bounded",
          f"RSS {before:.0f} -> {after:.0f} MB")
    status, _, _ = call(d, "GET", "/healthz", timeout=5)
    check(status == 200, "the daemon answers while they stall", str(status))
    for s in stalled:
        s.close()
    # A job's G-code download is streamed the same way.
    jobs = js(d, "GET", "/api/v1/jobs?state=done")[1]["jobs"]
    if jobs:
        status, headers, body = call(d, "GET", f"/api/v1/jobs/{jobs[0]['id']}/gcode")
        check(status == 200 and len(body) > 0 and headers.get("content-length") == str(len(body)),
              "a job's G-code downloads whole", f"{status} {headers.get('content-length')} {len(body)}")


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__ or "usage: printer_console.py SALIENTD SALIENT SALIENT_SIM WORKDIR")
    salientd, salient, sim, work = sys.argv[1:]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    d = Daemon(salientd, sim, work)
    try:
        wait_for("the simulated printer connects", lambda: printer(d)["state"] == "operational")
        console(d, salient, sim)
        deleted_job_leaves_the_queue(d)
        stalled_downloads(d, work)
        check(d.proc.poll() is None, "salientd is still running")
    finally:
        d.stop()
    print(f"{len(failures)} failed" if failures else "all passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
