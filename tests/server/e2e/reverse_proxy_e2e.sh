#!/usr/bin/env bash
# salientd behind a real nginx running deploy/nginx/salient.conf (ports, upstream and certificate
# substituted; a self-signed certificate made here by openssl): over TLS at the root and under
# /salient/, a model upload and a large file upload, the events WebSocket and OctoPrint's push
# socket, Location headers and OctoPrint refs with the proxy's scheme, host and prefix, the page's
# relative URLs; the client address in salientd's log and in the app-key rate limits is
# X-Forwarded-For's from nginx (trusted) and the peer's own from anyone else (a spoofed header
# ignored; the per-address connection limit counts clients, not nginx). Skipped (77) only when
# nginx cannot run here.
#   reverse_proxy_e2e.sh SALIENTD MODELS_DIR WORKDIR
set -euo pipefail
salientd=$1 models=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
conf="$here/../../../deploy/nginx/salient.conf"
rm -rf "$work" && mkdir -p "$work/nginx/tmp" && cd "$work"
. "$here/../../support/salientd.sh"
nginx_pid=
cleanup() {
  [ -n "$nginx_pid" ] && kill "$nginx_pid" 2>/dev/null || true
  [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
}
trap cleanup EXIT
nginx_bin=$(command -v nginx || echo /usr/sbin/nginx)
[ -x "$nginx_bin" ] || { echo "SKIP: nginx is not installed (deploy/install-deps.sh installs it)"; exit 77; }
free_port() { /usr/bin/python3 -c "import socket; s=socket.socket(); s.bind(('127.0.0.1', 0)); print(s.getsockname()[1])"; }

# salientd trusts nginx, which connects from 127.0.0.2; clients come from 127.0.0.1/.3/.4.
cat > proxy.toml <<'TOML'
[server]
trusted_proxies = ["127.0.0.2"]
max_connections_per_address = 2

[[printers]]
id = "sim"
kind = "sim"
sim_args = "--advanced-ok --time-scale 0 --heat-time-scale 0"
TOML
start proxy.toml
openssl req -x509 -newkey rsa:2048 -nodes -keyout nginx/key.pem -out nginx/cert.pem -days 1 -subj /CN=localhost \
  2>/dev/null || fail "openssl could not make a certificate"
plain=$(free_port) tls=$(free_port)
sed -e "s|listen 80;|listen 127.0.0.1:$plain;|" -e "s|listen 443 ssl;|listen 127.0.0.1:$tls ssl;|" -e '/listen \[::\]/d' \
  -e "s|server 127.0.0.1:8080;|server 127.0.0.1:$port;|" \
  -e "s|/etc/ssl/certs/salient.crt|$work/nginx/cert.pem|" -e "s|/etc/ssl/private/salient.key|$work/nginx/key.pem|" \
  -e "s|proxy_http_version 1.1;|proxy_http_version 1.1;\n    proxy_bind 127.0.0.2;|" "$conf" > nginx/salient.conf
grep -q "proxy_bind 127.0.0.2" nginx/salient.conf || fail "the shipped config changed shape: the test's substitutions missed"
cat > nginx/nginx.conf <<NGINX
pid $work/nginx/nginx.pid;
error_log $work/nginx/error.log;
events { worker_connections 64; }
http {
  access_log $work/nginx/access.log;
  client_body_temp_path $work/nginx/tmp/body;
  proxy_temp_path $work/nginx/tmp/proxy;
  fastcgi_temp_path $work/nginx/tmp/fastcgi;
  uwsgi_temp_path $work/nginx/tmp/uwsgi;
  scgi_temp_path $work/nginx/tmp/scgi;
  include $work/nginx/salient.conf;
}
NGINX
"$nginx_bin" -t -p "$work/nginx" -c "$work/nginx/nginx.conf" > nginx/check.out 2>&1 || {
  cat nginx/check.out
  grep -q "emerg" nginx/check.out && grep -qv "salient.conf" nginx/check.out && { echo "SKIP: nginx cannot run here"; exit 77; }
  fail "nginx rejects deploy/nginx/salient.conf"
}
"$nginx_bin" -p "$work/nginx" -c "$work/nginx/nginx.conf" -g 'daemon off;' 2>> nginx/error.log &
nginx_pid=$!
for _ in $(seq 100); do curl -sk -o /dev/null "https://127.0.0.1:$tls/healthz" && break; sleep 0.05; done
curl -sk -o /dev/null "https://127.0.0.1:$tls/healthz" || { cat nginx/error.log; echo "SKIP: nginx did not start"; exit 77; }
proxy="https://127.0.0.1:$tls"
# via ADDRESS curl-args…: a request through nginx over TLS from a client address of ours.
via() { local from=$1; shift; curl -sk --interface "$from" -H "X-Api-Key: $key" "$@"; }

# Plain HTTP is sent to HTTPS.
[ "$(curl -s -o /dev/null -w '%{http_code} %{redirect_url}' "http://127.0.0.1:$plain/x")" = "301 https://127.0.0.1/x" ] ||
  fail "http → https: $(curl -s -o /dev/null -w '%{http_code} %{redirect_url}' "http://127.0.0.1:$plain/x")"

# The page under /salient/: its URLs are relative, so they stay under the prefix.
[ "$(curl -sk -o /dev/null -w '%{http_code} %{redirect_url}' "$proxy/salient")" = "301 https://127.0.0.1:$tls/salient/" ] ||
  fail "/salient without its slash: $(curl -sk -o /dev/null -w '%{http_code} %{redirect_url}' "$proxy/salient")"
curl -skf -o page.html "$proxy/salient/" || fail "the page under /salient/"
grep -q 'src="web/app.js"' page.html || fail "the page's script URL is not relative: $(grep app.js page.html)"
grep -q 'href="/' page.html && fail "an absolute URL left in the page: $(grep -o 'href="/[^"]*"' page.html)"
for f in app.js api.js style.css; do curl -skf -o /dev/null "$proxy/salient/web/$f" || fail "/salient/web/$f"; done
curl -skf -o api.js "$proxy/salient/web/api.js" && ! grep -q "'/api/v1" api.js || fail "api.js still calls /api/v1 absolutely"
echo "page under /salient/: relative URLs, assets served"

# A model through nginx over TLS, under the prefix: 201, and a Location under the prefix.
via 127.0.0.3 -D job.headers -o job.json -F "file=@$models/cube_binary.ply" -F 'settings={"height": 10}' \
  "$proxy/salient/api/v1/jobs" || fail "job submit through nginx"
grep -q "^HTTP/1.1 20[12]" job.headers || fail "job submit: $(head -1 job.headers) $(cat job.json)"
id=$(field "['id']" < job.json)
location=$(grep -i '^location:' job.headers | tr -d '\r' | cut -d' ' -f2)
[ "$location" = "/salient/api/v1/jobs/$id" ] || fail "the job's Location: '$location'"
for _ in $(seq 300); do [ "$(via 127.0.0.3 "$proxy$location" | field "['state']")" = done ] && break; sleep 0.2; done
[ "$(via 127.0.0.3 "$proxy$location" | field "['state']")" = done ] || fail "the job via its Location: $(via 127.0.0.3 "$proxy$location")"
via 127.0.0.3 -f -o job.gcode "$proxy/salient/api/v1/jobs/$id/gcode" || fail "the G-code through nginx"
echo "model uploaded through nginx (TLS, /salient/): Location $location, sliced, G-code $(wc -c < job.gcode) bytes"

# A large upload (beyond nginx's default 1 MB), streamed, OctoPrint's way at the root: its refs
# carry https and nginx's host and port.
/usr/bin/python3 -c "
import sys
with open('big.gcode', 'w') as f:
    f.write('G28\n')
    for i in range(200000): f.write(f'G1 X{i % 200} Y{(i // 200) % 200} F3000 ; padding to make it large\n')"
via 127.0.0.3 -o up.json -D up.headers -F "file=@big.gcode" "$proxy/api/files/local" || fail "large upload"
grep -q "^HTTP/1.1 201" up.headers || fail "large upload ($(wc -c < big.gcode) bytes): $(head -1 up.headers) $(head -c 300 up.json)"
[ "$(field "['files']['local']['refs']['resource']" < up.json)" = "https://127.0.0.1:$tls/api/files/local/big.gcode" ] ||
  fail "OctoPrint's refs behind the proxy: $(cat up.json)"
via 127.0.0.3 -o up2.json -F "file=@big.gcode;filename=big2.gcode" "$proxy/salient/api/files/local" || fail "upload under the prefix"
[ "$(field "['files']['local']['refs']['resource']" < up2.json)" = "https://127.0.0.1:$tls/salient/api/files/local/big2.gcode" ] ||
  fail "OctoPrint's refs under the prefix: $(cat up2.json)"
via 127.0.0.3 -f -o big.back "$proxy/salient/downloads/files/local/big.gcode" && cmp -s big.gcode big.back || fail "download through nginx"
echo "large upload through nginx: $(wc -c < big.gcode) bytes, refs https under the proxy's host (and prefix)"

# WebSockets through nginx: the events socket at the root and under the prefix, OctoPrint's push socket.
/usr/bin/python3 - "$tls" "$key" <<'PY' || fail "WebSockets through nginx"
import json, ssl, sys, websocket
port, key = sys.argv[1], sys.argv[2]
for path in ("/api/v1/events", "/salient/api/v1/events"):
    ws = websocket.create_connection(f"wss://127.0.0.1:{port}{path}", subprotocols=["salient.v1", "salient-key." + key],
                                     sslopt={"cert_reqs": ssl.CERT_NONE}, timeout=10)
    ws.send(json.dumps({"subscribe": ["printers"]}))
    kinds = []
    while "subscribed" not in kinds:
        kinds.append(json.loads(ws.recv()).get("type"))
    ws.close()
    print(f"{path} through nginx: {kinds}")
for path in ("/sockjs/websocket", "/salient/sockjs/websocket"):
    ws = websocket.create_connection(f"wss://127.0.0.1:{port}{path}", sslopt={"cert_reqs": ssl.CERT_NONE}, timeout=10)
    first = json.loads(ws.recv())
    assert "connected" in first, first
    ws.close()
    print(f"{path} through nginx: {list(first)}")
PY

# The page in a real browser under /salient/: signed in, live events, the job listed; every request
# it made went under the prefix (nginx's access log).
if [ -x /usr/bin/chromedriver ] && [ -x /usr/bin/chromium ]; then
  /usr/bin/python3 - "$tls" "$key" "$work" <<'PY' || fail "the page under /salient/ in Chromium"
import sys, time
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
tls, key, work = sys.argv[1:4]
options = webdriver.ChromeOptions()
options.binary_location = "/usr/bin/chromium"
for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--ignore-certificate-errors",
            f"--user-data-dir={work}/chromium-profile", "--user-agent=salient-proxy-test"):
    options.add_argument(arg)
d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
def wait(what, f, seconds=30):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            if f():
                return
        except Exception:
            pass
        time.sleep(0.1)
    sys.exit(f"timed out waiting for {what}; page: {d.find_element(By.TAG_NAME, 'body').text[:300]!r}")
try:
    d.get(f"https://127.0.0.1:{tls}/salient/")
    wait("the sign-in form", lambda: d.find_elements(By.CSS_SELECTOR, "#api-key"))
    d.find_element(By.CSS_SELECTOR, "#api-key").send_keys(key)
    d.find_element(By.CSS_SELECTOR, "form.sign-in button[type=submit]").click()
    wait("the jobs page", lambda: d.find_elements(By.CSS_SELECTOR, "#drop-zone"))
    wait("the live events", lambda: d.find_element(By.CSS_SELECTOR, "#link-state").text == "live")
    wait("the job in the list", lambda: "cube_binary.ply" in d.find_element(By.TAG_NAME, "body").text)
    print("the page under /salient/ in Chromium: signed in, events live, the job listed")
finally:
    d.quit()
PY
  browser_paths=$(grep "salient-proxy-test" nginx/access.log | awk '{print $7}' | sort -u)
  [ -n "$browser_paths" ] || fail "no request of the browser in nginx's log"
  echo "$browser_paths" | grep -v "^/salient/" && fail "the page made requests outside /salient/"
  echo "the browser's $(echo "$browser_paths" | wc -l) distinct paths all under /salient/"
else
  echo "note: no Chromium here: the page under /salient/ was checked with curl only"
fi

# The per-address connection limit (2 here) counts clients, not the proxy that carries them all.
/usr/bin/python3 - "$tls" "$port" "$key" <<'PY' || fail "connection limits behind nginx"
import ssl, sys, websocket
tls, port, key = sys.argv[1:4]
def events(url, **kw):
    return websocket.create_connection(url, subprotocols=["salient.v1", "salient-key." + key], timeout=10, **kw)
held = [events(f"wss://127.0.0.1:{tls}/api/v1/events", sslopt={"cert_reqs": ssl.CERT_NONE}) for _ in range(3)]
print(f"{len(held)} sockets through nginx at once (over the per-address limit of 2)")
direct = [events(f"ws://127.0.0.1:{port}/api/v1/events") for _ in range(2)]
try:
    direct.append(events(f"ws://127.0.0.1:{port}/api/v1/events"))
    sys.exit("a third direct socket from one address was allowed")
except websocket.WebSocketException as e:
    print(f"a third direct socket is refused: {e}")
for w in held + direct:
    w.close()
PY

# The client address: nginx's X-Forwarded-For believed (the right-most hop nginx added, not the
# one the client wrote), a direct client's header ignored.
via 127.0.0.3 -H "X-Forwarded-For: 6.6.6.6" -o /dev/null "$proxy/api/version"
curl -s -H "X-Forwarded-For: 7.7.7.7" -o /dev/null "$base/plugin/appkeys/probe"
eventually 5 grep -q "route=/plugin/appkeys/probe status=204 .*client=127.0.0.1$" daemon.log ||
  fail "a direct request's client: $(grep appkeys/probe daemon.log)"
grep -q "route=/api/version status=200 .*client=127.0.0.3$" daemon.log || fail "a proxied request's client: $(grep api/version daemon.log)"
grep -q "client=6.6.6.6\|client=7.7.7.7\|client=127.0.0.2" daemon.log && fail "a forged or proxy address was logged: $(grep 'client=[67]\|client=127.0.0.2' daemon.log)"
echo "logged client: 127.0.0.3 through nginx (its spoofed 6.6.6.6 ignored), 127.0.0.1 direct (its 7.7.7.7 ignored)"

# App-key requests are limited per client address (2 waiting at once): behind nginx, per real client.
ask() { via "$1" -o ask.json -D ask.headers -w '%{http_code}' -H 'Content-Type: application/json' -d '{"app": "proxy test"}' "$proxy/salient/plugin/appkeys/request"; }
for i in 1 2; do [ "$(ask 127.0.0.3)" = 201 ] || fail "app key request $i from .3: $(cat ask.json)"; done
[ "$(grep -i '^location:' ask.headers | tr -d '\r' | cut -d' ' -f2)" = "https://127.0.0.1:$tls/salient/plugin/appkeys/request/$(field "['app_token']" < ask.json)" ] ||
  fail "the app key request's Location: $(grep -i '^location:' ask.headers)"
[ "$(field "['auth_dialog']" < ask.json)" = "https://127.0.0.1:$tls/salient/" ] || fail "auth_dialog: $(cat ask.json)"
[ "$(ask 127.0.0.3)" = 429 ] || fail "a third request from .3 was not limited: $(cat ask.json)"
[ "$(ask 127.0.0.4)" = 201 ] || fail "another client behind the same proxy was limited with .3: $(cat ask.json)"
echo "app key requests: limited per client behind nginx (.3 limited at 3, .4 free); Location https under /salient/"

stop
kill "$nginx_pid"; wait "$nginx_pid" 2>/dev/null || true; nginx_pid=
grep -q "terminate called\|Aborted" daemon.log && fail "the daemon aborted"
echo "ok: salientd behind nginx (TLS, prefix, uploads, WebSockets, client addresses)"
