#!/usr/bin/env python3
"""The component tests of the 21-error campaign started from the operator's page (issue 29),
driven in headless Chromium against `daq serve --simulate`:

1. the set-up offers the test kinds its instruments can measure (the simulated shop has a laser,
   an indicator and a level: positioning, straightness, angular, roll), with what each reads and
   where the other axes stand, in the Set-up form;
2. a straightness test of Y read in X typed in the form, applied and started (the laser on Y):
   the simulated indicator reads the machine's XY squareness (20 µm/m injected) across the
   travel, and the run is stored as `daq run linear` stores it (kind, component in its
   settings): `daq model build` takes it for E_XY.

Waits: up to 120 s for each run (6 stops at 20x on a loaded 2-core machine take some 20 s).
Usage: operator_page_kinds_test.py DAQ_BINARY SHOT_DIR
"""
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok, TYPE  # noqa: E402

DAQ, SHOTS, TMP, DB = page_checks.test_dirs("operator-page-kinds-")
WAIT_S = 120


get = page_checks.get_json


def model_build(run):
    """`daq model build --json` of the service's machine (its runs say no topology: given). One
    run of 3 targets compares each stop with too little: its stops may be judged suspect by the
    noise alone, so the run is accepted knowingly (the gate is not what this test checks)."""
    return json.loads(subprocess.run([DAQ, "model", "build", "--machine", "SIMULATED VMC", "--db", DB, "--topology", "FXYZ",
                                      "--allow-missing", "--accept-suspect", str(run), "--json", "-o", os.path.join(TMP, "m.json")],
                                     capture_output=True, text=True, check=True).stdout)


