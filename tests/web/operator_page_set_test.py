#!/usr/bin/env python3
"""The ballbar set from the operator's page (issue 29), driven in headless Chromium against
`daq serve --simulate`:

1. the set typed in the Set-up form (planes XY, ZX, YZ) and applied: the Run view names the set's
   three tests in the order Start runs them;
2. Start: the page says what to do now (mount the bar, run the program; then leave it mounted
   while the program moves it onto the next plane) and what comes next, test k of 3;
3. each test done shows its stored run, G and verdict (the same G as /api/runs/N);
4. before the feed-in the big number's place says "Waiting for the feed-in" in words (never blank,
   never a number: the bar's reading then is no circle deviation), with the test it is about to
   measure and the bar's live reading (the device board's, in the same message); the simulated
   machine's squareness is measured in every plane, and its vibration of Y (0.6 µm at 23.7 Hz) in
   XY and YZ, not in ZX; a circle's Results say nothing of target stops;
5. at the end the three-plane table, the same numbers `daq ballbar volumetric --runs` prints
   (the CLI's code), on the Run view and in the Results (opened by itself), at 1366 x 768 and
   560 px; the Results' verdict, what failed (the stored run's checks) and the polar plot all
   within the 1366 x 768 window without scrolling;
6. updates per second and bytes per update measured during the set: the polar trace is not resent
   whole in every message (it was: 15 kB an update), and the page's trace, built from the new
   points, is the service's whole trace (also for a page loaded after the test, which fetches it);
   units as their signs (µm, µrad, never "um", "urad") and no "-0.00" anywhere on the page.

Waits: up to 60 s for each phase (a 2-core machine under ctest -j3; the whole set is about 250 s
of simulated time, 5 s at the shop's 50x). Usage: operator_page_set_test.py DAQ_BINARY SHOT_DIR
"""
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok, post, TYPE  # noqa: E402

DAQ, SHOTS, TMP, DB = page_checks.test_dirs("operator-page-set-")
WAIT_S = 60


get = page_checks.get_json


def shot(b, name):
    page_checks.shot(b, SHOTS, name)


