#!/usr/bin/env bash
# Soak: one salientd with two simulated printers printing with faults (one ADVANCED_OK, one
# ping-pong), jobs submitted, downloaded and deleted, WebSocket clients coming and going (some
# abruptly), for SOAK_SECONDS. RSS, descriptors, threads and disk of the daemon every SOAK_SAMPLE
# seconds to a CSV; a baseline after a warm-up and an end record, both taken with the load stopped
# and settled, compared within stated margins; nothing lost (every print finished with
# confirmed == total, every job done, no HTTP 5xx, no restart); SIGTERM stops it within 5 s with 0.
# Exits non-zero if any check fails.
#   tests/bench/soak_bench.sh [BUILD_DIR]
# Environment: SOAK_SECONDS (1800), SOAK_WARMUP (60), SOAK_SAMPLE (60), SOAK_SETTLE (10),
# SOAK_WS_CLIENTS (6 at once), SOAK_OUT (where the CSV, logs and summary stay; default a new
# /tmp/soak.XXXXXX), SALIENTD (the daemon; default BUILD_DIR/server/salientd; it finds salient-sim
# beside itself, or set SALIENT_SIM), margins SOAK_RSS_MB (20), SOAK_FDS (5), SOAK_THREADS (2),
# SOAK_DISK_KB_PER_PRINT (1), SOAK_DISK_SLACK_MB (4, for SQLite's WAL; 1 MB more for the 256 shard
# directories of the file store, which stay when emptied).
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$(pwd)
build=${1:-build}
salientd=${SALIENTD:-$build/server/salientd}
salientd=$(cd "$(dirname "$salientd")" && pwd)/$(basename "$salientd")
models=$(cd ../shared/models && pwd)
out=${SOAK_OUT:-$(mktemp -d /tmp/soak.XXXXXX)}
mkdir -p "$out"
out=$(cd "$out" && pwd)
seconds=${SOAK_SECONDS:-1800}
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null; true' EXIT

cat > "$out/salientd.toml" <<'TOML'
[jobs]
workers = 1

[[printers]]
id = "fast"
kind = "sim"
profile = "generic-i3"
autoconnect = true
sim_args = "--advanced-ok --emergency-parser --autoreport --time-scale 0.02 --faults noise=0.01,drop-ok=0.005,seed=7"

[[printers]]
id = "pingpong"
kind = "sim"
profile = "generic-i3"
autoconnect = true
sim_args = "--time-scale 0.02 --faults noise=0.01,drop-ok=0.005,seed=11"
TOML

echo "soak: $(git -C "$repo" log -1 --format='commit %h (%cd)' --date=short 2>/dev/null || echo 'commit unknown')," \
  "$("$salientd" --version 2>&1 | head -1), binary $salientd (built $(date -u -r "$salientd" +%FT%TZ), sha256 $(sha256sum "$salientd" | cut -c1-12))," \
  "sim ${SALIENT_SIM:-$(dirname "$salientd")/salient-sim}"
echo "soak: $seconds s of load after a ${SOAK_WARMUP:-60} s warm-up; output in $out"
rm -rf "$out/data"
nice -n 5 "$salientd" --data "$out/data" --listen 127.0.0.1:0 --config "$out/salientd.toml" 2> "$out/daemon.log" &
pid=$!
for _ in $(seq 200); do grep -q "listening on" "$out/daemon.log" 2>/dev/null && break; sleep 0.05; done
grep -q "listening on" "$out/daemon.log" || { echo "FAIL: salientd did not start"; cat "$out/daemon.log"; exit 1; }
base=$(grep -o "http://127.0.0.1:[0-9]*" "$out/daemon.log" | tail -1)
port=${base##*:}
key=$(cat "$out/data/api-key")

# The load, the samples and the live checks; the figures go to summary.json.
status=0
python3 - "$port" "$key" "$pid" "$out" "$models" "$seconds" <<'PY' || status=$?
import base64, collections, hashlib, http.client, json, os, random, re, socket, struct, subprocess, sys, threading, time

PORT, KEY, PID, OUT, MODELS, SECONDS = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5], float(sys.argv[6])
env = lambda name, default: float(os.environ.get(name, default))
WARMUP, SAMPLE, SETTLE = env("SOAK_WARMUP", 60), env("SOAK_SAMPLE", 60), env("SOAK_SETTLE", 10)
WS_CLIENTS = int(env("SOAK_WS_CLIENTS", 6))
MARGIN = {"rss_mb": env("SOAK_RSS_MB", 20), "fds": env("SOAK_FDS", 5), "threads": env("SOAK_THREADS", 2),
          "disk_kb_per_print": env("SOAK_DISK_KB_PER_PRINT", 1), "disk_slack_mb": env("SOAK_DISK_SLACK_MB", 4)}
DATA = os.path.join(OUT, "data")
PRINTERS = ["fast", "pingpong"]
T0 = time.monotonic()
lock = threading.Lock()
failures = []              # (seconds since start, what)
http_counts = collections.Counter()   # (method, label, status)
stats = collections.Counter()

def now(): return time.monotonic() - T0
def fail(what):
    with lock:
        failures.append((round(now(), 1), what))
        n = len(failures)
    if n <= 50: print(f"  [{now():7.1f} s] FAIL: {what}", flush=True)
    elif n == 51: print(f"  [{now():7.1f} s] (more failures are counted, not shown)", flush=True)
