#!/usr/bin/env python3
"""The operator's control of a linear run from the page (issue 29), driven in headless Chromium
against `daq serve --simulate` with the keys an operator (or a foot switch) presses:

1. P pauses: PAUSED shown, the pause key now resumes, a stop the axis stands still at is not
   captured automatically;
2. C captures the stop by hand (paused or not): the page confirms it with the stop and value,
   the stops table says "by hand";
3. P resumes, S skips the next target (the table says "skipped", the machine's stop there is
   not taken), R measures the last captured stop again (its value discarded, captured anew);
4. the API answers 409 (with the reason) when an action does not apply, 400 for a bad body;
5. the stored run lists every action in order, with its stop, source and operator
   (/api/runs/N and `daq show N`), and the skipped stop among the missed ones; the run ends by
   itself with that stop missed, and the page says INCOMPLETE as the store does;
6. Start (idle), Stop and the manual keys (running) on the 1366 x 768 screen without scrolling.

Usage: operator_page_control_test.py DAQ_BINARY ARTEFACT_DIR
"""
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
import urllib.request

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok, post  # noqa: E402
from webdriver import Browser  # noqa: E402

DAQ, SHOTS = sys.argv[1], sys.argv[2]
os.makedirs(SHOTS, exist_ok=True)
TMP = tempfile.mkdtemp(prefix="operator-page-control-")
DB = os.path.join(TMP, "runs.sqlite")


def get(url):
    with urllib.request.urlopen(url, timeout=30) as r:
        return json.load(r)


RUN = "return window.caldaq.page && window.caldaq.page.run;"
EXPLAIN = ("const r = window.caldaq.page.run || {}; return JSON.stringify({motion: r.motion, "
           "display: r.display, captured: r.captured, stop: r.stop, message: r.message, "
           "paused: r.paused, control: window.caldaq.lastControl});")


def control(b, key, action):
    """Presses `key`; returns the page's answer to it (what it confirmed on screen)."""
    before = b.js("return window.caldaq.lastControl ? window.caldaq.lastControl.n : 0;")
    b.press(key)
    c = b.wait("const c = window.caldaq.lastControl; return c && c.n > %d && c;" % before,
               timeout_s=20, what=f"the page's answer to {key!r}", explain=EXPLAIN)
    ok(c["action"] == action and c["text"] == b.js("return document.getElementById('control-result').textContent;"),
       f"{key!r}: {action}, answered on screen")
    return c


