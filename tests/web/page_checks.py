"""What the operator-page tests share: a counted check, a screenshot that must not be blank, a
JSON POST that returns (status, body) for errors too, the test's folders, and the service with a
browser on its page."""
import atexit
import contextlib
import decimal
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

from webdriver import Browser, png_size

passes = 0

# Types VALUE into the set-up form's field of KEY (arguments: key, value) as an operator does.
TYPE = """const [key, value] = arguments;
  const input = [...document.querySelectorAll('[data-key]')].find(i => i.dataset.key === key);
  if (!input) return 'no field ' + key;
  input.value = value;
  input.dispatchEvent(new Event('input', {bubbles: true}));
  return 'ok';"""
FIELD = "return [...document.querySelectorAll('[data-key]')].find(i => i.dataset.key === arguments[0]).value;"


def ok(cond, what):
    global passes
    if not cond:
        raise AssertionError(what)
    passes += 1
    print("ok", what, flush=True)


def fixed(v, d, sign=""):
    """V to D decimals by the rule the page and the terminal share (cal::fixed_text): the
    double V x 10^D rounded half away from zero, not V's binary digits as "%.4f" rounds them.
    They differ on a decimal tie: 0.04923945 m is 49.23945 mm, whose double lies just under
    the tie (49.2394499...), so "%.4f" writes 49.2394 where the page writes 49.2395. SIGN "+"
    writes a plus on what is not negative, as the page's signed() does."""
    scaled = v * 10.0 ** d
    if abs(scaled) < 2.0 ** 52:
        whole = decimal.Decimal(scaled).quantize(decimal.Decimal(1), rounding=decimal.ROUND_HALF_UP)
        v = float(whole) / 10.0 ** d
    v = v if v != 0 else 0.0  # "0.00", never "-0.00"
    return f"{v:{sign}.{d}f}"


def shot(b, directory, name):
    png = b.screenshot(os.path.join(directory, name))
    w, h = png_size(png)
    ok(len(png) > 10000, f"screenshot {name} ({w}x{h})")


def fits_narrow(b, directory, name, what):
    """At 560 px wide nothing is wider than the screen (the check WHAT), shown in the screenshot
    NAME; the window is 1366 x 768 again after."""
    b.set_size(560, 900)
    time.sleep(0.5)
    ok(b.js("return document.documentElement.scrollWidth - window.innerWidth;") <= 0, what)
    shot(b, directory, name)
    b.set_size(1366, 768)


# A unit as a terminal writes it ("um", "urad", "um/m") as a word, or a number that rounds to
# zero written with a minus ("-0.00"): neither belongs on a page (daq/web/present.js).
ASCII_UNIT_OR_NEGATIVE_ZERO = re.compile(r"(?<![A-Za-z0-9])(?:um|urad|um/m)(?![A-Za-z0-9])|(?<![0-9.])-0\.0+(?![0-9])")


def ascii_units(text):
    """Where TEXT writes a unit in ASCII or a negative zero: up to 3 excerpts (none: [])."""
    return [text[max(0, m.start() - 30):m.end() + 10] for m in ASCII_UNIT_OR_NEGATIVE_ZERO.finditer(text)][:3]


def post(url, body):
    req = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, json.load(r)
    except urllib.error.HTTPError as e:
        return e.code, json.load(e)


def test_dirs(prefix):
    """The test's arguments (DAQ_BINARY SHOT_DIR, the folder made) and a new temporary folder
    named PREFIX... with the path of a run database in it: (daq, shots, tmp, db)."""
    daq, shots = os.path.abspath(sys.argv[1]), sys.argv[2]
    os.makedirs(shots, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix=prefix)
    _made.append(tmp)
    return daq, shots, tmp, os.path.join(tmp, "runs.sqlite")


_made = []  # the tests' temporary folders: removed after the last check passed, kept otherwise


def _remove_made():
    for d in _made:
        shutil.rmtree(d, ignore_errors=True)


def no_script_error(b):
    """The last check of a page test: the page raised no script error; the count of checks."""
    ok(not b.js("return window.__errors || null;"), "no script error")
    print(f"{passes} checks passed")
    atexit.register(_remove_made)


def get_json(url):
    """The JSON a GET of URL answers (30 s at most)."""
    with urllib.request.urlopen(url, timeout=30) as r:
        return json.load(r)


def waiter(b, tmp, explain, timeout_s):
    """A wait(script, what, timeout_s) on browser B that, on a time-out, says what the page showed
    (the script EXPLAIN) and the end of the service's log in TMP."""
    def wait(script, what, timeout_s=timeout_s):
        try:
            return b.wait(script, timeout_s=timeout_s, what=what, explain=explain)
        except AssertionError as e:
            raise AssertionError(f"{e}\n--- serve.log:\n{log_tail(tmp)}") from None
    return wait


def start_simulated_service(daq, tmp, db):
    """Starts `daq serve --simulate` at 20x on a free port with its log in tmp; returns the
    process and the page's URL once the service prints it (or fails with the log)."""
    return start_service(daq, tmp, simulated(db))


def start_service(daq, tmp, args):
    """Starts `daq serve ARGS` on a free port with its log in tmp/serve.log; returns the process
    and the page's URL once the service prints it (or fails with the log)."""
    log = open(os.path.join(tmp, "serve.log"), "w+")
    proc = subprocess.Popen([daq, "serve", "--port", "0", *args], stdout=log, stderr=subprocess.STDOUT)
    for _ in range(1500):
        log.seek(0)
        m = re.search(r"daq serve: (http://[0-9.]+:[0-9]+/)", log.read())
        if m:
            return proc, m.group(1)
        if proc.poll() is not None:
            break
        time.sleep(0.02)
    log.seek(0)
    raise AssertionError(f"daq serve {' '.join(args)} did not start: " + log.read())


@contextlib.contextmanager
def served_page(daq, tmp, args):
    """`daq serve ARGS` (as start_service) and a 1366x768 headless browser for its page: yields
    (service, url, browser); the browser is closed and the service ended however the test ends."""
    proc, url = start_service(daq, tmp, args)
    try:
        b = Browser(1366, 768)
        try:
            yield proc, url, b
        finally:
            b.close()
    finally:
        stop_service(proc)


def simulated(db):
    """The arguments of `daq serve --simulate` at 20x storing into DB (start_simulated_service)."""
    return ["--simulate", "--speed", "20", "--db", db]


def log_tail(tmp, name="serve.log", lines=30):
    """The last lines of a log the test keeps in tmp (for a failure's message)."""
    try:
        with open(os.path.join(tmp, name), encoding="utf-8", errors="replace") as f:
            return "".join(f.readlines()[-lines:])
    except OSError as e:
        return f"({name}: {e})"


def stop_service(proc):
    """Ends a `daq serve` the test started (continued first, in case a test stopped it)."""
    if proc.poll() is not None:
        return
    proc.send_signal(signal.SIGCONT)
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