def log(msg): print(f"  [{now():7.1f} s] {msg}", flush=True)
def bump(name, n=1):
    with lock:
        stats[name] += n

# ---- HTTP -------------------------------------------------------------------------------
class Api:
    """One client; persistent=True keeps its connection alive between requests."""
    def __init__(self, persistent=False):
        self.persistent, self.conn = persistent, None

    def request(self, method, path, body=None, headers=None, label=None, expect=(200,)):
        h = {"X-Api-Key": KEY}
        h.update(headers or {})
        label = label or path
        for attempt in (0, 1):
            reused = self.conn is not None
            if self.conn is None:
                self.conn = http.client.HTTPConnection("127.0.0.1", PORT, timeout=60)
            try:
                self.conn.request(method, path, body=body, headers=h)
                r = self.conn.getresponse()
                data = r.read()
                status, rh = r.status, {k.lower(): v for k, v in r.getheaders()}
                if not self.persistent or rh.get("connection", "").lower() == "close":
                    self.conn.close(); self.conn = None
                break
            except (http.client.RemoteDisconnected, BrokenPipeError, ConnectionResetError) as e:
                self.conn.close(); self.conn = None
                if reused and attempt == 0 and method == "GET":  # a keep-alive connection the server had closed
                    bump("http_keepalive_reconnects")
                    continue
                fail(f"HTTP {method} {label}: {type(e).__name__}: {e}")
                return None, {}, b""
            except (OSError, http.client.HTTPException) as e:
                if self.conn: self.conn.close()
                self.conn = None
                fail(f"HTTP {method} {label}: {type(e).__name__}: {e}")
                return None, {}, b""
        with lock:
            http_counts[(method, label, status)] += 1
        if status >= 500:
            fail(f"HTTP {method} {label} -> {status}: {data[:200]!r}")
        elif status not in expect:
            fail(f"HTTP {method} {label} -> {status} (expected {expect}): {data[:200]!r}")
        return status, rh, data

    def json(self, method, path, **kw):
        status, rh, data = self.request(method, path, **kw)
        try:
            return status, rh, (json.loads(data) if data else None)
        except ValueError:
            fail(f"HTTP {method} {kw.get('label', path)}: not JSON: {data[:200]!r}")
            return status, rh, None

def multipart(fields):
    boundary = "soak" + os.urandom(8).hex()
    out = b""
    for name, filename, value in fields:
        disp = f'form-data; name="{name}"' + (f'; filename="{filename}"' if filename else "")
        out += f"--{boundary}\r\nContent-Disposition: {disp}\r\n".encode()
        if filename: out += b"Content-Type: application/octet-stream\r\n"
        out += b"\r\n" + value + b"\r\n"
    out += f"--{boundary}--\r\n".encode()
    return out, {"Content-Type": f"multipart/form-data; boundary={boundary}"}

def read_model(name):
    with open(os.path.join(MODELS, name), "rb") as f:
        return f.read()
MODEL_BYTES = {m: read_model(m) for m in ("suzanne.obj", "cube_binary.ply", "spot.obj")}

def submit(api, model, settings):
    body, h = multipart([("file", model, MODEL_BYTES[model]), ("settings", None, json.dumps(settings).encode())])
    status, _, j = api.json("POST", "/api/v1/jobs", body=body, headers=h, label="/api/v1/jobs", expect=(200, 201))
    if j is None or "id" not in j: return None, status
    return j["id"], status

def wait_job(api, jid, timeout=300):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        _, _, j = api.json("GET", f"/api/v1/jobs/{jid}", label="/api/v1/jobs/{id}")
        if j and j.get("state") in ("done", "failed", "cancelled"): return j
        time.sleep(0.25)
    fail(f"job {jid} not finished after {timeout} s")
    return None

def job_digests(j):
    r = j.get("result") or {}
    return {r[k] for k in ("gcode", "plan", "plot", "model", "saliency") if isinstance(r.get(k), str)}

def object_path(d): return os.path.join(DATA, "files", "objects", d[:2], d[2:])

def metrics(api):
    status, _, data = api.request("GET", "/metrics", label="/metrics")
    m = {}
    for line in (data or b"").decode(errors="replace").splitlines():
        if line and not line.startswith("#"):
            k, _, v = line.rpartition(" ")
            try: m[k] = float(v)
            except ValueError: pass
    return m

# ---- the print pool: three jobs (and their G-code uploaded) kept for the whole soak ------
POOL_SPECS = [("suzanne.obj", {"up": "y", "height": 10}), ("cube_binary.ply", {"up": "y", "height": 5}),
              ("spot.obj", {"up": "y", "height": 8})]
setup = Api()
pool = []   # {"job", "file", "gcode"}
pool_digests = set()
for model, settings in POOL_SPECS:
    jid, _ = submit(setup, model, settings)
    j = wait_job(setup, jid) if jid else None
    if not j or j["state"] != "done":
        print(f"FAIL: pool job {model} did not finish: {j}"); sys.exit(1)
    _, _, gcode = setup.request("GET", f"/api/v1/jobs/{jid}/gcode", label="/api/v1/jobs/{id}/gcode")
    name = "soak-" + model.split(".")[0] + ".gcode"
    body, h = multipart([("file", name, gcode)])
    setup.request("POST", "/api/files/local", body=body, headers=h, label="/api/files/local", expect=(201,))
    pool.append({"job": jid, "file": name, "gcode": gcode, "lines": j["result"].get("layers")})
    pool_digests |= job_digests(j) | {hashlib.sha256(MODEL_BYTES[model]).hexdigest()}
    pool_digests.add(hashlib.sha256(gcode).hexdigest())
