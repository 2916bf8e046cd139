"""What a newcomer met wrong on the page (issue 32), each checked in headless Chromium against a
real salientd with a simulated printer: no "Sign out" on the sign-in form; a wrong key refused as
a wrong key (not "a key is required"); a G-code file uploaded as PrusaSlicer does listed on the
page and printed from it; a second upload queued and shown in the printer's queue; the history
row of the print under way at the card's percentage; "Time left" in words (not 7:06); the keys
page creating a key (shown once, and working) and revoking it; on a phone, a header in one row,
a history that does not scroll sideways, and the model's height field in sight.

Every check runs and the failures are listed together.
  page_details_test.py SALIENTD WORKDIR  (exit 77 without Chromium or Selenium)"""
import json
import os
import re
import shutil
import sys
import time
import urllib.error
import urllib.request
import uuid

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import web_page_test as w  # noqa: E402  (its Daemon, browser and Page)

failures = []


def expect(condition, message):
    if condition:
        w.log("ok: " + message)
    else:
        w.log("FAILED: " + message)
        failures.append(message)


def call(daemon, method, path, body=None, key=None, headers=None):
    headers = dict(headers or {})
    if key:
        headers["X-Api-Key"] = key
    data = body
    if isinstance(body, dict):
        headers["Content-Type"] = "application/json"
        data = json.dumps(body).encode()
    request = urllib.request.Request(daemon.base + path, data=data, headers=headers, method=method)
    try:
        with urllib.request.urlopen(request, timeout=10) as r:
            text = r.read()
            return r.status, json.loads(text) if text else None
    except urllib.error.HTTPError as e:
        text = e.read()
        return e.code, json.loads(text) if text.startswith(b"{") else None


def upload(daemon, name, gcode, print_it):
    """POST /api/files/local as PrusaSlicer sends it (multipart: file, print)."""
    boundary = uuid.uuid4().hex
    parts = [(f'name="file"; filename="{name}"', "application/octet-stream", gcode.encode()),
             ('name="print"', None, b"true" if print_it else b"false")]
    body = b""
    for disposition, kind, data in parts:
        body += f"--{boundary}\r\nContent-Disposition: form-data; {disposition}\r\n".encode()
        body += (f"Content-Type: {kind}\r\n" if kind else "").encode() + b"\r\n" + data + b"\r\n"
    body += f"--{boundary}--\r\n".encode()
    return call(daemon, "POST", "/api/files/local", body, daemon.key,
                {"Content-Type": "multipart/form-data; boundary=" + boundary})


def slow_gcode(moves):
    """Moves of 20 mm at 10 mm/s: 2 s each, 0.4 s at the simulator's --time-scale 0.2."""
    lines = ["G28", "G90", "G1 Z0.3 F600"]
    for i in range(moves):
        lines.append(f"G1 X{20 + 20 * (i % 2)} Y{20 + i % 50} E{i * 0.5:.1f} F600")
    return "\n".join(lines) + "\n"


def sign_in_page(page, key):
    page.d.get(page.daemon.base + "/")
    page.wait("the sign-in form", lambda: page.find("#api-key"))
    sign_out = page.find("#sign-out")
    expect(not sign_out.is_displayed(), "no Sign out button on the sign-in form")
    page.find("#api-key").send_keys("a-key-that-salientd-never-made")
    page.find("form.sign-in button[type=submit]").click()
    page.wait("the refusal", lambda: "refused" in page.text("#sign-in-error"))
    message = page.text("#sign-in-error")
    expect("required" not in message and "not one salientd knows" in message,
           f"a wrong key is refused as a wrong key: {message!r}")
    page.find("#api-key").clear()
    page.find("#api-key").send_keys(key)
    page.find("form.sign-in button[type=submit]").click()
    page.wait("the jobs page", lambda: page.find("#drop-zone"))
    expect(page.find("#sign-out").is_displayed(), "Sign out shows once signed in")
    page.d.get_log("browser")  # the wrong key's 401 is expected in the console: drained


