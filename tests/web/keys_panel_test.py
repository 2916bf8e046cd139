"""The web page's Keys panel in headless Chromium: an admin sees an app's key request (OctoPrint's
application keys) appear, approves one (the app's poll then gets a 43-character key) and denies
another (its poll gets 404); a viewer's page says only an admin may decide.
  keys_panel_test.py SALIENTD WORKDIR  (exit 77 without Chromium or Selenium)"""
import json
import os
import re
import shutil
import sys
import urllib.error
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import web_page_test as w  # noqa: E402  (its Daemon, browser, Page and sign-in)


def call(daemon, method, path, body=None, key=None):
    headers = {"Content-Type": "application/json"}
    if key:
        headers["X-Api-Key"] = key
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(daemon.base + path, data=data, headers=headers, method=method)
    try:
        with urllib.request.urlopen(request, timeout=10) as r:
            text = r.read()
            return r.status, json.loads(text) if text else None
    except urllib.error.HTTPError as e:
        return e.code, None


def decide_in_page(page, daemon, app, button):
    status, made = call(daemon, "POST", "/plugin/appkeys/request", {"app": app})
    w.check(status == 201, f"request for {app}: {status}")
    token = made["app_token"]
    page.wait(f"{app} in the panel", lambda: app in page.text("#key-requests"))
    page.click(f"#key-requests li button.{button}")
    page.wait(f"{app} gone from the panel", lambda: app not in page.text("#key-requests"))
    return call(daemon, "GET", "/plugin/appkeys/request/" + token)


def main():
    salientd, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    daemon = w.Daemon(salientd, work)
    driver = None
    try:
        driver = w.browser(work)
        page = w.Page(driver, daemon, work)
        w.sign_in(page, daemon.key)
        driver.get(daemon.base + "/#/keys")
        page.wait("the keys table", lambda: page.find("#key-list tr[data-id]"))
        page.wait("no request yet", lambda: "No app is waiting" in page.text("#key-requests"))
        status, body = decide_in_page(page, daemon, "PanelCura", "approve")
        w.check(status == 200 and re.fullmatch(r"[A-Za-z0-9_-]{43}", body["api_key"]),
                f"approved app's poll: {status} {body}")
        page.wait("the app's key in the table", lambda: "PanelCura" in page.text("#key-list"))
        status, _ = decide_in_page(page, daemon, "PanelPod", "deny")
        w.check(status == 404, f"denied app's poll: {status}")
        page.screenshot("keys")
        # A viewer signs in: the panel says who may decide, and shows only the viewer's keys.
        status, made = call(daemon, "POST", "/api/v1/keys", {"user": "vic", "role": "viewer"}, daemon.key)
        w.check(status == 201, f"viewer key: {status}")
        driver.find_element(w.By.CSS_SELECTOR, "#sign-out").click()
        w.sign_in(page, made["key"])
        driver.get(daemon.base + "/#/keys")
        page.wait("the viewer's note", lambda: "Only an admin" in page.text("#key-requests"))
        rows = driver.find_elements(w.By.CSS_SELECTOR, "#key-list tr[data-id]")
        w.check(len(rows) == 1, f"a viewer sees {len(rows)} keys")
        w.log("passed: approve and deny from the page, a viewer may not decide")
        return 0
    except w.Failure as e:
        w.log(f"FAIL: {e}")
        print(daemon.log_text()[-3000:])
        return 1
    finally:
        if driver:
            driver.quit()
        daemon.stop()


if __name__ == "__main__":
    sys.exit(main())