log(f"pool: {', '.join(p['job'] + ' ' + p['file'] for p in pool)}")

# ---- printers: print continuously, re-print when each finishes ----------------------------
started_prints = {p: [] for p in PRINTERS}   # print ids the soak started
finished_ok = collections.Counter()

def printer_status(api, pid_):
    _, _, s = api.json("GET", f"/api/v1/printers/{pid_}", label="/api/v1/printers/{id}")
    return s

def wait_operational(api, printer, timeout=120):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        s = printer_status(api, printer)
        if s and s["state"] == "operational" and s["print"] is None: return s
        if s and s["state"] in ("error", "disconnected"):
            fail(f"printer {printer} is {s['state']}: {s.get('error')}; connecting again")
            bump("reconnects")
            api.request("POST", f"/api/v1/printers/{printer}/connect", label="/api/v1/printers/{id}/connect",
                        expect=(202, 409))
            time.sleep(2)
        time.sleep(0.5)
    fail(f"printer {printer} not operational after {timeout} s")
    return None

def printer_loop(printer, stop, seed):
    rng = random.Random(seed)
    api = Api(persistent=True)
    i = 0
    while not stop.is_set():
        if not wait_operational(api, printer): return
        p = pool[rng.randrange(len(pool))]
        # "fast" is the first printer: OctoPrint's upload with print=true reaches it.
        mode = ["upload", "file", "job"][i % 3] if printer == "fast" else ["job", "file"][i % 2]
        i += 1
        t_start = time.monotonic()
        if mode == "upload":
            body, h = multipart([("file", p["file"], p["gcode"]), ("print", None, b"true")])
            status, _, _ = api.request("POST", "/api/files/local", body=body, headers=h, label="/api/files/local",
                                       expect=(201,))
            if status != 201: time.sleep(2); continue
            _, _, lst = api.json("GET", f"/api/v1/printers/{printer}/prints", label="/api/v1/printers/{id}/prints")
            print_id = max(r["id"] for r in lst["prints"]) if lst and lst.get("prints") else None
        else:
            body = json.dumps({"job": p["job"]} if mode == "job" else {"file": p["file"]})
            status, rh, _ = api.request("POST", f"/api/v1/printers/{printer}/print", body=body,
                                        headers={"Content-Type": "application/json"},
                                        label="/api/v1/printers/{id}/print", expect=(202,))
            if status != 202: time.sleep(2); continue
            m = re.search(r"print=(\d+)", rh.get("location", ""))
            print_id = int(m.group(1)) if m else None
        if print_id is None:
            fail(f"{printer}: no print id after starting a print ({mode})"); continue
        with lock:
            started_prints[printer].append(print_id)
        # Until it is the printer's last print (poll once a second, like a dashboard).
        deadline = t_start + 600
        while True:
            s = printer_status(api, printer)
            if s and s["state"] in ("error", "disconnected"):
                fail(f"{printer} print {print_id}: printer {s['state']}: {s.get('error')}")
                break
            lp = s and s.get("last_print")
            if s and (s["print"] is None or s["print"]["id"] != print_id) and lp and lp["id"] == print_id:
                if lp["state"] == "finished" and lp["confirmed"] == lp["total"]:
                    with lock:
                        finished_ok[printer] += 1
                        stats["print_lines"] += lp["total"]
                        stats[f"print_seconds_{printer}"] += time.monotonic() - t_start
                else:
                    fail(f"{printer} print {print_id} ({p['file']}): {lp['state']} {lp['confirmed']}/{lp['total']} "
                         f"reason {lp.get('reason')}")
                break
            if time.monotonic() > deadline:
                fail(f"{printer} print {print_id}: not finished after 600 s: {s and s.get('print')}")
                break
            time.sleep(1)
        time.sleep(rng.uniform(0, 2))

# ---- jobs: submitted in bursts, waited for, downloaded, deleted ---------------------------
jobs_submitted = jobs_done = jobs_deleted = 0
CHURN = [("suzanne.obj", 6, 14), ("cube_binary.ply", 3, 8), ("spot.obj", 5, 12)]
EXTRAS = [{}, {}, {"planner": "adapslice"}, {"saliency": "lee05"}, {"rho": 0.1}, {"planner": "hms", "infill": 0.15}]