def files_and_queue(page, daemon):
    status, _ = upload(daemon, "sliced-by-prusaslicer.gcode", slow_gcode(600), False)
    w.check(status == 201, f"upload: {status}")
    page.d.get(daemon.base + "/#/printers")
    try:
        page.wait("the uploaded file on the page", lambda: "sliced-by-prusaslicer.gcode" in page.text("#file-list"), 10)
        expect(True, "an upload that does not print is listed on the Printers page")
        page.screenshot("printers-files")
    except w.Failure:
        expect(False, "an upload that does not print is listed on the Printers page")
        return False
    page.click("#file-list [data-path='sliced-by-prusaslicer.gcode'] button.print-file")
    page.wait("the printer page printing", lambda: page.find("#current-print .badge.state-printing"), 20)
    expect(True, "the listed file prints from the page")
    status, answer = upload(daemon, "next-in-line.gcode", slow_gcode(20), True)
    w.check(status in (201, 202) and answer.get("queued"), f"second upload: {status} {answer}")
    try:
        page.wait("the queued file on the printer's page", lambda: "next-in-line.gcode" in page.text("#print-queue"), 10)
        expect(True, "a file queued behind the print shows in the printer's queue")
        page.click("#print-queue li button.remove")
        page.confirm()
        page.wait("the queue emptied", lambda: "next-in-line.gcode" not in page.text("#print-queue"), 10)
        queue = daemon.api("/printers/sim/queue")["entries"]
        expect(queue == [], f"removed from the queue on the page, the daemon's queue is empty: {queue}")
    except w.Failure:
        expect(False, "a file queued behind the print shows in the printer's queue")
    return True


def start_print_by_api(page, daemon):
    """When the page could not print the upload, the API starts it (the later checks need it)."""
    status, _ = call(daemon, "POST", "/api/v1/printers/sim/print", {"file": "sliced-by-prusaslicer.gcode"}, daemon.key)
    w.check(status == 202, f"print by the API: {status}")
    page.d.get(daemon.base + "/#/printers/sim")
    page.wait("the printer page printing", lambda: page.find("#current-print .badge.state-printing"), 20)


def progress_and_time_left(page):
    page.wait("some progress", lambda: page.text("#print-percent") not in ("", "0.0 %"), 30)
    page.wait("the history", lambda: page.find("#print-history tbody tr"), 10)
    time.sleep(2.0)  # the print goes on: the card's percentage moves past what was saved at the start
    card, row = page.js("""
      return [document.getElementById('print-percent').textContent,
              document.querySelector('#print-history tbody tr td:nth-child(3)').textContent];""")
    number = lambda text: float(re.sub(r"[^0-9.]", "", text) or "nan")
    expect(abs(number(card) - number(row)) <= 0.5,
           f"the history row of the print under way says what its card says: {row!r} vs {card!r}")
    left = page.text("#print-left")
    expect(re.fullmatch(r"(\d+ h \d+ min|\d+ min \d+ s|\d+ s)", left) is not None,
           f"time left says its units: {left!r}")
    elapsed = page.text("#print-elapsed")
    expect(re.fullmatch(r"(\d+ h \d+ min|\d+ min \d+ s|\d+ s)", elapsed) is not None,
           f"elapsed says its units: {elapsed!r}")


