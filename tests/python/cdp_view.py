#!/usr/bin/env python3
"""Drives `situ view`'s page in headless Chromium through the DevTools
protocol (CDP, spoken with the `websockets` package from PyPI), as a person
would: real mouse events on the timeline, a page left open on a live run,
in real time (no virtual time).

  cdp_view.py scrub URL [SCREENSHOT.png]
      clicks the timeline's slider at its start, middle and end, then
      presses Home on it; prints one JSON line per position:
      {"at": FRACTION, "time": LABEL, "state": NAME, "modes": {AGENT: MODE}}
  cdp_view.py live URL [SCREENSHOT.png]
      opens the page of a `situ run … --serve` and waits (60 s at most) for
      the run to end; prints one JSON line: {"time", "state", "modes",
      "firing_text", "received", "firings", "lags_ms"} where lags_ms are, per state change, the time from the
      server's stamp to the page having drawn it (the page's own clock, the
      machine's).

Exit 0 when the page was driven to the end; a page error, a timeout or a
missing Chromium is exit 1 with why.
"""
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

from websockets.sync.client import connect


class Page:
    """One Chromium page, driven over CDP."""

    def __init__(self):
        chromium = shutil.which("chromium")
        if not chromium:
            raise SystemExit("FAIL: Debian's `chromium` is missing: run scripts/install-chromium.sh")
        self.profile = tempfile.mkdtemp(prefix="situ-cdp-")
        self.proc = subprocess.Popen(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--window-size=1400,900", "--remote-debugging-port=0",
             f"--user-data-dir={self.profile}", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port = self._port()
        targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10))
        page = next(t for t in targets if t["type"] == "page")
        self.ws = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=10, legacy=True)
        self.next_id = 0

    def _port(self):
        path = os.path.join(self.profile, "DevToolsActivePort")
        deadline = time.time() + 30
        while time.time() < deadline:
            if os.path.exists(path):
                with open(path) as f:
                    first = f.readline().strip()
                if first:
                    return int(first)
            if self.proc.poll() is not None:
                raise SystemExit(f"FAIL: chromium exited ({self.proc.returncode})")
            time.sleep(0.05)
        raise SystemExit("FAIL: chromium did not open its DevTools port in 30 s")

    def call(self, method, **params):
        self.next_id += 1
        mine = self.next_id
        self.ws.send(json.dumps({"id": mine, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == mine:
                if "error" in msg:
                    raise SystemExit(f"FAIL: {method}: {msg['error']}")
                return msg.get("result", {})

    def eval(self, expression):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in r:
            raise SystemExit(f"FAIL: {expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait_for(self, expression, seconds):
        deadline = time.time() + seconds
        while time.time() < deadline:
            if self.eval(expression):
                return
            time.sleep(0.02)
        raise SystemExit(f"FAIL: `{expression}` still false after {seconds} s")

    def open(self, url):
        self.call("Page.navigate", url=url)
        self.wait_for("document.body && document.body.getAttribute('data-ready') === 'true'", 30)

    def errors(self):
        return self.eval("(document.getElementById('page-error') || {}).textContent || ''")

    def mouse(self, kind, x, y, buttons):
        self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                  buttons=buttons, clickCount=1)

    def now(self):
        return json.loads(self.eval("""JSON.stringify({
            time: document.getElementById('time-label').textContent,
            state: document.getElementById('current-state').textContent,
            modes: Object.fromEntries([...document.querySelectorAll('#wiring tr[data-agent]')].map(
                r => [r.getAttribute('data-agent'), r.querySelector('[data-mode]').getAttribute('data-mode')]))
        })"""))

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", format="png")["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        try:
            self.ws.close()
        finally:
            self.proc.kill()
            self.proc.wait()
            shutil.rmtree(self.profile, ignore_errors=True)


def scrub(page, url):
    page.open(url)
    for f in (0.0, 0.5, 1.0):
        # Where the slider is now: a redraw may move it.
        r = json.loads(page.eval("JSON.stringify(document.getElementById('scrub').getBoundingClientRect())"))
        # Inside the slider by a pixel at either end.
        x, y = r["x"] + 1 + f * (r["width"] - 2), r["y"] + r["height"] / 2
        page.mouse("mousePressed", x, y, 1)
        page.mouse("mouseReleased", x, y, 0)
        print(json.dumps({"at": f, **page.now()}))
    # Then the keyboard, on the focused slider: Home goes back to the start.
    # (A mouse drag of a range input is not delivered by headless Chromium.)
    for kind in ("rawKeyDown", "keyUp"):
        page.call("Input.dispatchKeyEvent", type=kind, key="Home", code="Home", windowsVirtualKeyCode=36)
    print(json.dumps({"at": "Home", **page.now()}))


def live(page, url):
    page.open(url)
    page.wait_for("['over', 'gone'].includes(document.body.getAttribute('data-live'))", 60)
    if page.eval("document.body.getAttribute('data-live')") != "over":
        raise SystemExit("FAIL: the page lost the run's server before the end")
    out = page.now()
    print(json.dumps({
        **out,
        "firing_text": page.eval("document.getElementById('firings').textContent"),
        "received": int(page.eval("document.body.getAttribute('data-received')")),
        "firings": page.eval("document.querySelectorAll('#firings li.firing').length"),
        "lags_ms": page.eval("view.lags"),
    }))


def main(mode, url, shot=None):
    page = Page()
    try:
        {"scrub": scrub, "live": live}[mode](page, url)
        errors = page.errors()
        if errors:
            raise SystemExit(f"FAIL: the page reported: {errors}")
        if shot:
            page.screenshot(shot)
    finally:
        page.close()
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) not in (2, 3) or args[0] not in ("scrub", "live"):
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    sys.exit(main(*args))
