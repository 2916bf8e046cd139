"""What the OctoPrint-client replays share (tests/clients/*_replay.py): salientd with a simulated
printer on a free loopback port (as tests/support/salientd.sh starts it), a G-code to print (the
cube, sliced by `salient`), plain HTTP as the clients send it (urllib: no retries, no redirects
taken silently), OctoPrint's push socket (/sockjs/websocket, websocket-client), and checks that
record every failed expectation with the exact response before the test ends non-zero.

Run with /usr/bin/python3 (Debian's, which has websocket-client)."""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
import uuid

import websocket  # Debian's python3-websocket


class Abort(Exception):
    """A step the rest of the replay depends on failed: stop here (the failures are reported)."""


class Checks:
    """Soft assertions: each failure is printed with its evidence and counted; `require` stops."""

    def __init__(self, client):
        self.client = client
        self.failures = []
        self.passed = 0
        self.block = ""

    def section(self, name):
        self.block = name
        print(f"--- {name}", flush=True)

    def expect(self, ok, what, evidence=None):
        if ok:
            self.passed += 1
            return True
        text = f"FAIL [{self.block}] {what}"
        if evidence is not None:
            text += f"\n      got: {shorten(evidence)}"
        print(text, flush=True)
        self.failures.append(text)
        return False

    def require(self, ok, what, evidence=None):
        if not self.expect(ok, what, evidence):
            raise Abort(what)

    def field(self, doc, path, kinds, what=None, evidence=None):
        """doc[path] exists and is one of `kinds` (types; bool is not an int here, as in Swift)."""
        value, found = dig(doc, path)
        kinds = kinds if isinstance(kinds, tuple) else (kinds,)
        ok = found and type_matches(value, kinds)
        names = "/".join("null" if k is type(None) else k.__name__ for k in kinds)
        self.expect(ok, what or f"{path} is {names}",
                    evidence if evidence is not None else (f"{path} = {value!r}" if found else f"no {path} in {doc!r}"))
        return value if found else None

    def finish(self):
        total = self.passed + len(self.failures)
        print(f"{self.client}: {self.passed} of {total} expectations met", flush=True)
        print(f"{self.passed} passed, {len(self.failures)} failed")
        return 1 if self.failures else 0


def type_matches(value, kinds):
    for k in kinds:
        if k is bool and isinstance(value, bool):
            return True
        if k in (int, float) and isinstance(value, bool):
            continue
        if k is float and isinstance(value, (int, float)):
            return True  # a JSON number: Swift's `as? Double` and Python take integers too
        if k is not bool and k is not float and isinstance(value, k):
            return True
    return False


def dig(doc, path):
    """doc["a"]["b"][0] for "a.b.0"; (value, found)."""
    cur = doc
    for part in path.split(".") if path else []:
        if isinstance(cur, dict) and part in cur:
            cur = cur[part]
        elif isinstance(cur, list) and part.isdigit() and int(part) < len(cur):
            cur = cur[int(part)]
        else:
            return None, False
    return cur, True


def shorten(x, limit=1500):
    text = x if isinstance(x, str) else repr(x)
    return text if len(text) <= limit else text[:limit] + f"… ({len(text)} chars)"


class Response:
    def __init__(self, method, url, status, headers, body):
        self.method, self.url, self.status, self.headers, self.body = method, url, status, headers, body

    def header(self, name):
        for k, v in self.headers.items():
            if k.lower() == name.lower():
                return v
        return None

    def json(self):
        try:
            return json.loads(self.body.decode("utf-8"))
        except (ValueError, UnicodeDecodeError):
            return None

    def __repr__(self):
        body = self.body[:1200].decode("utf-8", "replace")
        return f"{self.method} {self.url} -> {self.status} {body}"


class NoRedirect(urllib.request.HTTPRedirectHandler):
    def redirect_request(self, *args, **kwargs):
        return None


_opener = urllib.request.build_opener(NoRedirect)


