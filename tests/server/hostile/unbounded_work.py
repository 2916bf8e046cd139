#!/usr/bin/env python3
# Hostile clients asking salientd for unbounded work (issue 32, items 10, 11, 17): settings inside
# their ranges that took the daemon to gigabytes, a model 1e-20 mm across that crashed it at every
# start, and 20,000 loose triangles that kept saliency busy for ten minutes. Each must be refused
# (422 naming the setting) or fail as a job within seconds, the daemon alive and its memory flat.
#
#   unbounded_work.py SALIENTD WORKDIR
#
# Standard library only, loopback only; starts its own daemon and kills only that.
import http.client
import json
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import time

DEADLINE = time.monotonic() + 50  # CTest's TIMEOUT is 60
TETRA = "v 0 0 0\nv {s} 0 0\nv 0 {s} 0\nv 0 0 {s}\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
failures = []


def check(ok, what):
    print(("PASS " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def loose_triangles(count, seed=17):
    """A binary STL of `count` triangles that share no vertex (about 1 MB for 20,000)."""
    rnd = random.Random(seed)
    out = [b"\0" * 80, struct.pack("<I", count)]
    for _ in range(count):
        c = [rnd.uniform(0, 50) for _ in range(3)]
        out.append(struct.pack("<3f", 0, 0, 0))
        for _ in range(3):
            out.append(struct.pack("<3f", *[c[k] + rnd.uniform(-1, 1) for k in range(3)]))
        out.append(b"\0\0")
    return b"".join(out)


class Daemon:
    def __init__(self, salientd, work):
        self.data = os.path.join(work, "data")
        config = os.path.join(work, "salientd.toml")
        with open(config, "w") as f:
            f.write("printers = []\n")
        self.log = os.path.join(work, "daemon.log")
        with open(self.log, "wb") as log:
            self.proc = subprocess.Popen([salientd, "--data", self.data, "--listen", "127.0.0.1:0", "--config", config],
                                         stdin=subprocess.DEVNULL, stdout=log, stderr=log, start_new_session=True)
        while time.monotonic() < DEADLINE:
            m = re.search(r"listening on http://127\.0\.0\.1:(\d+)", open(self.log, errors="replace").read())
            if m:
                self.port = int(m.group(1))
                self.key = open(os.path.join(self.data, "api-key")).read().strip()
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        raise RuntimeError("salientd did not start: " + open(self.log, errors="replace").read()[-400:])

    def request(self, method, target, body=b"", headers=None, timeout=10):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        conn.request(method, target, body, dict(headers or {}, **{"X-Api-Key": self.key}))
        r = conn.getresponse()
        data = r.read()
        conn.close()
        return r.status, json.loads(data) if data else None

    def submit(self, filename, data, settings):
        boundary = "unboundedWork7MA4YWxk"
        body = b""
        for name, fname, value in [("file", filename, data), ("settings", None, settings.encode())]:
            body += b"--" + boundary.encode() + b"\r\nContent-Disposition: form-data; name=\"" + name.encode() + b"\""
            if fname:
                body += b"; filename=\"" + fname.encode() + b"\"\r\nContent-Type: application/octet-stream"
            body += b"\r\n\r\n" + value + b"\r\n"
        body += b"--" + boundary.encode() + b"--\r\n"
        return self.request("POST", "/api/v1/jobs", body,
                            {"Content-Type": "multipart/form-data; boundary=" + boundary})

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


def main(argv):
    salientd, work = argv[1], argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    d = Daemon(salientd, work)
    try:
        cube = TETRA.format(s=10).encode()
        for settings, key in [('{"height": 10000, "grid": 0.001}', "height"), ('{"scale": 1e6}', "scale"),
                              ('{"height": 150, "grid": 0.001}', "grid")]:
            started = time.monotonic()
            status, body = d.submit("tetra.obj", cube, settings)
            message = (body or {}).get("error", {}).get("message", "")
            check(status == 422 and f"'{key}'" in message and time.monotonic() - started < 2,
                  f"settings {settings}: 422 naming '{key}' at once (got {status}: {message!r})")
        status, body = d.submit("tiny.obj", TETRA.format(s="1e-20").encode(), "{}")
        message = (body or {}).get("error", {}).get("message", "")
        check(status == 422 and "less than one first layer" in message and "height" in message,
              f"a model 1e-20 mm across: 422 saying it is thinner than a layer (got {status}: {message!r})")
        # Loose triangles: accepted (they are a readable model), then the job fails within seconds,
        # naming 'saliency' and what to use instead.
        status, body = d.submit("loose.stl", loose_triangles(20000), "{}")
        check(status in (200, 201, 202) and body and "id" in body, f"20,000 loose triangles are queued (got {status})")
        if body and "id" in body:
            job = body
            while time.monotonic() < DEADLINE - 5 and job.get("state") not in ("done", "failed", "cancelled"):
                time.sleep(0.2)
                _, job = d.request("GET", "/api/v1/jobs/" + body["id"])
            error = str(job.get("error"))
            check(job.get("state") == "failed" and "saliency" in error and "lee05" in error,
                  f"20,000 loose triangles fail in seconds naming 'saliency' (state {job.get('state')}: {error!r})")
        check(d.proc.poll() is None, "the daemon is alive")
        rss = d.rss_mb() if d.proc.poll() is None else 0
        check(rss < 1024, f"the daemon's memory stayed bounded ({rss:.0f} MB)")
    finally:
        d.stop()
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