with page_checks.served_page(DAQ, TMP, page_checks.simulated(DB)) as (serve, url, b):
    wait = page_checks.waiter(b, TMP, (
        "return JSON.stringify({status: window.caldaq.page && window.caldaq.page.status, "
        "next: (document.getElementById('set-next') || {}).textContent, errors: window.__errors}).slice(0, 3000);"), WAIT_S)

    b.get(url)
    wait("return window.caldaq.page && window.caldaq.page.status && window.caldaq.page.status.start.circle.ready;", "Start ballbar ready")

    # --- 1. the set typed in the form and applied ----------------------------------------
    b.js("document.getElementById('tab-setup').click();")
    wait("return [...document.querySelectorAll('[data-key]')].some(i => i.dataset.key === 'test.circle.planes');",
         "the set's fields in the form")
    ok(b.js(TYPE, "test.circle.planes", "XY, ZX, YZ") == "ok", "typed: planes XY, ZX, YZ")
    ok(b.js(TYPE, "test.circle.feeds_mm_per_min", "3000") == "ok", "typed: feed 3000 mm/min")
    wait("return window.caldaq.check && window.caldaq.check.ok && !document.querySelector('.field.bad');",
         "the set accepted by the loader")
    b.js("document.getElementById('apply').click();")
    wait("const c = window.caldaq.page.status.setup.circle; return c.tests && c.tests.length === 3;",
         "the set applied")
    b.js("document.getElementById('tab-run').click();")
    plan = wait("const p = document.getElementById('plan'); return !p.hidden && /Ballbar set/.test(p.textContent) && p.textContent;",
                "the set on the Run view")
    ok("Ballbar set of 3 tests, in this order: XY 360°, 3000 mm/min, R 100.0 mm; ZX 220°, 3000 mm/min, R 100.0 mm; "
       "YZ 220°, 3000 mm/min, R 100.0 mm" in plan, f"the Run view names the set's tests in order: {plan!r}")
    wait("return window.caldaq.page.status.start.circle.ready;", "Start ballbar ready with the set")
    ok(b.js("return document.getElementById('start-circle').textContent;") == "Start ballbar set (3 tests)",
       "Start says it starts the set")

    # --- 2. Start: what to do now and next ------------------------------------------------
    post(url + "api/simulation/speed", {"speed": 1})  # the wait for test 1's feed-in is seen
    b.js("document.getElementById('start-circle').click();")
    first = wait("const s = window.caldaq.page.status; return s.running && s.set && s.set.tests[0].run;", "the set to start")
    # While the run waits for the feed-in the bar streams, but its reading is no deviation from
    # the circle (it showed "49999.97 µm"): what the run waits for in words where the number goes
    # (it was an empty area), the test it measures and the bar's own reading, read in the same
    # script as the live state the page drew them from.
    waiting = wait("const r = window.caldaq.page.run; if (!(r && r.schema === 'caldaq.live-circle.v1' && "
                   "r.state === 'waiting' && r.samples > 0)) return false; "
                   "const d = window.caldaq.page.devices.devices.find(x => x.role === 'ballbar'); "
                   "const q = Object.keys(d.values || {}).find(k => k.startsWith('length_m')); if (!q) return false; "
                   "const big = document.getElementById('big'); return [r.deviation_um, "
                   "document.getElementById('reading').textContent, document.getElementById('reading-unit').textContent, "
                   "document.getElementById('reading-label').textContent, document.getElementById('progress').textContent, "
                   "d.values[q], getComputedStyle(big).visibility, big.getBoundingClientRect().height];",
                   "the bar streaming before the feed-in")
    ok(waiting[0] is None and waiting[1] == "Waiting for the feed-in" and waiting[2] == "" and waiting[6] == "visible"
       and waiting[7] > 40, f"before the feed-in: no deviation in the status, 'Waiting for the feed-in' where the number goes: {waiting}")
    ok("XY 360°, 3000 mm/min, R 100.0 mm" in waiting[3] and "no circle deviation before the feed-in" in waiting[3],
       f"the test about to be measured named above it: {waiting[3]!r}")
    ok(waiting[4] == f"Bar reading now: {page_checks.fixed(waiting[5] * 1e3, 4)} mm",
       f"the bar's live reading below it, the device board's value in mm: {waiting[4]!r} vs {waiting[5]} m")
    NEXT = "const n = document.getElementById('set-next'); return !n.hidden"
    text = wait(NEXT + " && /set: test 1 of 3/.test(n.textContent) && n.textContent;", "test 1's instruction")
    ok("Ballbar set: test 1 of 3: XY 360°, 3000 mm/min, R 100.0 mm" in text and
       "Mount the bar in the XY plane on the table ball and run the set's program" in text and
       "Next: test 2 of 3, ZX 220°" in text, f"test 1: what to do and what comes next: {text!r}")
    shot(b, "s01-set-test1-1366x768.png")
    page_checks.fits_narrow(b, SHOTS, "s01b-set-waiting-560.png", "the wait for the feed-in fits 560 px")
    post(url + "api/simulation/speed", {"speed": 10})
    c0, bytes0, s0, t0 = b.js("return [window.caldaq.messages, window.caldaq.bytesTotal || 0, window.caldaq.statusMessages];") + [time.time()]
    b.js("window.__biggest = 0; window.__sizes = setInterval(() => { window.__biggest = Math.max(window.__biggest, window.caldaq.bytes || 0); }, 5);")
    text = wait(NEXT + " && /set: test 2 of 3/.test(n.textContent) && n.textContent;", "test 2's instruction")
    ok("Next: test 3 of 3, YZ 220°" in text and
       ("Leave the bar mounted: the set's program moves it from the XY plane onto the ZX plane" in text or
        "Measuring" in text), f"test 2: the bar stays (the program moves it), then YZ: {text!r}")
    c1, bytes1, s1, t1 = b.js("return [window.caldaq.messages, window.caldaq.bytesTotal || 0, window.caldaq.statusMessages];") + [time.time()]
    print(f"measured during the set's first test: {(c1 - c0) / (t1 - t0):.1f} page updates per second, "
          f"{(bytes1 - bytes0) / max(1, c1 - c0):.0f} bytes per update", flush=True)
    ok((c1 - c0) / (t1 - t0) >= 2, "the page is updated at least twice a second during the set")
    # The whole trace and the status in every message made 11 to 15 kB an update at this pace
    # (the shop at 10x: about 290 new points a second of wall time, ~14 bytes each); now each
    # carries the last 0.4 s of points (~1.5 kB at 10x), the devices' values (~1.8 kB) and the
    # run's state, and the status (1 to 2.5 kB) only after it changed.
    biggest = b.js("clearInterval(window.__sizes); return window.__biggest;")
    ok((bytes1 - bytes0) / max(1, c1 - c0) < 6000 and biggest < 10000,
       f"an update is not the whole trace again: {(bytes1 - bytes0) / max(1, c1 - c0):.0f} bytes on average, {biggest} at most")
    ok(s1 - s0 < (c1 - c0) / 2, f"the status is not in every update: in {s1 - s0} of {c1 - c0}")
    row = wait("const r = document.querySelector('#set-box tr[data-set-test=\"1\"]'); return r && "
               "r.cells[3].textContent === 'done' && r.cells[4].textContent !== '—' && [...r.cells].map(c => c.textContent);",
               "test 1 done in the set's table")
    doc = get(url + f"api/runs/{first}")
    g = [v for r in doc["results"] if r["current"] for v in r["values"] if v["symbol"] in ("G(b)", "G")]
    ok(g and row[4] == page_checks.fixed(g[0]['value'], 2), f"test 1's G is its stored run's: {row} vs {g[:1]}")
    ok(row[2] == str(first) and row[6] in ("PASS", "FAIL", "no tolerance configured"), f"with its run and verdict: {row}")
    post(url + "api/simulation/speed", {"speed": 50})
    shot(b, "s02-set-test2-1366x768.png")
    # The live polar plot beside the number at 1366 x 768, whole (it was under the fold).
    polar = b.js("const e = document.getElementById('polar').getBoundingClientRect(); return [e.top, e.bottom, e.width, window.innerHeight];")
    ok(polar[2] > 300 and polar[0] >= 0 and polar[1] <= polar[3], f"the live polar plot on screen, {polar[2]:.0f} px wide: {polar}")

    # --- 3. the end: the three-plane table as the CLI prints it ---------------------------
    wait("const s = window.caldaq.page.status.set; return s && s.state === 'complete' && s.table;", "the set's end")
    runs = b.js("return window.caldaq.page.status.set.tests.map(t => t.run);")
    ok(len(runs) == 3 and runs == sorted(runs) and runs[0] == first, f"three runs, one per test: {runs}")
    # The simulated shop's specification covers every plane of the set (it had XY's alone: YZ
    # and ZX said "no tolerance configured"): each test's verdict is judged.
    verdicts = wait("const r = [...document.querySelectorAll('#set-box tr[data-set-test]')]; return r.length === 3 && "
                    "r.every(x => x.cells[6].textContent !== '—') && r.map(x => [x.cells[1].textContent, x.cells[6].textContent]);",
                    "the set's three verdicts")
    ok(all(v in ("PASS", "FAIL") for _, v in verdicts), f"each plane judged against its tolerance: {verdicts}")
    cli = json.loads(subprocess.run([DAQ, "ballbar", "volumetric", "--db", DB, "--runs", ",".join(map(str, runs)), "--json"],
                                    capture_output=True, text=True, check=True).stdout)
    wait("return !document.getElementById('result-set').hidden;", "the Results with the set's table")
    ok(b.js("return window.caldaq.view;") == "results", "the Results view opened by itself at the set's end")
    shown = b.js("return [...document.querySelectorAll('#result-set-vol tbody tr')].map(r => [...r.cells].map(c => c.textContent));")
    ok(len(shown) == 3 and sorted(r[0] for r in shown) == ["XY", "YZ", "ZX"], f"a row per plane: {shown}")
    for p in cli["planes"]:
        r = next(x for x in shown if x[0] == p["plane"])
        want = page_checks.fixed(p['squareness_um_per_m'], 1, "+")
        ok(r[3] == want and r[1] == str(p["runs"][0]),
           f"{p['plane']}: squareness {r[3]} µm/m as `daq ballbar volumetric` ({want}), from run {r[1]}")
        # The simulated shop has squareness in every plane (`daq sim --test circle-set`'s truth:
        # 20, 15 and 10 µm/m in size), so each plane's diagnostic is a real one, not a square 0.
        ok(abs(p["squareness_um_per_m"]) >= 5,
           f"{p['plane']}: the simulated machine's squareness is measured ({want} µm/m), not ~0")
    # The simulated shop's Y vibrates 0.6 µm (peak) at 23.7 Hz (ShopTruth::served, docs/web.md):
    # an axial vibration of amplitude A reads A/2 rms over a full circle (docs/circle.md), so
    # the XY test finds 0.3 µm rms at 23.7 Hz; the ZX plane has no Y in it and finds none.
    def vibration(run):
        cur = next(r["result"] for r in get(url + f"api/runs/{run}")["results"] if r["current"])
        return next((d for d in cur.get("diagnostics", []) if d["key"] == "vibration"), None)
    vib = {plane: vibration(run) for plane, run in zip(("XY", "ZX", "YZ"), runs)}
    ok(vib["XY"] and abs(vib["XY"]["frequency_hz"] - 23.7) < 0.2 and abs(vib["XY"]["value"] - 0.3) < 0.05,
       f"XY: the injected vibration of Y read at 23.7 Hz, 0.3 µm rms (within 0.05): {vib['XY']}")
    ok(vib["YZ"] and abs(vib["YZ"]["frequency_hz"] - 23.7) < 0.2, f"YZ: the vibration of Y at 23.7 Hz: {vib['YZ']}")
    # ZX: nothing at the injected frequency, and nothing of its size. (The diagnostic may name
    # a component of the trace's noise: once 0.06 µm at 1.05 Hz, seen in a clean clone's run.)
    ok(vib["ZX"] is None or (abs(vib["ZX"]["frequency_hz"] - 23.7) > 1.0 and vib["ZX"]["value"] < 0.15),
       f"ZX: no vibration of Y (Y is not in the plane): {vib['ZX']}")
    # A ballbar test has no target stops: nothing is said of checking them ("Stops not checked:
    # not checked: one run in one direction" was a linear test's notion, its state said twice).
    quality = b.js("return document.getElementById('result-quality').textContent;")
    ok("not checked" not in quality and "Stops" not in quality, f"no stop check on a circle's Results: {quality!r}")
    # The polar plot of the test shown (the last), from its stored readings, bounded in size.
    trace = get(url + f"api/runs/{runs[2]}")["trace"]
    n_ccw, n_cw, size = len(trace["ccw"]), len(trace["cw"]), len(json.dumps(trace))
    ok(150 <= n_ccw <= 400 and 150 <= n_cw <= 400 and size < 30000,
       f"/api/runs/N carries the circle's traces, a point per degree at most: {n_ccw} + {n_cw} points, {size} bytes")
    ok(all(abs(p[1]) < 50 for p in trace["ccw"] + trace["cw"]), "deviations in µm about the centre")
    painted = wait("const c = document.getElementById('result-polar'); if (c.closest('[hidden]')) return false; "
                   "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; "
                   "for (let i = 0; i < d.length; i += 4) if (d[i + 2] > 200 && d[i] < 120) n++; return n;",
                   "the polar plot on the Results")
    ok(painted > 500, f"the ccw trace is drawn on the Results ({painted} blue pixels)")
    shot(b, "s03-set-results-1366x768.png")
    # At 1366 x 768 the verdict, what failed and the polar plot are on screen without scrolling
    # (they were under the set's tables). What failed is the stored run's checks that failed.
    fold = b.js("const r = (id) => { const e = document.getElementById(id).getBoundingClientRect(); return [e.top, e.bottom]; };"
                "return {h: window.innerHeight, y: window.scrollY, verdict: r('result-verdict'), failed: r('result-failed'),"
                " polar: r('result-polar'), text: document.getElementById('result-verdict').textContent,"
                " items: [...document.querySelectorAll('#result-failed [data-failed]')].map(e => e.textContent)};")
    ok(fold["y"] == 0 and all(0 <= fold[k][0] and fold[k][1] <= fold["h"] for k in ("verdict", "polar")),
       f"the verdict and the polar plot above the fold at 1366 x 768: {fold}")
    cur = next(r for r in get(url + f"api/runs/{runs[2]}")["results"] if r["current"])
    failed = [c for c in cur["verdict"]["checks"] if not c["pass"]]
    ok(fold["text"] == ("FAIL" if failed else "PASS") and len(fold["items"]) == len(failed) and
       (not failed or fold["failed"][1] <= fold["h"]), f"the verdict with each failed value beside it: {fold['items']} vs {failed}")
    for c, text in zip(failed, fold["items"]):
        unit = {"um": "µm", "um/m": "µm/m"}.get(c["unit"], c["unit"])
        ok(text == f"{c['symbol']} {c['value']:.3f} {unit} over its limit {c['limit']:.3f} {unit}",
           f"the failed value as stored, in its unit's sign: {text!r}")
    b.js("document.getElementById('result-polar').scrollIntoView();")
    shot(b, "s03b-set-results-polar-1366x768.png")
    b.js("window.scrollTo(0, 0);")
    b.js("document.getElementById('tab-run').click();")
    text = wait(NEXT + " && /complete/.test(n.textContent) && n.textContent;", "the set's end on the Run view")
    ok(f"Ballbar set complete: 3 of 3 tests stored (runs {runs[0]}, {runs[1]}, {runs[2]})" in text, f"the end in words: {text!r}")
    ok(b.js("return document.querySelectorAll('#set-box-vol tbody tr').length;") == 3, "the table on the Run view too")
    shot(b, "s04-set-end-run-1366x768.png")
    page_checks.fits_narrow(b, SHOTS, "s05-set-end-run-560.png", "the set's table fits 560 px")
    # At 560 px each test on one line of the set's table, which does not scroll sideways, nor
    # does the three-plane table (the names wrapped to three lines and both tables scrolled, the
    # verdicts out of sight), on the Run view and in the Results.
    COMPACT = ("const box = document.getElementById(arguments[0]); const rows = [...box.querySelectorAll('.set-table tbody tr')];"
               " if (rows.length !== 3 || rows[0].cells[1].textContent !== arguments[1]) return false;"
               " const line = 1.25 * parseFloat(getComputedStyle(rows[0].cells[1]).fontSize);"
               " return {names: rows.map(r => r.cells[1].textContent), line,"
               " tallest: Math.max(...rows.map(r => r.cells[1].getBoundingClientRect().height)),"
               " sideways: [...box.querySelectorAll('.scroll-x')].map(x => x.scrollWidth - x.clientWidth),"
               " verdict: rows[0].cells[6].getBoundingClientRect().right <= box.getBoundingClientRect().right + 1};")
    for view, box in (("run", "set-box"), ("results", "result-set")):
        b.js(f"document.getElementById('tab-{view}').click();")
        b.set_size(560, 900)
        narrow = wait("return (() => {" + COMPACT.replace("arguments[0]", repr(box)).replace("arguments[1]", "'XY 360° 3000 R100'") + "})();",
                      f"the set's table at 560 px ({view})")
        ok(narrow["names"] == ["XY 360° 3000 R100", "ZX 220° 3000 R100", "YZ 220° 3000 R100"] and
           narrow["tallest"] < 1.5 * narrow["line"] and max(narrow["sideways"]) <= 0 and narrow["verdict"],
           f"560 px ({view}): each test on one line, its verdict in sight, no table scrolls sideways: {narrow}")
        b.set_size(1366, 768)
        wait(f"const r = document.querySelector('#{box} .set-table tbody tr'); return r && r.cells[1].textContent === 'XY 360°, 3000 mm/min, R 100.0 mm';",
             f"the whole names again at 1366 px ({view})")
    b.js("document.getElementById('tab-results').click();")
    page_checks.fits_narrow(b, SHOTS, "s06-set-results-560.png", "the Results with the set fit 560 px")
    # Units as their signs and numbers without a negative zero, on every view shown; the shared
    # presentation itself (daq/web/present.js) on the service's own words, checked by hand.
    for view in ("run", "results"):
        b.js(f"document.getElementById('tab-{view}').click();")
        bad = page_checks.ascii_units(b.js("return document.body.innerText;"))
        ok(not bad, f"the {view} view writes no 'um', 'urad' nor '-0.00': {bad}")
    shown = b.js("return [present.text('stop quality 0.050 urad, spread 1.5 um/m, drum'), "
                 "present.text('captured by hand: stop 3: -0.000 urad'), present.fixed(-0.004, 2), present.fixed(-0.006, 2), "
                 "present.signed(-0.01, 1), present.unit('urad'), present.unit('arcsec')];")
    ok(shown == ["stop quality 0.050 µrad, spread 1.5 µm/m, drum", "captured by hand: stop 3: 0.000 µrad", "0.00", "-0.01",
                 "+0.0", "µrad", "arcsec"], f"present.js: units as signs, no negative zero: {shown}")

    # The page's status (kept from the messages that carried it) is the service's.
    mine = b.js("return window.caldaq.page.status;")
    theirs = get(url + "api/status")
    ok({k: v for k, v in mine.items() if k != "seq"} == {k: v for k, v in theirs.items() if k != "seq"},
       f"the page's status is the service's: {json.dumps(mine)[:300]} vs {json.dumps(theirs)[:300]}")

    # --- 4. the live trace: the page's, from the new points, is the service's whole ----------
    b.js("document.getElementById('tab-run').click();")
    whole = get(url + "api/live/trace")
    mine = b.js("const t = window.caldaq.liveTrace; return t && {epoch: t.epoch, ccw: t.ccw, cw: t.cw};")
    ok(mine and mine["epoch"] == whole["epoch"] and mine["ccw"] == whole["ccw"] and mine["cw"] == whole["cw"] and len(whole["ccw"]) > 150,
       f"the page's trace is the service's: {len(whole['ccw'])} + {len(whole['cw'])} points, the page "
       f"{mine and (len(mine['ccw']), len(mine['cw']))}")
    # A page loaded now missed every new point: it asks for the whole trace once.
    b.get(url)
    again = wait("const t = window.caldaq.liveTrace; return t && t.ccw.length > 150 && [t.ccw.length, t.cw.length, window.caldaq.traceFetches];",
                 "the trace on a page loaded after the test")
    ok(again == [len(whole["ccw"]), len(whole["cw"]), 1], f"fetched whole once by a page loaded late: {again}")
    page_checks.no_script_error(b)