class Http:
    """An OctoPrint client's HTTP: base URL, X-Api-Key on every request (when it has one)."""

    def __init__(self, base, key=None, user_agent="salient-replay"):
        self.base, self.key, self.user_agent = base.rstrip("/"), key, user_agent

    def request(self, method, path, body=None, headers=None, timeout=30):
        url = path if path.startswith("http") else self.base + path
        h = {"User-Agent": self.user_agent}
        if self.key:
            h["X-Api-Key"] = self.key
        data = None
        if isinstance(body, (dict, list)):
            data = json.dumps(body).encode()
            h["Content-Type"] = "application/json"
        elif isinstance(body, bytes):
            data = body
        h.update(headers or {})
        req = urllib.request.Request(url, data=data, method=method, headers=h)
        try:
            with _opener.open(req, timeout=timeout) as r:
                return Response(method, url, r.status, dict(r.headers), r.read())
        except urllib.error.HTTPError as e:
            return Response(method, url, e.code, dict(e.headers), e.read())

    def get(self, path, **kw):
        return self.request("GET", path, **kw)

    def post(self, path, body=None, **kw):
        return self.request("POST", path, body, **kw)

    def delete(self, path, **kw):
        return self.request("DELETE", path, **kw)

    def multipart(self, path, parts, **kw):
        """parts: [(name, value)] or [(name, (filename, bytes, content_type))], sent in this order."""
        boundary = "----salientReplay" + uuid.uuid4().hex
        out = b""
        for name, value in parts:
            out += f"--{boundary}\r\n".encode()
            if isinstance(value, tuple):
                filename, content, ctype = value
                out += (f'Content-Disposition: form-data; name="{name}"; filename="{filename}"\r\n'
                        f"Content-Type: {ctype}\r\n\r\n").encode() + content + b"\r\n"
            else:
                out += f'Content-Disposition: form-data; name="{name}"\r\n\r\n'.encode()
                out += (value if isinstance(value, bytes) else str(value).encode()) + b"\r\n"
        out += f"--{boundary}--\r\n".encode()
        headers = {"Content-Type": f"multipart/form-data; boundary={boundary}"}
        return self.request("POST", path, out, headers=headers, **kw)


OPENED = []  # every PushSocket, dumped into the work directory at the end (evidence)


class PushSocket:
    """OctoPrint's push API as a raw WebSocket at /sockjs/websocket. A reader thread keeps every
    message with the time it came (monotonic), so the tests can look at the order and the pace."""

    def __init__(self, base, path="/sockjs/websocket", header=None):
        OPENED.append(self)
        url = "ws" + base[len("http"):] + path
        self.ws = websocket.create_connection(url, timeout=10, header=header or [])
        self.messages = []  # (time, type, payload, raw)
        self.lock = threading.Condition()
        self.closed = False
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        while True:
            try:
                raw = self.ws.recv()
            except websocket.WebSocketTimeoutException:
                continue
            except Exception:
                break
            if not raw:
                break
            try:
                doc = json.loads(raw)
            except ValueError:
                doc = {"<unparsable>": raw}
            kind = next(iter(doc), None) if isinstance(doc, dict) else None
            with self.lock:
                self.messages.append((time.monotonic(), kind, doc.get(kind) if kind else doc, raw))
                self.lock.notify_all()
        with self.lock:
            self.closed = True
            self.lock.notify_all()

    def send(self, doc):
        self.ws.send(json.dumps(doc))

    def wait_for(self, predicate, timeout, start=0):
        """The first message from index `start` on with predicate(kind, payload); (index, message)."""
        deadline = time.monotonic() + timeout
        with self.lock:
            i = start
            while True:
                while i < len(self.messages):
                    m = self.messages[i]
                    if predicate(m[1], m[2]):
                        return i, m
                    i += 1
                left = deadline - time.monotonic()
                if left <= 0 or self.closed:
                    return None, None
                self.lock.wait(min(left, 0.2))

    def count(self):
        with self.lock:
            return len(self.messages)

    def of(self, kind, start=0):
        with self.lock:
            return [m for m in self.messages[start:] if m[1] == kind]

    def summary(self, start=0, limit=12):
        with self.lock:
            tail = self.messages[start:][-limit:]
        return [shorten(m[3], 400) for m in tail]

    def close(self):
        try:
            self.ws.close()
        except Exception:
            pass


def open_push(checks, base):
    """The push socket, or a failed requirement naming why it did not open."""
    try:
        return PushSocket(base)
    except Exception as e:
        checks.require(False, "the WebSocket /sockjs/websocket opens", repr(e))


def event_is(name):
    return lambda kind, p: kind == "event" and isinstance(p, dict) and p.get("type") == name