serve, url = page_checks.start_simulated_service(DAQ, TMP, DB)
b = Browser(1366, 768)
try:
    setup = get(url + "api/setup")["setup"]
    # 3 targets x 2 runs both ways = 12 stops; the machine stands 10 s at each (2.5 s of wall
    # time at speed 4, 5 s at speed 2): time to see a stop, act on it and see the answer.
    setup["test"]["linear"].update(first_mm=0, last_mm=100, interval_mm=50, runs=2, dwell_s=10)
    setup["test"]["linear"].pop("count", None)
    setup["operator"] = "A. Operator"
    status, body = post(url + "api/setup/apply", {"setup": setup})
    ok(status == 200, f"a short linear test applied: {status} {body.get('error', '')}")

    # --- 4. the API before a run: 409 with the reason, 400 for a bad body --------------------
    status, body = post(url + "api/runs/capture", {})
    ok(status == 409 and body["error"] == "no run is running", f"capture with no run: {status} {body}")
    status, body = post(url + "api/runs/skip", [1])
    ok(status == 400 and "must be empty or {}" in body["error"], f"a bad body: {status} {body}")

    b.get(url)
    b.wait("return window.caldaq.page && window.caldaq.page.status && window.caldaq.page.status.start.linear.ready;",
           timeout_s=30, what="Start linear ready")
    ok(b.js("return document.getElementById('manual').hidden;"), "no run: no manual control shown")

    # --- 0. alignment while idle: the laser's reading live in big digits, dashes when stale -----
    b.js("document.getElementById('tab-align').click();")
    shown, data = b.wait("const t = document.getElementById('align-reading').textContent; "
                         "const a = laserAxes(device('laser')); "
                         "return /^-?\\d+\\.\\d{4}$/.test(t) && a.length && "
                         # the value to 4 places, a negative zero shown as 0 (never "-0.0000")
                         "[t, a[0].mm.toFixed(4).replace(/^-(0\\.0+)$/, '$1')];",
                         timeout_s=20, what="the laser's reading on the Align view")
    ok(shown == data, f"Align: the laser's current reading in mm: {shown} (its value {data})")
    align = b.js("const g = id => document.getElementById(id); return {label: g('align-label').textContent, "
                 "signal: g('align-signal').textContent, note: g('align-note').textContent, "
                 "size: parseFloat(getComputedStyle(g('align-big')).fontSize), unit: g('align-unit').textContent};")
    ok(align["label"] == "laser (IDS3010), axis 1: raw reading, not compensated" and align["unit"] == "mm", f"which laser and axis: {align['label']!r}")
    ok(align["signal"] == "Beam: streaming · valid readings 100 %", f"its beam: {align['signal']!r}")
    ok("reports no signal strength" in align["note"], f"and that it gives no signal strength: {align['note']!r}")
    ok(align["size"] >= 100, f"in digits readable from 2 m: {align['size']:.0f} px")
    m0 = b.js("return window.caldaq.messages;")
    b.wait("return window.caldaq.messages > %d + 5;" % m0, what="live updates on the Align view")
    page_checks.shot(b, SHOTS, "c00-align-1366x768.png")
    serve.send_signal(signal.SIGSTOP)
    t0 = time.time()
    b.wait("return document.getElementById('align-reading').textContent === '—' && "
           "!document.getElementById('stale').hidden;", timeout_s=10, what="dashes on the Align view")
    took = time.time() - t0
    ok(took <= 3.0 and b.js("return document.getElementById('align-signal').textContent;").startswith("Beam: no data"),
       f"a hung service: the Align view shows dashes and no data within 3 s ({took:.2f} s)")
    # The smallest and largest reading since Reset and their span, at rounding boundaries, on the
    # page's own rendering of hand-made laser readings (the service still stopped: no message
    # comes between them). 10.00004 and 20.00016 mm are written 10.0000 and 20.0002; their span
    # 10.00012 alone would be written 10.0001, one digit from what the two values read. The page
    # writes the span as the difference of the values it writes (docs/web.md, "Align"), also
    # when both round the other way (10.0001 ... 20.0001: span 10.0000, not 10.0001).
    span_js = """const [lo, hi] = arguments; const page = structuredClone(window.caldaq.page);
        const laser = page.devices.devices.find(d => d.role === 'laser');
        laser.values = {displacement_m: lo}; show(page);
        document.getElementById('align-reset').click();  // from the reading now: lo
        laser.values = {displacement_m: hi}; show(page);
        return document.getElementById('align-span').textContent;"""
    for lo_m, hi_m in ((0.01000004, 0.02000016), (0.01000006, 0.02000014)):
        lo_mm, hi_mm = lo_m * 1e3, hi_m * 1e3  # as the page scales them (a double's product)
        lo, hi = page_checks.fixed(lo_mm, 4), page_checks.fixed(hi_mm, 4)
        span = f"{decimal.Decimal(hi) - decimal.Decimal(lo):.4f}"
        ok(span != page_checks.fixed(hi_mm - lo_mm, 4), f"a boundary: {lo} ... {hi} is {span}, the span rounded alone not")
        shown = b.js(span_js, lo_m, hi_m)
        ok(shown == f"Since Reset: {lo} … {hi} mm (span {span} mm)", f"Align: the span is what the two values read: {shown!r}")
    b.js(span_js, 0.01000004, 0.02000016)
    page_checks.shot(b, SHOTS, "c00c-align-span-1366x768.png")
    b.set_size(560, 900)
    b.js(span_js, 0.01000004, 0.02000016)
    page_checks.shot(b, SHOTS, "c00d-align-span-560px.png")
    b.set_size(1366, 768)
    serve.send_signal(signal.SIGCONT)
    b.wait("return /\\d/.test(document.getElementById('align-reading').textContent);", timeout_s=30,
           what="the reading back after SIGCONT")
    page_checks.fits_narrow(b, SHOTS, "c00b-align-560px.png", "560 px: the Align view fits")

    # --- words an operator uses: the instruments' fields labelled from their option tables ------
    b.js("document.getElementById('tab-setup').click();")
    b.wait("return !!document.querySelector('[data-field=\"devices.laser.poll_s\"]');", timeout_s=20,
           what="the instrument cards")
    words = b.js("""const f = k => document.querySelector(`[data-field="${k}"]`);
        const role = document.querySelector('[data-key="devices.material.role"]');
        return {poll: f('devices.laser.poll_s').querySelector('label').textContent,
                unit: f('devices.laser.poll_s').querySelector('.u').textContent,
                help: f('devices.laser.poll_s').title,
                role: role.options[role.selectedIndex].textContent, value: role.value,
                roles: [...role.options].map(o => o.textContent)};""")
    ok(words["poll"] == "Poll interval" and words["unit"] == "s" and words["help"].startswith("poll_s: poll period"),
       f"an option labelled in words with its unit, its key and help on pointing: {words['poll']!r} ({words['unit']}), {words['help']!r}")
    ok(words["role"] == "thermometer (material)" and words["value"] == "material" and
       "air station (air)" in words["roles"], f"roles as names, their keys kept: {words['roles']}")
    ok(b.js("return document.getElementById('setup-status').className;") == "ok", "the set-up still checks ok")
    b.js("document.querySelector('[data-key=\"devices.material.role\"]').scrollIntoView();")
    page_checks.shot(b, SHOTS, "c00c-setup-labels-1366x768.png")
    b.js("window.scrollTo(0, 0);")
    b.js("document.getElementById('tab-run').click();")

    # On the screen of 1366 x 768 (less the browser's bar) without scrolling: Start (it was under
    # the instruments' column's height), and during the run Stop and the manual keys (under the
    # big number and the run's lines).
    IN_VIEW = ("return arguments[0].map(id => { const r = document.getElementById(id).getBoundingClientRect();"
               " return r.height > 0 && r.top >= 0 && r.bottom <= window.innerHeight; });")
    ok(b.js(IN_VIEW, ["start-linear", "start-circle"]) == [True, True], "idle: Start on screen without scrolling")
    post(url + "api/simulation/speed", {"speed": 2})
    b.js("document.getElementById('start-linear').click();")
    b.wait("const r = window.caldaq.page.run; return window.caldaq.page.status.running && r && r.stop;",
           timeout_s=30, what="the run to start")
    run_id = b.js("return window.caldaq.page.status.run.id;")
    labels = b.js("return [...document.querySelectorAll('#manual button')].map(b => b.textContent);")
    ok(labels == ["Capture (C)", "Skip target (S)", "Measure again (R)", "Pause (P)"],
       f"a linear run: the controls with their keys: {labels}")
    b.wait("return window.caldaq.page.run.display && document.getElementById('reading').textContent !== '—';", what="the number")
    ok(b.js(IN_VIEW, ["stop", "ctl-capture", "ctl-skip", "ctl-retry", "ctl-pause"]) == [True] * 5,
       "running: Stop and the manual keys on screen without scrolling")

    # --- 1. pause: no automatic capture at a stop ----------------------------------------------
    c = control(b, "p", "pause")
    ok(c["ok"] and c["text"].startswith("Done: paused"), f"P pauses, confirmed: {c['text']!r}")
    b.wait("return window.caldaq.page.run.paused && !document.getElementById('paused').hidden;",
           what="PAUSED shown")
    ok(b.js("return document.getElementById('ctl-pause').textContent;") == "Resume (P)",
       "the pause key now resumes")
    captured0 = b.js("return window.caldaq.page.run.captured;")
    b.wait("const r = window.caldaq.page.run; return r.display && r.display.mode === 'deviation' && "
           "r.motion.state === 'stable';", timeout_s=60, what="the axis still at a stop",
           explain=EXPLAIN)
    time.sleep(1.0)  # the trigger's dwell (1.5 s simulated) has passed: paused, it takes nothing
    run = b.js(RUN)
    ok(run["captured"] == captured0 and run["motion"]["state"] != "captured",
       f"paused at a still stop: nothing captured ({run['captured']} of {captured0})")
    page_checks.shot(b, SHOTS, "c01-paused-1366x768.png")

    # --- 2. capture by hand -------------------------------------------------------------------
    c = control(b, "c", "capture")
    ok(c["ok"] and re.match(r"Done: captured by hand: target \d \(\d+\.000 mm\) run \d (up|down): [+-]?\d+\.\d{3} µm$",
                            c["text"]), f"C captures the stop, confirmed with its value: {c['text']!r}")
    run = b.wait("const r = window.caldaq.page.run; return r.captured === arguments[0] + 1 && r;".replace(
        "arguments[0]", str(captured0)), what="the captured stop in the live state")
    manual = [s for s in run["stops"] if s["manual"]]
    ok(len(manual) == 1 and not manual[0]["missed"], f"one stop captured by hand: {manual}")
    manual_stop = manual[0]
    b.wait("const r = document.querySelector(`#stops tbody tr[data-stop='%d']`); "
           "return r && r.cells[6].textContent === 'by hand';" % manual_stop["number"],
           what="the table row saying 'by hand'")
    page_checks.shot(b, SHOTS, "c02-captured-by-hand-1366x768.png")

    # --- 2b. capture by hand while the axis moves: refused, and the way to force it said -------
    b.wait("return window.caldaq.page.run.motion.state === 'moving';", timeout_s=60,
           what="the axis moving to the next target", explain=EXPLAIN)
    c = control(b, "c", "capture")
    ok(not c["ok"] and c["status"] == 409 and "not captured: the axis is moving (" in c["text"]
       and "press Capture (C) again within 3 s to take it anyway" in c["text"],
       f"C while moving: refused, saying how to force it: {c['text']!r}")
    ok(b.js("return document.getElementById('ctl-capture').textContent;") == "Capture anyway, while moving (C)",
       "the Capture button says a second press takes it anyway")
    page_checks.shot(b, SHOTS, "c02b-refused-while-moving-1366x768.png")
    b.wait("return document.getElementById('ctl-capture').textContent === 'Capture (C)';", timeout_s=10,
           what="the Capture button back after 3 s")

    # --- 3. resume, skip, measure again --------------------------------------------------------
    status, body = post(url + "api/runs/pause", {"why": 1})
    ok(status == 400, f"pause with a body of keys: 400 ({body.get('error')})")
    c = control(b, "p", "resume")
    ok(c["ok"] and c["text"].startswith("Done: resumed"), f"P resumes: {c['text']!r}")
    b.wait("return !window.caldaq.page.run.paused && document.getElementById('paused').hidden;",
           what="PAUSED gone")
    status, body = post(url + "api/runs/resume", {})
    ok(status == 409 and body["error"] == "the run is not paused", f"resume when running: 409 {body}")

    next_stop = b.js("return window.caldaq.page.run.stop.number;")
    c = control(b, "s", "skip")
    ok(c["ok"] and c["text"].startswith("Done: skipped by the operator: target "), f"S skips: {c['text']!r}")
    run = b.wait("const r = window.caldaq.page.run; return r.stops.some(s => s.skipped) && r;",
                 what="the skipped stop in the live state")
    skipped = [s for s in run["stops"] if s["skipped"]]
    # The next stop when S arrived: the one read before it, or the one after when the trigger
    # took that one in between (the axis may stand at it as the run resumes; seen once in 5).
    # Either way the stop the answer names, with every stop before it taken.
    named = re.search(r"target (\d+) \(\d+\.000 mm\) run (\d+) (up|down)$", c["text"])
    taken = {s["number"] for s in run["stops"] if not s["missed"]}
    ok(len(skipped) == 1 and skipped[0]["number"] in (next_stop, next_stop + 1) and skipped[0]["missed"] and named
       and [skipped[0]["target"], skipped[0]["run"], skipped[0]["direction"]] == [int(named[1]), int(named[2]), named[3]]
       and all(k in taken for k in range(1, skipped[0]["number"])),
       f"the next stop ({next_stop}) skipped: {skipped}")
    next_stop = skipped[0]["number"]
    b.wait("const r = document.querySelector(`#stops tbody tr[data-stop='%d']`); "
           "return r && r.cells[5].textContent === 'skipped';" % next_stop, what="the table row 'skipped'")

    # The machine goes on: its stop at the skipped target is not taken; the one after is.
    after = b.wait("const r = window.caldaq.page.run; const s = r.stops.filter(x => !x.missed); "
                   "const last = s[s.length - 1]; return last && last.number > %d && "
                   "r.motion.state === 'captured' && last;" % next_stop,
                   timeout_s=90, what="an automatic capture after the skipped target", explain=EXPLAIN)
    ok(after["number"] == next_stop + 1 and not after["manual"],
       f"the stop after the skipped one captured by the trigger: stop {after['number']}")
    ok(all(s["skipped"] for s in b.js(RUN)["stops"] if s["number"] == next_stop),
       "the skipped stop stays skipped")
    captured1 = b.js("return window.caldaq.page.run.captured;")
    c = control(b, "r", "retry")
    ok(c["ok"] and re.match(r"Done: measuring again: target \d .* \(the value [+-]\d+\.\d{3} µm discarded\)$", c["text"]),
       f"R measures the last stop again: {c['text']!r}")
    b.wait("return window.caldaq.page.run.captured === %d;" % (captured1 - 1),
           what="its value out of the run")
    ok(b.js("return window.caldaq.page.run.stop.number;") == after["number"],
       "the stop is expected again")
    again = b.wait("const r = window.caldaq.page.run; const s = r.stops.find(x => x.number === %d); "
                   "return r.captured === %d && s && !s.missed && s;" % (after["number"], captured1),
                   timeout_s=30, what="the stop captured anew", explain=EXPLAIN)
    ok(not again["manual"], f"captured anew by the trigger: {again['deviation_um']:+.4f} µm")
    # The deviation-versus-target plot has every captured stop (none missed or skipped).
    plotted, captured = b.wait("const r = window.caldaq.page.run; const n = r.stops.filter(s => !s.missed).length; "
                               "return window.caldaq.dvt && window.caldaq.dvt.points === n && [window.caldaq.dvt.points, n];",
                               what="the deviation-versus-target plot up to date")
    ok(plotted == captured and plotted >= 2, f"the deviation-versus-target plot: {plotted} stops plotted")
    b.js("document.getElementById('dvt').scrollIntoView();")
    page_checks.shot(b, SHOTS, "c03b-deviation-plot-1366x768.png")
    b.js("window.scrollTo(0, 0);")
    page_checks.shot(b, SHOTS, "c03-skip-retry-1366x768.png")
    page_checks.fits_narrow(b, SHOTS, "c04-controls-560px.png", "560 px: the controls fit")

    # --- 5. the run's end and record ----------------------------------------------------------
    # The run goes on to its end by itself with the skipped stop missed: too few runs are left
    # at that target to evaluate it, and it is stored as incomplete. The page says so (it said
    # ABORTED in red, as if stopped, while the store and the Results said incomplete).
    post(url + "api/simulation/speed", {"speed": 50})
    end = b.wait("const s = window.caldaq.page.status; return !s.running && s.last && s.last.run === %d && "
                 "[s.last.status, document.getElementById('reading').textContent, document.getElementById('run-line').textContent];" % run_id,
                 timeout_s=120, what="the run's end", explain=EXPLAIN)
    stored = get(url + "api/runs")
    stored = next(r for r in stored["runs"] if r["id"] == run_id)
    ok(end[0] == "incomplete" == stored["status"] and end[1] == "INCOMPLETE" and "missed" in end[2],
       f"its end as stored, in words: {end} (stored {stored['status']})")
    ok(b.js("return document.getElementById('manual').hidden;"), "no run: the controls go")
    status, body = post(url + "api/runs/retry", {})
    ok(status == 409, f"retry after the run: 409 ({body.get('error')})")
    doc = get(url + f"api/runs/{run_id}")
    actions = doc["operator_actions"]
    ok([a["action"] for a in actions] == ["pause", "capture", "resume", "skip", "retry"],
       f"every action recorded in order (none refused): {[a['action'] for a in actions]}")
    ok(all(a["source"] == "web page" and a["operator"] == "A. Operator" and
           re.match(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d", a["time"]) for a in actions),
       "each with its time, source and operator")
    cap, skip, retry = actions[1], actions[3], actions[4]
    ok(cap["stop"]["nominal_mm"] == manual_stop["nominal_mm"] and cap["stop"]["run"] == manual_stop["run"]
       and cap["stop"]["direction"] == manual_stop["direction"] and "captured by hand" in cap["detail"],
       f"the capture names its stop: {cap}")
    ok(skip["stop"]["target_index"] == skipped[0]["target"] and skip["stop"]["run"] == skipped[0]["run"],
       f"the skip names its stop: {skip}")
    ok(retry["stop"]["target_index"] == after["target"] and "discarded" in retry["detail"],
       f"the retry names its stop and the value discarded: {retry}")
    ok(any(m["target_index"] == skipped[0]["target"] and m["run"] == skipped[0]["run"] and
           m["direction"] == skipped[0]["direction"] for m in doc["missed_stops"]),
       "the skipped stop is among the run's missed stops")
    shown = subprocess.run([DAQ, "show", str(run_id), "--db", DB], capture_output=True, text=True)
    ok(shown.returncode == 0 and "operator actions (5):" in shown.stdout and
       "capture from the web page by A. Operator: captured by hand" in shown.stdout,
       "`daq show` lists them: " + "; ".join(l.strip() for l in shown.stdout.splitlines() if "from the" in l)[:400])
    report = os.path.join(TMP, "report.html")
    made = subprocess.run([DAQ, "report", str(run_id), "--db", DB, "-o", report], capture_output=True, text=True)
    html = open(report, encoding="utf-8").read() if made.returncode == 0 else made.stderr
    ok("<h4>Operator actions (5)</h4>" in html and f"captured by hand: target {manual_stop['target']} " in html and
       "skipped by the operator" in html and "web page (A. Operator)" in html,
       "the run's report lists the operator's actions")
    ok(b.js("return JSON.stringify(window.__errors);") == "[]", "no script error on the page")
    b.get("file://" + report)
    b.js("[...document.querySelectorAll('h4')].find(h => h.textContent.startsWith('Operator actions')).scrollIntoView();")
    page_checks.shot(b, SHOTS, "c05-report-operator-actions.png")
    print(f"operator page control: {page_checks.passes} checks passed; screenshots in {SHOTS}")
finally:
    b.close()
    page_checks.stop_service(serve)
    shutil.rmtree(TMP, ignore_errors=True)
