"""A minimal W3C WebDriver client (standard library only) for Debian's chromium-driver.

Used by the report rendering test and the operator's page end-to-end test: start
chromedriver, open a headless Chromium session, load pages, run scripts (synchronous and
asynchronous), resize the window, take screenshots.
"""
import base64
import http.client
import json
import os
import shutil
import socket
import subprocess
import time
import urllib.error
import urllib.request


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Browser:
    def __init__(self, width=1200, height=900):
        driver = shutil.which("chromedriver") or "/usr/lib/chromium/chromedriver"
        browser = os.environ.get("CALDAQ_CHROMIUM") or shutil.which("chromium")
        if not os.path.exists(driver) or not browser:
            raise RuntimeError("chromium and chromium-driver are needed (Debian packages)")
        # A free port is only free until someone takes it: between _free_port() and
        # chromedriver's bind, another test's server (a simulated MTConnect agent, seen in a
        # parallel ctest) can get it, and /status then answers in its protocol. So the port is
        # checked to be chromedriver's, and another is tried if it is not.
        for attempt in range(5):
            self.port = _free_port()
            self.proc = subprocess.Popen([driver, f"--port={self.port}"],
                                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            self.base = f"http://127.0.0.1:{self.port}"
            if self._wait_for_driver():
                break
            self.proc.kill()
            self.proc.wait()
        else:
            raise RuntimeError("chromedriver did not start on any of 5 ports")
        args = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                f"--window-size={width},{height}"]
        caps = {"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": browser, "args": args}}}}
        self.session = self._call("POST", "/session", caps)["sessionId"]

    def _wait_for_driver(self):
        """True once chromedriver answers /status on self.port; False if something else holds
        the port or chromedriver exited; raises after 20 s without an answer."""
        deadline = time.time() + 20
        while True:
            if self.proc.poll() is not None:
                return False  # it could not bind: the port was taken
            try:
                status = self._call("GET", "/status")
                return isinstance(status, dict) and "ready" in status
            except (http.client.HTTPException, ValueError, RuntimeError):
                return False  # an answer, but not chromedriver's
            except (urllib.error.URLError, ConnectionError):
                if time.time() > deadline:
                    raise RuntimeError("chromedriver did not start")
                time.sleep(0.1)

    def _call(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.base + path, data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(req, timeout=60) as r:
                return json.loads(r.read() or b"{}").get("value")
        except urllib.error.HTTPError as e:
            raise RuntimeError(f"webdriver {method} {path}: {e.read().decode()[:500]}") from None

    def get(self, url):
        self._call("POST", f"/session/{self.session}/url", {"url": url})

    def js(self, script, *args):
        return self._call("POST", f"/session/{self.session}/execute/sync",
                          {"script": script, "args": list(args)})

    def js_async(self, script, *args):
        """Runs `script` with a callback as its last argument (arguments[arguments.length-1])
        and returns what the script passes to it (e.g. the text of a fetched blob URL)."""
        return self._call("POST", f"/session/{self.session}/execute/async",
                          {"script": script, "args": list(args)})

    def press(self, key):
        """Presses and releases one key on the focused element, as a keyboard (or a foot switch
        that sends a key) does."""
        self._call("POST", f"/session/{self.session}/actions", {"actions": [{
            "type": "key", "id": "keyboard",
            "actions": [{"type": "keyDown", "value": key}, {"type": "keyUp", "value": key}]}]})

    def set_size(self, width, height):
        self._call("POST", f"/session/{self.session}/window/rect",
                   {"width": width, "height": height})

    def screenshot(self, path):
        png = base64.b64decode(self._call("GET", f"/session/{self.session}/screenshot"))
        with open(path, "wb") as f:
            f.write(png)
        return png

    def wait(self, script, timeout_s=45, what="condition", explain=None):
        """Polls `script` until it returns a true value; on time-out, `explain` (a script)
        says what the page showed instead."""
        deadline = time.time() + timeout_s
        while time.time() < deadline:
            value = self.js(script)
            if value:
                return value
            time.sleep(0.02)  # a script round trip takes about 5 ms: poll often, cheaply
        detail = f": {self.js(explain)}" if explain else ""
        raise AssertionError(f"timed out after {timeout_s} s waiting for {what}{detail}")

    def close(self):
        try:
            self._call("DELETE", f"/session/{self.session}")
        except Exception:
            pass
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def png_size(png):
    """Width and height from a PNG's IHDR chunk."""
    assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
