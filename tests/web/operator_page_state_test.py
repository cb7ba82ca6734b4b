#!/usr/bin/env python3
"""The operator's page never shows a value that is not current as if it were (issue 29),
driven in headless Chromium against `daq serve --simulate` at 1366 x 768 (and 560 px):

1. at CAPTURED the big number is the captured stop's value with its target, and the line
   below names the next target; while the axis moves the big position is the laser's raw
   reading on its card (of the same moment), compensated;
2. a hung service (SIGSTOP: the connection stays open, nothing arrives): within 3 s every live
   value is dashes and a blocking banner gives the time of the last data; values return after
   SIGCONT;
3. a stopped run shows ABORTED with its reason, a finished run COMPLETE with its count, never a
   live-looking number or a lit indicator;
4. the service killed mid-run (kill -9): dashes and the banner within 3 s.

Measured (printed, not asserted): page updates per second and bytes per update during a linear
run. Usage: operator_page_state_test.py DAQ_BINARY ARTEFACT_DIR
"""
import json
import os
import re
import shutil
import signal
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok, post  # noqa: E402
from webdriver import Browser  # noqa: E402

DAQ, SHOTS = sys.argv[1], sys.argv[2]
os.makedirs(SHOTS, exist_ok=True)
TMP = tempfile.mkdtemp(prefix="operator-page-state-")


def shot(b, name):
    page_checks.shot(b, SHOTS, name)


def settle_machine(url):
    """The simulated machine finishes a stopped run's program (as a machine left in Cycle Start
    would) before the next run."""
    post(url + "api/simulation/speed", {"speed": 100})
    time.sleep(2.0)
    post(url + "api/simulation/speed", {"speed": 20})


# What the operator sees of the live state.
SEEN = """const g = id => document.getElementById(id);
  return {big: g('reading').textContent, unit: g('reading-unit').textContent,
          label: g('reading-label').textContent, progress: g('progress').textContent,
          line: g('run-line').textContent, banner: !g('stale').hidden,
          origin: g('run-origin').hidden ? '' : g('run-origin').textContent,
          since: g('stale-since').textContent,
          lit: [...document.querySelectorAll('#indicator span.on')].map(e => e.dataset.motion),
          env: ['env-air', 'env-p', 'env-rh', 'env-n', 'env-material', 'env-factor'].map(i => g(i).textContent),
          badges: [...document.querySelectorAll('#devices .badge')].map(e => e.textContent),
          values: [...document.querySelectorAll('#devices .dev-values')].map(e => e.textContent),
          start: g('start-linear').disabled, stop: g('stop').disabled,
          run: window.caldaq.page && window.caldaq.page.run, status: window.caldaq.page && window.caldaq.page.status};"""
DASH = "—"
# Sets a form field as typing would; the value of a form field.
from page_checks import TYPE, FIELD  # noqa: E402


def no_live_values(s, where):
    ok(s["banner"] and re.search(r"Last data at \d\d:\d\d:\d\d \(\d+ s ago\)", s["since"]),
       f"{where}: the blocking banner with the time of the last data: {s['since']!r}")
    ok(s["big"] == DASH and s["unit"] == "" and s["lit"] == [],
       f"{where}: the big number is dashes, no motion lit ({s['big']!r}, {s['lit']})")
    ok(all(v == DASH for v in s["env"]), f"{where}: every environment value is dashes: {s['env']}")
    ok(s["badges"] and all(x == "no data" for x in s["badges"]) and all(v == DASH for v in s["values"]),
       f"{where}: no instrument looks streaming: {s['badges']} {s['values']}")
    ok(s["progress"] == "" and s["line"] == "", f"{where}: no stop or target shown as current")
    ok(s["start"] and s["stop"], f"{where}: Start and Stop wait for data")


def wait_stale(b, where):
    t0 = time.time()
    b.wait("return !document.getElementById('stale').hidden;", timeout_s=10,
           what=f"{where}: the stale banner")
    took = time.time() - t0
    ok(took <= 3.0, f"{where}: dashes and banner after {took:.2f} s (at most 3 s)")
    return took