with page_checks.served_page(DAQ, TMP, page_checks.simulated(DB)) as (serve, url, b):
    wait = page_checks.waiter(b, TMP, (
        "const s = window.caldaq.page && window.caldaq.page.status; return JSON.stringify({running: s && s.running, "
        "last: s && s.last, check: window.caldaq.check, errors: window.__errors}).slice(0, 3000);"), WAIT_S)

    # --- 1. the kinds the instruments can measure -------------------------------------------
    kinds = get(url + "api/setup")["choices"]["kinds"]
    ok(kinds == ["positioning", "straightness", "angular", "roll"],
       f"the simulated shop's laser, indicator and level measure every linear kind: {kinds}")
    b.get(url)
    wait("return window.caldaq.page && window.caldaq.page.status.start.linear.ready;", "Start linear ready")

    def run_kind(kind, axis, direction, what):
        """Types a short test of KIND in the form, applies it and starts it from the Run view;
        returns the stored run's id once it is complete."""
        b.js("document.getElementById('tab-setup').click();")
        wait("return !!document.querySelector('[data-key=\"test.linear.measure\"]');", "the test kind in the form")
        offered = b.js("return [...document.querySelector('[data-key=\"test.linear.measure\"]').options].map(o => o.value);")
        ok(offered == ["", "positioning", "straightness", "angular", "roll"], f"the form offers the kinds: {offered}")
        for key, value in (("test.linear.measure", kind), ("test.linear.axis", axis), ("test.linear.direction", direction),
                           ("test.linear.last_mm", "100"), ("test.linear.runs", "1"),
                           ("test.linear.stationary_mm", "200, 0, 150")):
            ok(b.js(TYPE, key, value) == "ok", f"{what}: typed {key} = {value}")
        # The instruments' cards keep the probe's role (they offered only the positioning roles:
        # the indicator's card lost it and the test its probe).
        wait("const c = window.caldaq.check; return c && c.ok && c.tests.linear.problem === null && "
             "!document.querySelector('.field.bad');", f"{what}: accepted by the loader, its probe found")
        page_checks.shot(b, SHOTS, f"k-{kind}-setup-1366x768.png")
        version = b.js("return window.caldaq.page.status.setup.version;")
        b.js("document.getElementById('apply').click();")
        wait("const s = window.caldaq.page.status.setup; return s.version > %d && s.linear && s.linear.last_mm === 100;"
             % version, f"{what}: applied")
        b.js("document.getElementById('tab-run').click();")
        wait("return window.caldaq.page.status.start.linear.ready;", f"{what}: Start ready")
        # The Run view names what Start runs by its kind and component, not "Linear test".
        plan = b.js("return document.getElementById('plan').textContent;")
        ok(f"{kind.capitalize()} test E_" in plan and f"axis {axis}: 0.000 → 100.000 mm" in plan,
           f"{what}: the Run view names the kind: {plan!r}")
        before = b.js("return (window.caldaq.page.status.last || {}).run || 0;")
        # What the stops table showed while the run ran, recorded in the page (a 20x run may
        # end between two WebDriver looks): its value column's head and each stop's value.
        b.js("window.__stops = {head: '', rows: {}}; clearInterval(window.__stopsTimer);"
             "window.__stopsTimer = setInterval(() => { const rows = document.querySelectorAll('#stops tbody tr');"
             " if (!rows.length) return; window.__stops.head = document.getElementById('stops-value').textContent;"
             " for (const r of rows) { const c = [...r.cells].map(x => x.textContent);"
             " if (/^[-+]?[0-9]/.test(c[5])) window.__stops.rows[c[0]] = [c[3], c[2], c[5]]; } }, 20);")
        b.js("document.getElementById('start-linear').click();")
        # Started (a short run at 20x may end between two looks: its end counts too).
        wait("const s = window.caldaq.page.status; return s.running || (s.last && s.last.run > %d);" % before,
             f"{what}: started")
        page_checks.shot(b, SHOTS, f"k-{kind}-run-1366x768.png")
        wait("const s = window.caldaq.page.status; return Object.keys(window.__stops.rows).length >= 3 || "
             "!s.running;", f"{what}: three stops in the table")
        b.js("document.getElementById('stops-panel').scrollIntoView();")
        page_checks.shot(b, SHOTS, f"k-{kind}-stops-1366x768.png")
        b.js("window.scrollTo(0, 0);")
        last = wait("const l = window.caldaq.page.status.last; return !window.caldaq.page.status.running && l && "
                    "l.run > %d && l;" % before, f"{what}: the run's end")
        ok(last["status"] == "complete" and last["test"] == "linear", f"{what}: complete: {last}")
        return last["run"]

    # --- 2. straightness of X read in Y ----------------------------------------------------
    run = run_kind("straightness", "Y", "X", "straightness of Y in X")
    doc = get(url + f"api/runs/{run}")
    # The stops table showed the indicator's values (as stored), under their name and unit; it
    # showed the laser's positioning deviation under "Deviation (µm)" before.
    shown = b.js("clearInterval(window.__stopsTimer); return window.__stops;")
    stored = {(s["target_index"] + 1, "↑" if s["direction"] == "up" else "↓"): s["deviation_um"] for s in doc["stops"]}
    seen = [(int(t), d, float(v)) for t, d, v in shown["rows"].values()]
    ok(shown["head"] == "Straightness (µm)" and seen and
       all(abs(v - stored[(t, d)]) < 0.006 for t, d, v in seen),
       f"the stops table showed each stop's straightness value as stored: {shown['head']} {seen} {stored}")
    ok(doc["kind"] == "straightness" and doc["axis"] == "Y", f"stored as a straightness run of Y: {doc['kind']} {doc['axis']}")
    settings = doc["settings"]
    ok(settings["measure"]["component"] == "E_XY" and settings["measure"]["stationary_mm"] == [200, 0, 150],
       f"its component and set-up in its settings as `daq run linear` stores them: {settings['measure']}")
    cur = [r for r in doc["results"] if r["current"]]
    slope = re.search(r'"slope_um_per_m":\s*(-?[0-9.e+-]+)', json.dumps(cur))
    # The indicator reads the machine's XY squareness as the line's slope (20 µm/m injected: X
    # is off by E_C0Y x y as Y moves; the straightness proper is about the noise).
    ok(slope and 10 <= abs(float(slope.group(1))) <= 30,
       f"the simulated indicator reads the injected XY squareness as the profile's slope: {slope and slope.group(1)} µm/m")
    build = model_build(run)
    ok(build["used"].get("E_XY") == [run], f"`daq model build` takes run {run} for E_XY: {build['used']}")

    # --- 3. the kinds follow the form's instruments, not the applied set-up -----------------
    # The level removed in the form (not applied): roll is no longer offered (the kinds came
    # from the applied set-up and still offered it); the Run view names the unapplied edit.
    b.js("document.getElementById('tab-setup').click();")
    wait("return !!document.querySelector('[data-key=\"test.linear.measure\"]');", "the form again")
    b.js("const card = [...document.querySelectorAll('.device-card')].find(c => c.querySelector('[data-device-id]').value === 'level');"
         "card.querySelector('button.stop').click();")
    offered = wait("const c = window.caldaq.check; const o = [...document.querySelector('[data-key=\"test.linear.measure\"]').options]"
                   ".map(o => o.value); return c && c.kinds && !c.kinds.includes('roll') && !o.includes('roll') && o;",
                   "the kinds of the form's instruments")
    ok(offered == ["", "positioning", "straightness", "angular"], f"without the level, no roll test is offered: {offered}")
    b.js("document.getElementById('tab-run').click();")
    pending = wait("const p = document.getElementById('pending-edits'); return !p.hidden && p.textContent;", "the unapplied edit named")
    ok("level" in pending, f"the Run view says Start runs the applied set-up, not the edit: {pending!r}")
    page_checks.shot(b, SHOTS, "k-edited-run-1366x768.png")

    b.js("document.getElementById('tab-setup').click();")
    page_checks.fits_narrow(b, SHOTS, "k-setup-560.png", "the form with the test kind fits 560 px")
    page_checks.no_script_error(b)
