#!/usr/bin/env python3
"""Hostile clients: an OctoPrint app-key request flood (issue 32, item 19) against a real salientd.

Seven loopback addresses ask for app keys as fast as they are let and keep polling their
requests; before, they filled the 16 waiting slots and every other app got 429 for 10 minutes.
Now each address has at most 2 waiting and a network (here 127.0.0.0/24) 8, so an app from
elsewhere (127.0.1.1) still asks and is answered 202 on its poll; the flood's extra asks get 429
with a Retry-After. Bounded: well under 60 s.

  app_key_flood.py SALIENTD WORKDIR
"""
import http.client
import json
import os
import re
import shutil
import subprocess
import sys
import time

salientd, work = sys.argv[1:3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
log = open(os.path.join(work, "daemon.log"), "w+")
daemon = subprocess.Popen([salientd, "--data", os.path.join(work, "data"), "--listen", "127.0.0.1:0"],
                          stderr=log, stdout=subprocess.DEVNULL)


def fail(message):
    log.seek(0)
    print("FAIL:", message, "\n" + "".join(log.readlines()[-20:]))
    daemon.kill()
    sys.exit(1)


port = None
for _ in range(600):
    log.seek(0)
    m = re.search(r"listening on http://127\.0\.0\.1:(\d+)", log.read())
    if m:
        port = int(m.group(1))
        break
    time.sleep(0.05)
if not port:
    fail("salientd did not start")


def call(source, method, path, body=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10, source_address=(source, 0))
    c.request(method, path, body=json.dumps(body) if body is not None else None,
              headers={"Content-Type": "application/json"})
    r = c.getresponse()
    out = (r.status, r.getheader("Retry-After"), r.read())
    c.close()
    return out


try:
    flood = []  # app tokens the flood holds
    refused = 0
    for round_ in range(3):  # three asks each: the per-minute limit
        for a in range(2, 9):
            status, retry, body = call(f"127.0.0.{a}", "POST", "/plugin/appkeys/request", {"app": "flood"})
            if status == 201:
                flood.append((f"127.0.0.{a}", json.loads(body)["app_token"]))
            elif status == 429:
                refused += 1
                if not retry or int(retry) <= 0:
                    fail("a 429 without a Retry-After")
            else:
                fail(f"the flood's ask answered {status}: {body[:200]}")
        for source, token in flood:  # kept alive, as an attacker would
            call(source, "GET", f"/plugin/appkeys/request/{token}")
    print(f"flood: {len(flood)} requests waiting, {refused} refused (429)")
    if len(flood) > 8:
        fail(f"7 addresses of one network hold {len(flood)} waiting requests (at most 8)")
    per_address = {}
    for source, _ in flood:
        per_address[source] = per_address.get(source, 0) + 1
    if max(per_address.values()) > 2:
        fail(f"an address holds {max(per_address.values())} waiting requests (at most 2)")
    # Another app, from another network: asks and is waiting for a decision.
    status, _, body = call("127.0.1.1", "POST", "/plugin/appkeys/request", {"app": "OctoPod"})
    if status != 201:
        fail(f"another app was answered {status} during the flood: {body[:200]}")
    token = json.loads(body)["app_token"]
    status, _, _ = call("127.0.1.1", "GET", f"/plugin/appkeys/request/{token}")
    if status != 202:
        fail(f"the other app's poll answered {status}, expected 202")
    if daemon.poll() is not None:
        fail("salientd ended")
    print("ok: the flood holds its share; another app still asks and waits for a decision")
finally:
    daemon.terminate()
    try:
        daemon.wait(10)
    except subprocess.TimeoutExpired:
        daemon.kill()