def on_a_phone(page, daemon):
    page.d.set_window_size(*w.PHONE)
    time.sleep(0.4)
    page.d.save_screenshot(os.path.join(page.shots, "printer-phone.png"))
    layout = page.js("""
      const bar = document.querySelector('header.bar');
      const shown = [...bar.children].filter((el) => el.offsetParent !== null);
      const tops = shown.map((el) => Math.round(el.getBoundingClientRect().top + el.getBoundingClientRect().height / 2));
      const box = document.querySelector('#print-history').parentElement;
      return {rows: new Set(tops.map((t) => Math.round(t / 12))).size, barWidth: bar.scrollWidth,
              tallest: Math.max(...shown.map((el) => el.getBoundingClientRect().height)),
              viewport: document.documentElement.clientWidth, pageWidth: document.documentElement.scrollWidth,
              history: [box.scrollWidth, box.clientWidth]};""")
    expect(layout["rows"] == 1 and layout["tallest"] <= 48 and layout["barWidth"] <= layout["viewport"],
           f"on a phone the header is one row within the screen: {layout}")
    expect(layout["pageWidth"] <= layout["viewport"], f"on a phone the printer page fits its width: {layout}")
    expect(layout["history"][0] <= layout["history"][1] + 1, f"on a phone the history does not scroll sideways: {layout}")
    page.d.get(daemon.base + "/#/jobs")
    page.wait("the jobs page", lambda: page.find("#drop-zone"))
    time.sleep(0.3)
    page.d.save_screenshot(os.path.join(page.shots, "jobs-phone.png"))
    # (Selenium's is_displayed() and the box's size count a field in a closed <details> as shown.)
    expect(page.js("return document.getElementById('s-height').checkVisibility()"),
           "on a phone the model's height field is in sight")
    page.d.set_window_size(*w.DESKTOP)


def keys_create_and_revoke(page, daemon):
    page.d.get(daemon.base + "/#/keys")
    page.wait("the keys table", lambda: page.find("#key-list tr[data-id]"))
    if not page.find("#new-key-user"):
        expect(False, "the Keys page creates a key")
        return
    page.find("#new-key-user").send_keys("olive")
    page.js("const s = document.getElementById('new-key-role'); s.value = 'operator'; s.dispatchEvent(new Event('change'))")
    page.find("#new-key-label").send_keys("olive's phone")
    page.click("#new-key button[type=submit]")
    page.wait("the new key shown once", lambda: re.fullmatch(r"[A-Za-z0-9_-]{43}", page.text("#made-key")), 10)
    key = page.text("#made-key")
    status, body = call(daemon, "GET", "/api/v1/keys", key=key)
    expect(status == 200 and body["you"]["user"] == "olive" and body["you"]["role"] == "operator",
           f"the key made on the page works, as olive, an operator: {status} {body and body.get('you')}")
    key_id = body["you"]["key"]
    page.wait("olive's key in the table", lambda: page.find(f"#key-list tr[data-id='{key_id}']"), 10)
    page.click(f"#key-list tr[data-id='{key_id}'] button")
    page.confirm()
    page.wait("olive's key gone from the table", lambda: not page.find(f"#key-list tr[data-id='{key_id}']"), 10)
    status, _ = call(daemon, "GET", "/api/v1/keys", key=key)
    expect(status == 401, f"the key revoked on the page is refused: {status}")
    page.screenshot("keys-made")


def main():
    salientd, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    daemon = w.Daemon(salientd, work)
    driver = None
    try:
        driver = w.browser(work)
        page = w.Page(driver, daemon, work)
        sign_in_page(page, daemon.key)
        if not files_and_queue(page, daemon):
            start_print_by_api(page, daemon)
        progress_and_time_left(page)
        page.screenshot("printer-printing")
        on_a_phone(page, daemon)
        keys_create_and_revoke(page, daemon)
        call(daemon, "POST", "/api/v1/printers/sim/cancel", {}, daemon.key)
        errors = page.console_errors()
        expect(not errors, f"no errors in the browser's console: {errors}")
    except w.Failure as e:
        failures.append(str(e))
        print(daemon.log_text()[-3000:])
    finally:
        if driver:
            driver.quit()
        daemon.stop()
    for f in failures:
        w.log("FAIL: " + f)
    w.log(f"{'passed' if not failures else str(len(failures)) + ' failed'}; screenshots in {work}/screenshots")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