def churn_loop(stop, seed):
    global jobs_submitted, jobs_done, jobs_deleted
    rng = random.Random(seed)
    api = Api()
    while not stop.is_set():
        burst = {}
        for _ in range(rng.randint(1, 3)):
            model, lo, hi = CHURN[rng.randrange(len(CHURN))]
            h = round(rng.uniform(lo, hi), 2)
            if h == int(h): h += 0.01          # never the pool's settings
            settings = {"up": "y", "height": h, **rng.choice(EXTRAS)}
            jid, status = submit(api, model, settings)
            if jid:
                burst[jid] = settings
                with lock: jobs_submitted += 1
        finished = {}
        for jid in burst:
            j = wait_job(api, jid)
            if j is None: continue
            if j["state"] != "done":
                fail(f"job {jid} {burst[jid]}: {j['state']}: {j.get('error')}")
            else:
                with lock: jobs_done += 1
            finished[jid] = j
        for jid, j in finished.items():
            if j["state"] == "done":
                what = rng.choice(["gcode", "plan", "plot.svg", "model.3mf", "saliency.ply"])
                api.request("GET", f"/api/v1/jobs/{jid}/{what}", label="/api/v1/jobs/{id}/" + what)
        remaining = dict(finished)
        for jid, j in finished.items():
            status, _, _ = api.request("DELETE", f"/api/v1/jobs/{jid}", label="/api/v1/jobs/{id}", expect=(204,))
            del remaining[jid]
            if status == 204:
                with lock: jobs_deleted += 1
            api.request("GET", f"/api/v1/jobs/{jid}", label="/api/v1/jobs/{id} (deleted)", expect=(404,))
            keep = set(pool_digests)
            for other in remaining.values(): keep |= job_digests(other)
            for d in job_digests(j) - keep:
                if os.path.exists(object_path(d)):
                    fail(f"job {jid} deleted but its file {d[:12]}… is still on disk")
                else:
                    bump("job_files_removed")
        time.sleep(rng.uniform(2, 6))

# ---- WebSocket clients -----------------------------------------------------------------------
def ws_send(sock, opcode, payload):
    mask = os.urandom(4)
    n = len(payload)
    head = bytes([0x80 | opcode]) + (bytes([0x80 | n]) if n < 126 else
                                     bytes([0x80 | 126]) + struct.pack("!H", n) if n < 65536 else
                                     bytes([0x80 | 127]) + struct.pack("!Q", n))
    sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))

class Frames:
    def __init__(self, sock): self.sock, self.buf = sock, b""
    def next(self):
        """A frame (fin, opcode, payload), or None on a timeout; raises EOFError when the peer closed."""
        while True:
            if len(self.buf) >= 2:
                b0, b1 = self.buf[0], self.buf[1]
                n, at = b1 & 0x7F, 2
                if n == 126 and len(self.buf) >= 4: n, at = struct.unpack("!H", self.buf[2:4])[0], 4
                elif n == 127 and len(self.buf) >= 10: n, at = struct.unpack("!Q", self.buf[2:10])[0], 10
                elif n >= 126: n = None
                if b1 & 0x80: raise ValueError("the server masked a frame")
                if n is not None and len(self.buf) >= at + n:
                    payload, self.buf = self.buf[at:at + n], self.buf[at + n:]
                    return bool(b0 & 0x80), b0 & 0x0F, payload
            try:
                chunk = self.sock.recv(65536)
            except socket.timeout:
                return None
            if not chunk: raise EOFError("connection closed")
            self.buf += chunk

ws_live = 0
ws_summary = collections.Counter()