def current_where(pred):
    def match(kind, p):
        if kind != "current" or not isinstance(p, dict):
            return False
        try:
            return bool(pred(p))
        except (KeyError, TypeError, AttributeError):
            return False
    return match


def flags_of(p):
    return ((p or {}).get("state") or {}).get("flags") or {}


def job_path(p):
    return (((p or {}).get("job") or {}).get("file") or {}).get("path")


class Daemon:
    """salientd with one simulated printer "sim" (tests/support/salientd.sh's start + sim_config)."""

    def __init__(self, salientd, work, sim_args):
        self.work = work
        os.makedirs(work, exist_ok=True)
        config = os.path.join(work, "sim.toml")
        with open(config, "w") as f:
            f.write(f'[[printers]]\nid = "sim"\nkind = "sim"\nsim_args = "{sim_args}"\n')
        self.log_path = os.path.join(work, "daemon.log")
        self.log = open(self.log_path, "a")
        self.process = subprocess.Popen(
            [salientd, "--data", os.path.join(work, "data"), "--listen", "127.0.0.1:0", "--config", config],
            stdout=self.log, stderr=self.log)
        deadline = time.monotonic() + 60  # a sanitizer build starts slowly
        self.base = None
        while time.monotonic() < deadline:
            m = re.search(r"listening on (http://127\.0\.0\.1:\d+)", self.log_text())
            if m:
                self.base = m.group(1)
                break
            if self.process.poll() is not None:
                break
            time.sleep(0.05)
        if not self.base:
            raise RuntimeError("salientd did not start:\n" + self.log_text()[-3000:])
        with open(os.path.join(work, "data", "api-key")) as f:
            self.key = f.read().strip()

    def log_text(self):
        with open(self.log_path, errors="replace") as f:
            return f.read()

    def stop(self):
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


def slice_cube(salient, models, work, name="cube.gcode"):
    """A real G-code file, our own slicer's (as the e2e replays use)."""
    out = os.path.join(work, name)
    subprocess.run([salient, "slice", os.path.join(models, "cube_binary.ply"), "--height", "10", "-o", out],
                   check=True, stdout=subprocess.DEVNULL)
    with open(out, "rb") as f:
        return f.read()


def wait_operational(http, timeout=60):
    """Until GET /api/printer answers 200 with flags.operational (the simulator has connected)."""
    deadline = time.monotonic() + timeout
    r = None
    while time.monotonic() < deadline:
        r = http.get("/api/printer")
        if r.status == 200 and flags_of(r.json()).get("operational") and not flags_of(r.json()).get("printing"):
            return r
        time.sleep(0.2)
    return r


def main(run, client):
    """argv: SALIENTD SALIENT MODELS WORKDIR. run(checks, daemon, gcode, args) does the replay."""
    if len(sys.argv) != 5:
        print(f"usage: {sys.argv[0]} SALIENTD SALIENT MODELS_DIR WORKDIR", file=sys.stderr)
        return 2
    salientd, salient, models, work = sys.argv[1:]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    checks = Checks(client)
    gcode = slice_cube(salient, models, work)
    # Moves at 1/30 of real time: the cube (about 5 min in the file's estimate) prints in about
    # ten seconds, long enough for several `current` messages at throttle 2, a pause and a cancel.
    sim_args = (f"--advanced-ok --emergency-parser --autoreport --time-scale 0.033 "
                f"--heat-time-scale 0.01 --log {work}/sim.log")
    daemon = Daemon(salientd, work, sim_args)
    try:
        run(checks, daemon, gcode, {"salient": salient, "models": models, "work": work})
    except Abort as e:
        print(f"stopped: {e}", flush=True)
    except Exception as e:  # a client would crash here too: report it as a failure
        import traceback
        traceback.print_exc()
        checks.failures.append(f"exception: {e!r}")
    finally:
        daemon.stop()
        for n, ws in enumerate(OPENED):
            with open(os.path.join(work, f"socket-{n}.jsonl"), "w") as f:
                t0 = ws.messages[0][0] if ws.messages else 0
                for t, _, _, raw in list(ws.messages):
                    f.write(f"{t - t0:9.3f} {raw}\n")
    if checks.failures:
        print("daemon log (tail):\n" + daemon.log_text()[-2000:])
    return checks.finish()
