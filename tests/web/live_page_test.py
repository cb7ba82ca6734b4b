"""Drives the live page of `daq serve` in headless Chromium against a SIMULATED run:
starts a linear run with the page's button, checks the live reading, target, run, air,
material and compensation values and the update rate, stops the run with the page's button,
and checks the API's run list. Usage: live_page_test.py URL SCREENSHOT.png"""
import json
import os
import sys
import time
import urllib.request

sys.path.insert(0, os.path.dirname(__file__))
from webdriver import Browser, png_size  # noqa: E402

url, shot = sys.argv[1], sys.argv[2]


def ok(cond, what):
    if not cond:
        raise AssertionError(what)
    print("ok", what)


with Browser(width=1280, height=800) as b:
    b.get(url)
    b.wait("return window.messageCount > 0", what="the first WebSocket message")
    b.js("document.getElementById('start-linear').click();")
    started = b.wait("const t = document.getElementById('api').textContent;"
                     "return /run \\d+ started/.test(t) ? t : null;", what="the run to start")
    run_id = int(started.split()[1])
    ok(run_id >= 1, f"the page started run {run_id}")
    # The program of `daq sim` starts a few seconds later; then a target and a deviation show.
    b.wait("const s = window.lastState; return s && s.target && s.run && "
           "/^\\d+ of \\d+$/.test(document.getElementById('target').textContent);",
           timeout_s=60, what="a target on the page")
    # The air follows with the first sample of the environment (until then the page shows
    # dashes, not zeros).
    b.wait("return document.getElementById('air-t').textContent.endsWith('°C');",
           timeout_s=30, what="the air values")
    text = b.js("""const g = id => document.getElementById(id).textContent;
        return {reading: g('reading'), unit: g('reading-unit'), target: g('target'),
                run: g('run'), air: g('air-t'), p: g('air-p'), rh: g('air-rh'), n: g('air-n'),
                material: g('material'), factor: g('factor')};""")
    print(json.dumps(text, ensure_ascii=False))
    ok(text["reading"].replace("-", "").replace(".", "").replace("+", "").isdigit(),
       f"a live deviation in large digits: {text['reading']} {text['unit']}")
    ok(" of " in text["run"], f"the run: {text['run']}")
    # The simulated shop's air is about 20.6 degC, 1013 hPa, 50 %RH; n - 1 about 2.7e-4.
    air_c = float(text["air"].split()[0])
    ok(15 < air_c < 30, f"air temperature {text['air']}")
    ok(900 < float(text["p"].split()[0]) < 1100, f"pressure {text['p']}")
    ok(abs(float(text["n"]) - 1.00027) < 0.00003, f"refractive index {text['n']}")
    ok(15 < float(text["material"].split()[0]) < 30, f"material {text['material']}")
    ok(text["factor"].endswith("ppm"), f"compensation factor {text['factor']}")
    # Updates: the service pushes the latest state 10 times a second.
    c0 = b.js("return window.messageCount;")
    t0 = time.time()
    time.sleep(3.0)
    c1 = b.js("return window.messageCount;")
    rate = (c1 - c0) / (time.time() - t0)
    ok(rate >= 9.0, f"{rate:.1f} updates per second")
    png = b.screenshot(shot)
    w, h = png_size(png)
    ok(w == 1280 and len(png) > 20000, f"screenshot {w}x{h}, {len(png)} bytes")
    b.js("document.getElementById('stop').click();")
    b.wait("return /stopped/.test(document.getElementById('api').textContent);",
           what="the stop to be acknowledged")
    # A ballbar run from the same page: its state (caldaq.live-circle.v1) shows the phase.
    b.js("document.getElementById('start-circle').click();")
    b.wait("return /run \\d+ started/.test(document.getElementById('api').textContent) && "
           "window.lastState && /feed-in/.test(document.getElementById('message').textContent);",
           timeout_s=30, what="the circle run's phase on the page")
    ok(True, "circle run: " + b.js("return document.getElementById('message').textContent;"))
    b.js("document.getElementById('stop').click();")
    b.wait("return /stopped/.test(document.getElementById('api').textContent);",
           what="the circle stop to be acknowledged")
with urllib.request.urlopen(url.rstrip("/") + "/api/runs", timeout=10) as r:
    runs = json.load(r)["runs"]
mine = [r for r in runs if r["id"] == run_id]
ok(mine and mine[0]["status"] == "aborted" and "web page" in mine[0]["note"],
   f"run {run_id} listed as stopped from the web page: {mine}")
print(f"live page: run {run_id}, {rate:.1f} updates/s")