def ws_client(n, stop):
    global ws_live
    rng = random.Random(1000 + n)
    topics = rng.sample(["jobs", "printers", "printer/fast", "printer/pingpong"], rng.randint(1, 3))
    if rng.random() < 0.2 and pool: topics.append("job/" + pool[rng.randrange(len(pool))]["job"])
    by_query = rng.random() < 0.3
    auth = rng.choice(["header", "bearer", "query"])
    query = []
    if by_query: query.append("topics=" + ",".join(topics))
    if auth == "query": query.append("apikey=" + KEY)
    target = "/api/v1/events" + ("?" + "&".join(query) if query else "")
    nonce = base64.b64encode(os.urandom(16)).decode()
    hdr = {"header": f"X-Api-Key: {KEY}\r\n", "bearer": f"Authorization: Bearer {KEY}\r\n", "query": ""}[auth]
    life = rng.uniform(3, 45)
    leave = rng.choice(["close", "close", "abrupt", "reset", "mid-frame"])
    stall = rng.random() < 0.15
    with lock: ws_live += 1
    try:
        sock = socket.create_connection(("127.0.0.1", PORT), timeout=10)
        sock.sendall((f"GET {target} HTTP/1.1\r\nHost: 127.0.0.1:{PORT}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                      f"Sec-WebSocket-Key: {nonce}\r\nSec-WebSocket-Version: 13\r\n{hdr}\r\n").encode())
        resp = b""
        while b"\r\n\r\n" not in resp:
            chunk = sock.recv(4096)
            if not chunk: raise EOFError("closed during the handshake")
            resp += chunk
        head, _, rest = resp.partition(b"\r\n\r\n")
        lines = head.decode(errors="replace").split("\r\n")
        want = base64.b64encode(hashlib.sha1((nonce + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11").encode()).digest()).decode()
        if " 101 " not in lines[0] + " " or f"sec-websocket-accept: {want}".lower() not in head.decode().lower():
            fail(f"ws {n}: handshake refused: {lines[0]}"); sock.close(); return
        frames = Frames(sock)
        frames.buf = rest
        sock.settimeout(0.5)
        if not by_query:
            ws_send(sock, 0x1, json.dumps({"subscribe": topics}).encode())
        got = collections.Counter()
        deadline = time.monotonic() + life
        stall_at = time.monotonic() + life / 3 if stall else None
        server_closed = None
        while time.monotonic() < deadline and not stop.is_set():
            if stall_at and time.monotonic() > stall_at:
                time.sleep(min(12, life / 3)); stall_at = None   # a client that stops reading for a while
            f = frames.next()
            if f is None: continue
            fin, op, payload = f
            if op == 0x9: ws_send(sock, 0xA, payload); continue
            if op == 0x8:
                code = struct.unpack("!H", payload[:2])[0] if len(payload) >= 2 else None
                server_closed = (code, payload[2:].decode(errors="replace")); break
            if op != 0x1 or not fin:
                fail(f"ws {n}: unexpected frame opcode {op} fin {fin}"); continue
            try:   # events name their most specific topic: "jobs" brings job/ID, "printers" printer/ID
                m = json.loads(payload)
                if m.get("type") == "subscribed":
                    assert sorted(m["data"]["topics"]) == sorted(topics), m["data"]
                    got["(subscribed)"] += 1; continue
                assert set(m) >= {"type", "topic", "time", "data"}, m.keys()
                t = m["topic"]
                assert t in topics or (t.startswith("job/") and "jobs" in topics) or \
                    (t.startswith("printer/") and "printers" in topics), f"topic {t} not subscribed ({topics})"
            except (ValueError, AssertionError, KeyError, TypeError) as e:
                fail(f"ws {n}: bad message {payload[:120]!r}: {e}"); continue
            got[t] += 1
            if t.startswith("printer/") and "printers" in topics: got["printers"] += 1
        if server_closed:
            fail(f"ws {n}: the server closed it: {server_closed}")
        lived = life - max(0, deadline - time.monotonic())
        if lived >= 3 and not stop.is_set():
            for t in topics:
                if t.startswith("printer") and got[t] == 0:   # a new subscriber first gets the current state
                    fail(f"ws {n}: no message on {t} in {lived:.0f} s (subscribed {topics})")
            if not by_query and got["(subscribed)"] != 1:
                fail(f"ws {n}: {got['(subscribed)']} replies to its subscribe")
        with lock:
            ws_summary["clients"] += 1
            ws_summary["messages"] += sum(v for k, v in got.items() if k != "printers")
            ws_summary["leave_" + leave] += 1
            if stall: ws_summary["stalled_readers"] += 1
        if leave == "close":
            ws_send(sock, 0x8, struct.pack("!H", 1000) + b"bye")
            sock.settimeout(5)
            try:   # the server answers with its close; messages may come first
                while True:
                    f = frames.next()
                    if f is None or f[1] == 0x8: break
            except EOFError:
                pass
            sock.close()
        elif leave == "abrupt":
            sock.close()
        elif leave == "reset":
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            sock.close()
        else:  # half a frame, then gone
            sock.sendall(bytes([0x81, 0x80 | 100]) + os.urandom(4) + b"{\"subscr")
            sock.close()
    except (OSError, EOFError, ValueError) as e:
        fail(f"ws {n}: {type(e).__name__}: {e}")
    finally:
        with lock: ws_live -= 1

ws_serial = 0
def ws_manager(stop):
    global ws_serial
    threads = []
    while not stop.is_set():
        threads = [t for t in threads if t.is_alive()]
        while len(threads) < WS_CLIENTS and not stop.is_set():
            ws_serial += 1
            t = threading.Thread(target=ws_client, args=(ws_serial, stop), daemon=True)
            t.start(); threads.append(t)
            time.sleep(0.2)
        time.sleep(0.5)
    for t in threads: t.join(30)

# ---- samples -------------------------------------------------------------------------------
def proc_sample(api, phase):
    st = open(f"/proc/{PID}/status").read()
    field = lambda k: int(re.search(rf"^{k}:\s+(\d+)", st, re.M).group(1))
    stat = open(f"/proc/{PID}/stat").read().rsplit(")", 1)[1].split()
    tick = os.sysconf("SC_CLK_TCK")
    du = int(subprocess.run(["du", "-sb", DATA], capture_output=True, text=True).stdout.split()[0])
    size = lambda p: os.path.getsize(p) if os.path.exists(p) else 0
    objs, shards = {}, 0
    for root, dirs, files in os.walk(os.path.join(DATA, "files", "objects")):
        shards += len(dirs)
        for f in files: objs[os.path.basename(root) + f] = size(os.path.join(root, f))
    m = metrics(api)
    with lock:
        row = {"elapsed_s": round(now()), "phase": phase, "rss_kb": field("VmRSS"), "fds": len(os.listdir(f"/proc/{PID}/fd")),
               "threads": field("Threads"), "data_bytes": du, "db_bytes": size(os.path.join(DATA, "salient.db")),
               "wal_bytes": size(os.path.join(DATA, "salient.db-wal")), "objects": len(objs),
               "object_bytes": sum(objs.values()), "shard_dirs": shards,
               "cpu_s": round((int(stat[11]) + int(stat[12])) / tick, 1),
               "ws_subscribers": int(m.get("salient_event_subscribers", -1)),
               "prints_finished": sum(finished_ok.values()), "jobs_done": jobs_done, "ws_clients": ws_summary["clients"],
               "load1": os.getloadavg()[0], "start_time": int(stat[19])}
    return row, objs

CSV = os.path.join(OUT, "soak.csv")
COLUMNS = ["elapsed_s", "phase", "rss_kb", "fds", "threads", "data_bytes", "db_bytes", "wal_bytes", "objects", "object_bytes",
           "shard_dirs", "cpu_s",
           "ws_subscribers", "prints_finished", "jobs_done", "ws_clients", "load1"]
csv = open(CSV, "w")
csv.write(",".join(COLUMNS) + "\n")
def record(row):
    csv.write(",".join(str(row[c]) for c in COLUMNS) + "\n"); csv.flush()
    log(f"{row['phase']:8s} RSS {row['rss_kb'] / 1024:6.1f} MB  fds {row['fds']:3d}  threads {row['threads']:2d}  "
        f"data {row['data_bytes'] / 1024:8.1f} KB  objects {row['objects']}  ws {row['ws_subscribers']}  "
        f"prints {row['prints_finished']}  jobs {row['jobs_done']}  cpu {row['cpu_s']} s  load {row['load1']:.2f}")

def sims():
    kids = []
    for task in os.listdir(f"/proc/{PID}/task"):   # each printer's thread starts its own simulator
        try: kids += open(f"/proc/{PID}/task/{task}/children").read().split()
        except OSError: pass
    out = []
    for k in kids:
        try:
            if "salient-sim" in open(f"/proc/{k}/cmdline").read(): out.append(int(k))
        except OSError: pass
    return sorted(out)

def run_load(duration, sampling):
    stop = threading.Event()
    threads = [threading.Thread(target=printer_loop, args=(p, stop, 17 + i), daemon=True) for i, p in enumerate(PRINTERS)]
    threads.append(threading.Thread(target=churn_loop, args=(stop, 99 + int(now())), daemon=True))
    threads.append(threading.Thread(target=ws_manager, args=(stop,), daemon=True))
    for t in threads: t.start()
    api = Api()
    end = time.monotonic() + duration
    next_sample = time.monotonic() + SAMPLE
    while time.monotonic() < end:
        time.sleep(min(1, max(0, end - time.monotonic())))
        if sampling and time.monotonic() >= next_sample:
            record(proc_sample(api, "load")[0]); next_sample += SAMPLE
        if not os.path.exists(f"/proc/{PID}"):
            fail("salientd is gone"); break
    log("load stops: the prints and jobs in progress finish, the WebSocket clients leave")
    stop.set()
    for t in threads: t.join(900)
    if any(t.is_alive() for t in threads): fail("a load thread did not finish within 900 s of the stop")

def settle(phase):
    api = Api()
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        m = metrics(api)
        ps = [printer_status(api, p) for p in PRINTERS]
        idle = all(s and s["state"] == "operational" and s["print"] is None for s in ps)
        if (idle and m.get("salient_event_subscribers") == 0 and m.get("salient_job_queue_length") == 0
                and m.get('salient_jobs{state="running"}') == 0 and m.get('salient_jobs{state="queued"}') == 0):
            break
        time.sleep(1)
    else:
        fail(f"{phase}: not settled after 120 s: subscribers {m.get('salient_event_subscribers')}, "
             f"printers {[s and s['state'] for s in ps]}")
    time.sleep(SETTLE)
    row, objs = proc_sample(api, phase)
    record(row)
    return row, objs

idle_row, _ = proc_sample(setup, "idle")
record(idle_row)
log(f"warm-up: {WARMUP:.0f} s of the same load")
run_load(WARMUP, sampling=False)
base_row, base_objs = settle("baseline")
base_sims = sims()
prints_at_baseline = {p: len(v) for p, v in started_prints.items()}
log(f"soak: {SECONDS:.0f} s; simulators {base_sims}")
run_load(SECONDS, sampling=True)
end_row, end_objs = settle("end")
end_sims = sims()

# ---- checks ------------------------------------------------------------------------------------
api = Api()
m = metrics(api)
server_5xx = {k: v for k, v in m.items() if k.startswith("salient_http_requests_total") and re.search(r'status="5', k)}
checks = []
def check(name, ok, detail):
    checks.append({"check": name, "ok": bool(ok), "detail": detail})

d_rss = (end_row["rss_kb"] - base_row["rss_kb"]) / 1024
d_fds = end_row["fds"] - base_row["fds"]
d_threads = end_row["threads"] - base_row["threads"]
soak_prints = sum(len(v) for v in started_prints.values()) - sum(prints_at_baseline.values())
all_prints = sum(len(v) for v in started_prints.values())
d_disk = end_row["data_bytes"] - base_row["data_bytes"]
disk_allow = MARGIN["disk_kb_per_print"] * 1024 * soak_prints + MARGIN["disk_slack_mb"] * 1024 * 1024 + 256 * 4096
load_rows = [l.split(",") for l in open(CSV).read().splitlines()[1:] if ",load," in l]
rss_series = [int(r[2]) / 1024 for r in load_rows]
slope = 0.0
if len(rss_series) >= 3:   # MB per hour over the samples under load
    ts = [int(r[0]) for r in load_rows]
    mt, mr = sum(ts) / len(ts), sum(rss_series) / len(rss_series)
    slope = sum((t - mt) * (r - mr) for t, r in zip(ts, rss_series)) / max(1e-9, sum((t - mt) ** 2 for t in ts)) * 3600

check("RSS", abs(d_rss) <= MARGIN["rss_mb"], f"{base_row['rss_kb'] / 1024:.1f} -> {end_row['rss_kb'] / 1024:.1f} MB "
      f"({d_rss:+.1f} MB, margin ±{MARGIN['rss_mb']:.0f}); under load {min(rss_series, default=0):.1f}-{max(rss_series, default=0):.1f} MB, "
      f"trend {slope:+.1f} MB/h")
check("descriptors", abs(d_fds) <= MARGIN["fds"], f"{base_row['fds']} -> {end_row['fds']} ({d_fds:+d}, margin ±{MARGIN['fds']:.0f})")
check("threads", abs(d_threads) <= MARGIN["threads"],
      f"{base_row['threads']} -> {end_row['threads']} ({d_threads:+d}, margin ±{MARGIN['threads']:.0f})")
same_objects = base_objs == end_objs
check("files", same_objects and not os.listdir(os.path.join(DATA, "files", "tmp")),
      f"stored files {len(base_objs)} -> {len(end_objs)} "
      + ("(the same files, the same sizes: every deleted job's files are gone)" if same_objects else
         f"(new {sorted(set(end_objs) - set(base_objs))[:5]}, gone {sorted(set(base_objs) - set(end_objs))[:5]})")
      + f"; files/tmp {'empty' if not os.listdir(os.path.join(DATA, 'files', 'tmp')) else 'NOT empty'}")
check("disk", d_disk <= disk_allow,
      f"data dir {base_row['data_bytes'] / 1024:.0f} -> {end_row['data_bytes'] / 1024:.0f} KB ({d_disk / 1024:+.0f} KB; "
      f"database {base_row['db_bytes'] / 1024:.0f} -> {end_row['db_bytes'] / 1024:.0f} KB, "
      f"WAL {base_row['wal_bytes'] / 1024:.0f} -> {end_row['wal_bytes'] / 1024:.0f} KB, stored files "
      f"{base_row['object_bytes'] / 1024:.0f} -> {end_row['object_bytes'] / 1024:.0f} KB, shard directories "
      f"{base_row['shard_dirs']} -> {end_row['shard_dirs']} of at most 256, kept when emptied); allowed "
      f"{MARGIN['disk_kb_per_print']:.0f} KB x {soak_prints} prints + {MARGIN['disk_slack_mb']:.0f} MB (WAL) + 1 MB (shard "
      f"directories) = {disk_allow / 1024:.0f} KB")
ok_prints = sum(finished_ok.values())
check("prints", ok_prints == all_prints and all_prints > 0,
      f"{ok_prints} of {all_prints} prints finished with confirmed == total "
      f"({', '.join(f'{p}: {finished_ok[p]}' for p in PRINTERS)}; {stats['print_lines']} commands; "
      f"{soak_prints} after the baseline)")
check("jobs", jobs_done == jobs_submitted and jobs_deleted == jobs_done and jobs_submitted > 0,
      f"{jobs_submitted} submitted, {jobs_done} done, {jobs_deleted} deleted; {stats['job_files_removed']} of their "
      f"files checked gone on deletion")
n5 = sum(v for (_, _, s), v in http_counts.items() if s >= 500)
check("HTTP", n5 == 0 and not server_5xx,
      f"{sum(http_counts.values())} requests, {n5} 5xx seen by the clients, {int(sum(server_5xx.values()))} 5xx in /metrics; "
      f"statuses {dict(sorted(collections.Counter(s for (_, _, s) in http_counts.elements()).items()))}")
check("WebSocket", ws_summary["clients"] > 0 and end_row["ws_subscribers"] == 0,
      f"{ws_summary['clients']} clients, {ws_summary['messages']} messages; left by close {ws_summary['leave_close']}, "
      f"abrupt {ws_summary['leave_abrupt']}, reset {ws_summary['leave_reset']}, mid-frame {ws_summary['leave_mid-frame']}; "
      f"{ws_summary['stalled_readers']} stalled readers; subscribers at the end {end_row['ws_subscribers']}")
check("no restart", end_row["start_time"] == idle_row["start_time"] and (base_sims == end_sims or stats["reconnects"])
      and len(end_sims) == 2, f"salientd pid {PID} throughout (same start time); simulators {base_sims} -> {end_sims}, "
      f"{stats['reconnects']} reconnects after a printer error (each starts a new simulator)")
pm = lambda name, printer, result=None: m.get(f'salient_{name}{{printer="{printer}"' + (f',result="{result}"' if result else "") + "}", 0)
lost = sum(pm("prints_total", p, "failed") for p in PRINTERS)
check("printer metrics", lost == 0,
      "/metrics: prints finished " + ", ".join(f"{p} {pm('prints_total', p, 'finished'):.0f}" for p in PRINTERS)
      + f", failed {lost:.0f}; lines sent " + " + ".join(f"{pm('print_lines_total', p):.0f}" for p in PRINTERS)
      + ", resends " + " + ".join(f"{pm('print_resends_total', p):.0f}" for p in PRINTERS))
check("live checks", not failures, f"{len(failures)} failures during the run" + (f", first: {failures[:3]}" if failures else ""))

print("\nsoak figures (baseline and end: load stopped and settled)")
for c in checks:
    print(f"  {'ok  ' if c['ok'] else 'FAIL'} {c['check']:16s} {c['detail']}")
for t, what in failures[:30]:
    print(f"       at {t:7.1f} s: {what}")
summary = {"checks": checks, "failures": failures, "baseline": base_row, "end": end_row, "idle": idle_row,
           "margins": MARGIN, "prints": {p: len(v) for p, v in started_prints.items()}, "soak_prints": soak_prints,
           "print_ids": started_prints, "pool": [{k: p[k] for k in ("job", "file")} for p in pool],
           "jobs": {"submitted": jobs_submitted, "done": jobs_done, "deleted": jobs_deleted},
           "ws": dict(ws_summary), "http": {f"{a} {b} {c}": v for (a, b, c), v in sorted(http_counts.items())},
           "stats": dict(stats), "seconds": SECONDS, "warmup": WARMUP}
json.dump(summary, open(os.path.join(OUT, "summary.json"), "w"), indent=1)
sys.exit(0 if all(c["ok"] for c in checks) else 1)
PY

# SIGTERM: stopped within 5 s, exit status 0.
alive=no; [ -d "/proc/$pid" ] && alive=yes
t0=$EPOCHREALTIME
kill -TERM "$pid" 2>/dev/null || true
( sleep 30; kill -KILL "$pid" 2>/dev/null ) & watchdog=$!
rc=0; wait "$pid" || rc=$?
t1=$EPOCHREALTIME
kill "$watchdog" 2>/dev/null || true; wait "$watchdog" 2>/dev/null || true
pid=
stop_s=$(python3 -c "print(f'{$t1 - $t0:.2f}')")
if [ "$alive" = yes ] && [ "$rc" -eq 0 ] && python3 -c "import sys; sys.exit(0 if $t1 - $t0 <= 5 else 1)"; then
  echo "  ok   SIGTERM          stopped in $stop_s s, exit status $rc"
else
  echo "  FAIL SIGTERM          alive before: $alive; stopped in $stop_s s, exit status $rc"; status=1
fi

# Afterwards, the database itself: only the prints' rows grew; every print finished, confirmed == total.
python3 - "$out" <<'PY' || status=1
import json, os, sqlite3, sys
out = sys.argv[1]
s = json.load(open(os.path.join(out, "summary.json")))
db = sqlite3.connect(f"file:{os.path.join(out, 'data', 'salient.db')}?mode=ro", uri=True)
q = lambda sql: db.execute(sql).fetchall()
integrity = q("PRAGMA integrity_check")[0][0]
jobs = q("SELECT id, state FROM jobs")
files = q("SELECT name FROM files")
prints = q("SELECT id, state, confirmed, total FROM prints")
bad = [p for p in prints if p[1] != "finished" or p[2] != p[3]]
want_ids = sorted(i for v in s["print_ids"].values() for i in v)
pool_jobs = sorted(p["job"] for p in s["pool"])
ok = (integrity == "ok" and sorted(j[0] for j in jobs) == pool_jobs and len(files) == len(s["pool"])
      and not bad and sorted(p[0] for p in prints) == want_ids)
print(f"  {'ok  ' if ok else 'FAIL'} database         integrity {integrity}; jobs {len(jobs)} (the pool: "
      f"{sorted(j[0] for j in jobs) == pool_jobs}), uploaded files {len(files)}, prints {len(prints)} "
      f"(those the soak started: {sorted(p[0] for p in prints) == want_ids}), not finished or short: {len(bad)}; "
      f"free pages {q('PRAGMA freelist_count')[0][0]} of {q('PRAGMA page_count')[0][0]}")
sys.exit(0 if ok else 1)
PY

# The daemon's log: one start, one stop, and what else it said besides requests.
sims=$(grep -c "salient-sim: stopped after" "$out/daemon.log" || true)
want_sims=$(python3 -c "import json; print(2 + json.load(open('$out/summary.json'))['stats'].get('reconnects', 0))" 2>/dev/null || echo "?")
if [ "$sims" = "$want_sims" ]; then
  echo "  ok   simulators       $sims started and stopped: 2 + one per reconnect"
else
  echo "  FAIL simulators       $sims stopped, expected $want_sims (2 + one per reconnect)"; status=1
fi
starts=$(grep -c "listening on" "$out/daemon.log" || true)
stops=$(grep -c "stopping (SIGTERM)" "$out/daemon.log" || true)
http5=$(grep -c "http .*status=5[0-9][0-9]" "$out/daemon.log" || true)
other=$(grep -v " http method=\| job id=" "$out/daemon.log" | grep -v "api key (shown once" | grep -vc "listening on\|stopping (SIGTERM)\|^[0-9TZ:-]* stopped$\|salient-sim: stopped after" || true)
if [ "$starts" -eq 1 ] && [ "$stops" -eq 1 ] && [ "$http5" -eq 0 ]; then
  echo "  ok   daemon log       1 start, 1 SIGTERM stop, no 5xx logged; $other other lines"
else
  echo "  FAIL daemon log       $starts starts, $stops SIGTERM stops, $http5 5xx logged; $other other lines"; status=1
fi
echo "    $(grep -c " http method=" "$out/daemon.log" || true) request lines, $(grep -c " job id=" "$out/daemon.log" || true) job lines; the rest:"
grep -v " http method=\| job id=" "$out/daemon.log" | grep -v "api key (shown once" | sed 's/^[0-9TZ:-]* //' |
  sed -E 's/[0-9]+/N/g' | sort | uniq -c | sort -rn | head -15 | sed 's/^/    /'
echo "soak: $( [ "$status" -eq 0 ] && echo PASS || echo FAIL ); CSV $out/soak.csv, summary $out/summary.json, log $out/daemon.log"
exit "$status"