serve, url = page_checks.start_simulated_service(DAQ, TMP, os.path.join(TMP, "runs.sqlite"))
b = Browser(1366, 768)
try:
    # A short test (12 stops) so that a whole run completes in a few seconds.
    with urllib.request.urlopen(url + "api/setup", timeout=30) as r:
        setup = json.load(r)["setup"]
    setup["test"]["linear"].update(first_mm=0, last_mm=100, interval_mm=50, runs=2, dwell_s=4)
    setup["test"]["linear"].pop("count", None)
    status, body = post(url + "api/setup/apply", {"setup": setup})
    ok(status == 200, f"a short linear test applied: {status} {body.get('error', '')}")
    b.get(url)
    b.wait("return window.caldaq.page && window.caldaq.page.status && window.caldaq.page.status.start.linear.ready;",
           timeout_s=30, what="Start linear ready")
    ok(b.js("return document.getElementById('stale').hidden;"), "live data: no banner")

    # --- 1. CAPTURED: the captured stop's value with its target, then the next target -------
    post(url + "api/simulation/speed", {"speed": 5})  # CAPTURED lasts long enough to be seen
    b.js("document.getElementById('start-linear').click();")
    b.wait("return window.caldaq.page.status.running;", what="the run to start")
    c0, bytes0, t0 = b.js("return [window.caldaq.messages, window.caldaq.bytesTotal || 0];") + [time.time()]
    captured = None
    deadline = time.time() + 60
    while time.time() < deadline and captured is None:
        s = b.js(SEEN)
        run = s["run"] or {}
        if (run.get("motion") or {}).get("state") == "captured" and s["lit"] == ["captured"]:
            captured = s
        time.sleep(0.02)
    ok(captured is not None, "a stop seen at CAPTURED")
    stops = [x for x in captured["run"]["stops"] if not x["missed"]]
    last = stops[-1]
    ok(captured["big"] == page_checks.fixed(last['deviation_um'], 2) and captured["unit"] == "µm",
       f"at CAPTURED the number is the captured stop's value: {captured['big']} µm = stop "
       f"{last['number']}'s {last['deviation_um']:.4f}")
    ok(captured["label"] == f"Captured at {last['nominal_mm']:.3f} mm (stop {last['number']})",
       f"with its target: {captured['label']!r}")
    target = captured["run"].get("target")
    ok(target and captured["line"].startswith("Next: ") and f"({target['nominal_mm']:.3f} mm)" in captured["line"],
       f"then the next target: {captured['progress']!r} / {captured['line']!r}")
    shot(b, "s01-captured-1366x768.png")
    post(url + "api/simulation/speed", {"speed": 2})  # the run lasts past the hang, to be stopped
    page_checks.fits_narrow(b, SHOTS, "s02-run-560px.png", "560 px: nothing wider than the screen")
    time.sleep(1.0)
    c1, bytes1 = b.js("return [window.caldaq.messages, window.caldaq.bytesTotal || 0];")
    t1 = time.time()
    print(f"measured: {(c1 - c0) / (t1 - t0):.1f} page updates/s during a linear run, "
          f"{(bytes1 - bytes0) / max(1, c1 - c0):.0f} bytes per update", flush=True)

    # --- 1b. the big position and the laser's raw reading on its card: of the same moment ------
    # While the axis moves (the number a position, not a deviation), recorded in the page every
    # 10 ms: the position is the card's raw reading compensated, raw x (1 + the compensation in
    # ppm), the datum 0 (the laser zeroed at X = 0). The run's state was up to 100 ms older than
    # the card's reading: at 6000 mm/min and 2x, "Position 21.175" beside "raw 31.1810 mm".
    b.js("""window.__pairs = []; window.__pairTimer = setInterval(() => {
        const g = id => document.getElementById(id), card = document.querySelector('#devices li[data-device="laser"] .dev-values');
        const raw = card && /raw (-?[0-9.]+) mm/.exec(card.textContent), f = /^(-?[0-9.]+) ppm$/.exec(g('env-factor').textContent);
        if (g('reading-label').textContent.startsWith('Position') && raw && f)
          window.__pairs.push([Number(g('reading').textContent), Number(raw[1]), Number(f[1])]); }, 10);""")
    b.wait("return new Set(window.__pairs.map(p => p[0])).size >= 4;", timeout_s=20,
           what="the axis moving between targets", explain="return JSON.stringify(window.__pairs.slice(-5));")
    pairs = b.js("clearInterval(window.__pairTimer); return window.__pairs;")
    off = max(abs(pos - raw * (1 + ppm * 1e-6)) for pos, raw, ppm in pairs)
    moving = sorted({pos for pos, _, _ in pairs})
    ok(off <= 0.0015, f"while moving the position shown is the laser's raw reading shown beside it, compensated: "
                      f"at most {off * 1e3:.2f} µm apart over {len(pairs)} samples at {moving} mm")

    # --- 2. a hung service: the connection stays, nothing arrives ------------------------------
    serve.send_signal(signal.SIGSTOP)
    wait_stale(b, "hung service (SIGSTOP)")
    time.sleep(0.3)
    no_live_values(b.js(SEEN), "hung service")
    shot(b, "s03-hung-1366x768.png")
    serve.send_signal(signal.SIGCONT)
    b.wait("return document.getElementById('stale').hidden && "
           "document.getElementById('reading').textContent !== '—';", timeout_s=5,
           what="live values back after SIGCONT")
    ok(True, "the service answers again: the banner goes, values return")

    # --- 3. a stopped run and a finished run: their end, never a live-looking number ---------
    ok(b.js("return window.caldaq.page.status.running;"), "the run goes on after the hang")
    post(url + "api/simulation/speed", {"speed": 20})
    b.js("document.getElementById('stop').click();")
    b.js("document.getElementById('confirm-yes').click();")
    b.wait("const l = window.caldaq.page.status.last; return l && l.status === 'aborted';",
           what="the stop")
    b.js("document.getElementById('tab-run').click();")
    time.sleep(0.5)
    s = b.js(SEEN)
    run_id = s["status"]["last"]["run"]
    ok(s["big"] == "ABORTED" and s["label"] == f"Run {run_id} ended" and s["unit"] == "",
       f"a stopped run: its end where the number was ({s['label']}: {s['big']})")
    ok("stopped from the web page" in s["line"] and s["lit"] == [],
       f"with the reason, nothing lit: {s['line']!r} {s['lit']}")
    ok(re.fullmatch(r"\d+ of \d+ stops captured", s["progress"]), f"what it captured: {s['progress']!r}")
    ok(not re.search(r"\d", s["big"]) and "Deviation" not in s["label"] and "Stop" not in s["progress"],
       "no number, target or stop shown as current")
    ok(b.js("return document.getElementById('conn').textContent;") == "live",
       "the connection shown live again after the hang")
    shot(b, "s04-aborted-1366x768.png")
    settle_machine(url)

    b.wait("return window.caldaq.page.status.start.linear.ready;", timeout_s=30, what="ready again")
    # At 5x, not 20x: a stop's window then holds enough readings that the stops' check below is
    # about the shop's repeatability, not about how few samples a starved 20x run catches (at 20x
    # a stop was once flagged suspect at 0.071 um against a limit of 0.066 um).
    post(url + "api/simulation/speed", {"speed": 5})
    b.js("document.getElementById('start-linear').click();")
    b.wait("const l = window.caldaq.page.status.last; return l && l.run > arguments[0];".replace(
        "arguments[0]", str(run_id)), timeout_s=120, what="the second run to end")
    b.js("document.getElementById('tab-run').click();")
    time.sleep(0.5)
    s = b.js(SEEN)
    last = s["status"]["last"]
    ok(last["status"] == "complete" and s["big"] == "COMPLETE" and s["lit"] == [],
       f"a finished run: COMPLETE ({s['label']}: {s['big']}, {s['progress']}, {s['line']})")
    m = re.fullmatch(r"(\d+) of (\d+) stops captured", s["progress"])
    ok(m and m.group(1) == m.group(2), f"all its stops: {s['progress']!r}")
    ok(s["origin"].startswith(f"SIMULATED Run {last['run']}, as stored: ") and "daq serve --simulate" in s["origin"],
       f"the Run view says the run's instruments were simulated, as stored: {s['origin']!r}")
    shot(b, "s05-complete-1366x768.png")

    # Its results: SIMULATED before anything else, the stops' check, the origin in the list.
    b.js("document.getElementById('tab-results').click();")
    b.wait("return document.getElementById('result-quality').textContent !== '' && "
           "document.querySelectorAll('#runs tbody tr').length >= 2;", what="the results")
    res = b.js("""const g = id => document.getElementById(id);
        return {origin: g('result-origin').hidden ? null : g('result-origin').textContent,
                quality: g('result-quality').textContent,
                runs: [...document.querySelectorAll('#runs tbody tr')].map(r => r.cells[5].textContent)};""")
    ok(res["origin"] and res["origin"].startswith("SIMULATED"), f"the results say SIMULATED: {res['origin']!r}")
    # The state said once ("Stops checked: ok: every stop ..." said it twice).
    ok(res["quality"].startswith("Stops checked: every stop within"), f"and the stops' check: {res['quality']!r}")
    ok(res["runs"] and all(x == "SIMULATED" for x in res["runs"]), f"every stored run's origin listed: {res['runs']}")
    time.sleep(1.0)  # the results view opened by the run's end has rendered too
    # A suspect run (the simulated shop repeats to 0.001 um: none of its runs is suspect), on a
    # hand-made document through the page's own rendering: each suspect stop named by its target.
    suspect = b.js("""showQuality({id: 7, quality: {state: 'suspect', summary: 'suspect: 1 stop',
            suspect_stops: [{run: 2, direction: 'up', target_index: 1,
                             reason: 'run 2 up at 50 mm: +1.200 µm from the median of its target\\'s runs (limit 0.3)'}]}});
        return document.getElementById('result-quality').textContent;""")
    ok("SUSPECT STOPS: 1" in suspect and "target 2: run 2 up at 50 mm" in suspect
       and "refuse run 7 while it has suspect stops: measure the test again" in suspect and "--accept" not in suspect,
       f"a suspect run names its stops: {suspect!r}")
    # Its summary without its state again ("SUSPECT STOPS: 1suspect: 1 stop" said it twice).
    ok("suspect: 1 stop" not in suspect and "1 stop" in suspect, f"the state said once: {suspect!r}")
    shot(b, "s05b-suspect-results-1366x768.png")
    b.js("document.getElementById('tab-run').click();")

    # --- 4. Start runs what the operator sees: an unapplied edit is named, Start asks ---------
    b.js("document.getElementById('tab-setup').click();")
    b.wait("return !!document.querySelector('[data-key=\"test.linear.last_mm\"]') && "
           "document.getElementById('setup-status').className === 'ok';", what="the set-up form")
    # The test conditions the report states, in the form (checked by the loader, in the TOML).
    ok(b.js(TYPE, "conditions.warm_up", "20 min at 50 % rapid") == "ok", "typed: the warm-up")
    ok(b.js(TYPE, "conditions.controller_compensation", "off") == "ok", "chosen: controller compensation off")
    toml = b.wait("return document.getElementById('setup-status').className === 'ok' && "
                  "/controller_compensation = false/.test(window.caldaq.toml || '') && window.caldaq.toml;",
                  what="the conditions in the TOML")
    ok('warm_up = "20 min at 50 % rapid"' in toml, "the warm-up in the TOML the loader read")
    labels = b.js("return ['conditions.warm_up', 'conditions.controller_compensation'].map(k => "
                  "document.querySelector(`[data-field='${k}'] label`).textContent);")
    ok(labels == ["Warm-up (what and how long)", "Controller compensation"], f"labelled in words: {labels}")
    b.js(TYPE, "conditions.warm_up", "")
    b.js(TYPE, "conditions.controller_compensation", "")
    ok(b.js(TYPE, "test.linear.last_mm", "50") == "ok", "typed: last target 50 mm (not applied)")
    b.js("document.getElementById('tab-run').click();")
    b.wait("const t = document.getElementById('pending-edits'); return !t.hidden && "
           "/Last target/.test(t.textContent) && !/Warm-up/.test(t.textContent);",
           what="the edit named (the conditions typed back to empty are no edit)")
    seen = b.js("return [document.getElementById('plan').textContent, "
                "document.getElementById('pending-edits').textContent];")
    ok("Positioning test E_XX, axis X: 0.000 → 100.000 mm, 3 targets × 2 runs ↑↓ = 12 stops" in seen[0]
       and "instruments: air (air station), laser, material (thermometer)" in seen[0],  # roles, not drivers ("gauge")
       f"the Run view shows the test Start runs: {seen[0]!r}")
    ok("Last target 100 → 50" in seen[1], f"and the edit that is not in use: {seen[1]!r}")
    shot(b, "s06-unapplied-edit-1366x768.png")
    b.js("document.getElementById('start-linear').click();")
    ok(b.js("return document.getElementById('confirm-edits').open;"), "Start asks first")
    ok("Last target 100 → 50" in b.js("return document.getElementById('confirm-edits-list').textContent;"),
       "naming the edit")
    shot(b, "s07-start-asks-1366x768.png")
    b.js("document.getElementById('edits-cancel').click();")
    time.sleep(0.5)
    ok(not b.js("return window.caldaq.page.status.running;"), "Cancel starts nothing")
    # Discard: the form is the service's set-up again, and Start runs it (12 stops).
    b.js("document.getElementById('start-linear').click();")
    b.js("document.getElementById('edits-discard').click();")
    b.wait("return window.caldaq.page.status.running && window.caldaq.page.run && "
           "window.caldaq.page.run.stop;", what="the run with the discarded edit")
    ok(b.js("return window.caldaq.page.run.stop.count;") == 12, "discarded: the run has the 12 stops in use")
    ok(b.js(FIELD, "test.linear.last_mm") == "100" and b.js("return document.getElementById('pending-edits').hidden;"),
       "the form shows the set-up in use again, no edit pending")
    status, _ = post(url + "api/runs/stop", {})
    ok(status == 200, "that run stopped")
    settle_machine(url)
    # Apply: Start runs the edited test (2 targets: 8 stops).
    b.js("document.getElementById('tab-setup').click();")
    ok(b.js(TYPE, "test.linear.last_mm", "50") == "ok", "typed again: last target 50 mm")
    b.js("document.getElementById('tab-run').click();")
    b.wait("return window.caldaq.page.status.start.linear.ready && "
           "!document.getElementById('pending-edits').hidden;", timeout_s=30, what="ready, the edit named")
    # At 2x the run's stops stand for seconds: the checks before the kill below read a live value
    # at a stop, not the run's end (at 20x it had ended between two reads).
    post(url + "api/simulation/speed", {"speed": 2})
    b.js("document.getElementById('start-linear').click();")
    b.js("document.getElementById('edits-apply').click();")
    b.wait("return window.caldaq.page.status.running && window.caldaq.page.run && "
           "window.caldaq.page.run.stop;", timeout_s=45, what="the run with the applied edit")
    ok(b.js("return window.caldaq.page.run.stop.count;") == 8, "applied: the run has the edited 8 stops")
    ok(b.js("return window.caldaq.page.status.setup.linear.last_mm;") == 50, "the service's set-up is the edited one")

    # --- 5. the service killed mid-run -------------------------------------------------------
    b.wait("const r = window.caldaq.page.run; return window.caldaq.page.status.running && r && "
           "r.motion && r.motion.state === 'stable';", timeout_s=60, what="the axis still at a stop")
    before = b.js(SEEN)
    ok(re.fullmatch(r"-?\d+\.\d\d", before["big"]), f"a live value before the kill: {before['big']}")
    serve.send_signal(signal.SIGKILL)
    serve.wait()
    wait_stale(b, "killed service (kill -9)")
    time.sleep(0.3)
    s = b.js(SEEN)
    no_live_values(s, "killed service")
    shot(b, "s08-killed-1366x768.png")
    b.set_size(560, 900)
    time.sleep(0.4)
    shot(b, "s09-killed-560px.png")
    time.sleep(1.5)
    s2 = b.js(SEEN)
    ok(s2["banner"] and s2["big"] == DASH, f"still dashes later: {s2['since']!r}")
    ok(b.js("return JSON.stringify(window.__errors);") == "[]", "no script error on the page")
    print(f"operator page state: {page_checks.passes} checks passed; screenshots in {SHOTS}")
finally:
    b.close()
    page_checks.stop_service(serve)
    shutil.rmtree(TMP, ignore_errors=True)
