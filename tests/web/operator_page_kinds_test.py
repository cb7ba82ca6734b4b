#!/usr/bin/env python3
"""The component tests of the 21-error campaign started from the operator's page (issue 29),
driven in headless Chromium against `daq serve --simulate`:

1. the set-up offers the test kinds its instruments can measure (the simulated shop has a laser,
   an indicator and a level: positioning, straightness, angular, roll), with what each reads and
   where the other axes stand, in the Set-up form;
2. a straightness test of Y read in X typed in the form, applied and started (the laser on Y):
   the simulated indicator reads the machine's XY squareness (20 µm/m injected) across the
   travel, and the run is stored as `daq run linear` stores it (kind, component in its
   settings): `daq model build` takes it for E_XY;
3. an angular test (pitch of X, two laser beams 80 mm apart in Z) and a roll test of X (the
   level) from the form: the beams' fields only for the angular kind, checked at the field as
   typed; each run stored with what was typed, the stops table under "Angular deviation (µrad)"
   and "Roll (µrad)" with the stored values, the captured number in µrad; each stop reads the
   rotation the shop injects there (ShopTruth::served: E_BX = +40 µrad/m x X and E_AX =
   +40 µrad/m x X, so +4 µrad at X = 100 mm) within 0.3 µrad, with its sign;
4. the kinds offered follow the form's instruments.

What the page showed during a run is recorded in the page (a setInterval), not by WebDriver
looks racing a 50x run. Waits: up to 120 s for each run (6 stops at 20x on a loaded 2-core
machine take some 20 s; the angular and roll runs go at 50x).
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

    def run_kind(kind, axis, direction, what, extra=()):
        """Types a short test of KIND in the form (and the fields EXTRA: (key, value) pairs),
        applies it and starts it from the Run view; returns the stored run's id once it is
        complete and what the page showed of its stops (recorded in the page)."""
        b.js("document.getElementById('tab-setup').click();")
        wait("return !!document.querySelector('[data-key=\"test.linear.measure\"]');", "the test kind in the form")
        offered = b.js("return [...document.querySelector('[data-key=\"test.linear.measure\"]').options].map(o => o.value);")
        ok(offered == ["", "positioning", "straightness", "angular", "roll"], f"the form offers the kinds: {offered}")
        for key, value in (("test.linear.measure", kind), ("test.linear.axis", axis), ("test.linear.direction", direction),
                           ("test.linear.last_mm", "100"), ("test.linear.runs", "1"),
                           ("test.linear.stationary_mm", "200, 0, 150"), *extra):
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
        # The big number at CAPTURED too: its label names the stop, the number and unit are its own.
        b.js("window.__stops = {head: '', rows: {}, captured: {}}; clearInterval(window.__stopsTimer);"
             "window.__stopsTimer = setInterval(() => {"
             " const m = /\\(stop ([0-9]+)\\)/.exec(document.getElementById('reading-label').textContent);"
             " const v = document.getElementById('reading').textContent;"
             " if (m && /^[-+]?[0-9]/.test(v)) window.__stops.captured[m[1]] = [v, document.getElementById('reading-unit').textContent];"
             " const rows = document.querySelectorAll('#stops tbody tr');"
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
        return last["run"], b.js("clearInterval(window.__stopsTimer); return window.__stops;")

    # The rotations of X the simulated shop injects (daq/src/sim/sim_shop.hpp, ShopTruth::served;
    # docs/web.md): linear in X from 0 at X = 0.
    PITCH_URAD_PER_M = 40.0  # E_BX
    ROLL_URAD_PER_M = 40.0  # E_AX
    TOLERANCE_URAD = 0.3  # the laser's and the level's digits and the stop's noise are far below

    def read_as_injected(doc, urad_per_m, what):
        """Every stored stop of DOC is the injected rotation at its target, urad_per_m x X, within
        TOLERANCE_URAD: a run reading zeros (nothing injected) or the other sign fails (at 100 mm
        the rotation is 4 µrad)."""
        stops = [(s["nominal_mm"], s["deviation_um"]) for s in doc["stops"]]
        want = [(x, urad_per_m * x * 1e-3) for x, _ in stops]
        ok(len(stops) == 6 and max(x for x, _ in stops) >= 99.0
           and all(abs(v - w) <= TOLERANCE_URAD for (_, v), (_, w) in zip(stops, want)),
           f"{what}: each stop reads the injected {urad_per_m:+g} µrad/m x X within {TOLERANCE_URAD} µrad: "
           f"read {[(round(x, 3), round(v, 3)) for x, v in stops]}, injected {[(round(x, 3), round(w, 3)) for x, w in want]}")

    def stored_stops(doc):
        """A run's stored stop values by (target number, arrow) as the stops table names them."""
        return {(s["target_index"] + 1, "↑" if s["direction"] == "up" else "↓"): s["deviation_um"] for s in doc["stops"]}

    def shown_as_stored(shown, doc, head, what):
        """The stops table's head was HEAD and each value it showed (2 decimals) is the stored one."""
        stored = stored_stops(doc)
        seen = [(int(t), d, float(v)) for t, d, v in shown["rows"].values()]
        ok(shown["head"] == head and len(seen) >= 3 and all(abs(v - stored[(t, d)]) < 0.006 for t, d, v in seen),
           f"{what}: the stops table showed each stop's value as stored under {head!r}: {shown['head']} {seen} {stored}")

    # --- 2. straightness of X read in Y ----------------------------------------------------
    run, shown = run_kind("straightness", "Y", "X", "straightness of Y in X")
    doc = get(url + f"api/runs/{run}")
    # The stops table showed the indicator's values (as stored), under their name and unit; it
    # showed the laser's positioning deviation under "Deviation (µm)" before.
    shown_as_stored(shown, doc, "Straightness (µm)", "straightness")
    ok(doc["kind"] == "straightness" and doc["axis"] == "Y", f"stored as a straightness run of Y: {doc['kind']} {doc['axis']}")
    settings = doc["settings"]
    ok(settings["measure"]["component"] == "E_XY" and settings["measure"]["stationary_mm"] == [200, 0, 150],
       f"its component and set-up in its settings as `daq run linear` stores them: {settings['measure']}")
    cur = [r for r in doc["results"] if r["current"]]
    slope = re.search(r'"slope_um_per_m":\s*(-?[0-9.e+-]+)', json.dumps(cur))
    # The indicator reads the machine's XY squareness as the line's slope (20 µm/m injected: X
    # is off by E_C0Y x y as Y moves; the straightness proper is about the noise), changed by
    # 4 µm/m by X's yaw at X = 200 mm (E_CX = -20 µrad/m x X: -4 µrad, Y riding on X).
    ok(slope and 10 <= abs(float(slope.group(1))) <= 30,
       f"the simulated indicator reads the injected XY squareness as the profile's slope: {slope and slope.group(1)} µm/m")
    build = model_build(run)
    ok(build["used"].get("E_XY") == [run], f"`daq model build` takes run {run} for E_XY: {build['used']}")

    # --- 3. an angular test (pitch of X, E_BX) and a roll test (E_AX) from the form -----------
    # The shop at 5x from here (the page's recorder, not WebDriver's looks, sees each stop). A
    # stop shows CAPTURED for the rest of its dwell, 1.5 s of simulated time: 30 ms at 50x,
    # shorter than the page's updates (about 6 a second), so at 50x the captured number was
    # seen at 0 to 2 of 6 stops, as the machine's load fell; at 5x it lasts 300 ms.
    status, _ = page_checks.post(url + "api/simulation/speed", {"speed": 5})
    ok(status == 200, f"the simulated shop at 5x: {status}")
    b.js("document.getElementById('tab-setup').click();")
    SHOWN = "const f = [...document.querySelectorAll('[data-field]')].find(x => x.dataset.field === arguments[0]); return !!f && !f.hidden;"
    BEAMS = ("test.linear.beams", "test.linear.separation_mm")
    ok(not any(b.js(SHOWN, k) for k in BEAMS), "no beams in the form of a straightness test")
    for key, value in (("test.linear.measure", "angular"), ("test.linear.axis", "X"), ("test.linear.direction", "B")):
        ok(b.js(TYPE, key, value) == "ok", f"angular: typed {key} = {value}")
    ok(all(b.js(SHOWN, k) for k in BEAMS) and b.js(SHOWN, "test.linear.direction") and not b.js(SHOWN, "test.linear.square"),
       "an angular test's beams and their separation and its direction in the form, no square")
    labels = b.js("return arguments[0].map(k => { const f = [...document.querySelectorAll('[data-field]')].find(x => x.dataset.field === k);"
                  " return f.querySelector('label').textContent + ' [' + (f.querySelector('.u') || {textContent: ''}).textContent + ']'; });",
                  list(BEAMS))
    ok(labels == ["Laser axes of beam a and beam b (0, 1, 2) []", "Beam a's reflector from beam b's, across the travel [mm]"],
       f"labelled in words, the separation in mm: {labels}")
    # The error shown at the field of KEY once it says NEEDLE (arguments: key, needle).
    BAD = ("const f = [...document.querySelectorAll('[data-field]')].find(x => x.dataset.field === '%s');"
           " const t = f.classList.contains('bad') && f.querySelector('.err').textContent; return t && t.includes('%s') && t;")
    # Checked as typed, at the field: the loader's (no separation), the kind's (one along the
    # travel sees no pitch), the laser's (it reads axis 0 only).
    err = wait(BAD % ("test.linear.separation_mm", "separation"), "no separation named at its field")
    ok("needs the separation" in err, f"angular: an angular test needs its separation: {err}")
    ok(b.js(TYPE, "test.linear.separation_mm", "0, 100, 0") == "ok", "typed a separation across Y")
    err = wait(BAD % ("test.linear.separation_mm", "apart along"), "a separation that sees no pitch named at its field")
    ok("apart along Z" in err, f"angular: X about B is seen by beams apart along Z: {err}")
    ok(b.js(TYPE, "test.linear.separation_mm", "0, 0, 80") == "ok" and b.js(TYPE, "test.linear.beams", "2, 1") == "ok",
       "typed beams 2, 1 and 80 mm apart in Z")
    err = wait(BAD % ("test.linear.beams", "axis"), "beams the laser does not read named at their field")
    ok("does not read axis" in err, f"angular: the laser reads only axis 0: {err}")
    status = b.js("return document.getElementById('setup-status').textContent;")
    ok("linear test cannot start" in status, f"angular: not called valid beside the field in red: {status!r}")
    page_checks.shot(b, SHOTS, "k-angular-beams-1366x768.png")
    run, shown = run_kind("angular", "X", "B", "pitch of X",
                          (("test.linear.beams", "2, 1"), ("test.linear.separation_mm", "0, 0, 80"), ("devices.laser.axes", "0, 1, 2")))
    doc = get(url + f"api/runs/{run}")
    shown_as_stored(shown, doc, "Angular deviation (µrad)", "angular")
    measure = doc["settings"]["measure"]
    ok(doc["kind"] == "angular" and measure["component"] == "E_BX" and measure["beams"] == [2, 1]
       and measure["separation_mm"] == [0, 0, 80],
       f"the run used the beams and separation typed: {doc['kind']} {measure}")
    # The shop's X carriage pitches by E_BX = +40 µrad/m x X (ShopTruth::served, zero at X = 0
    # where the run starts): each stop reads it, with its sign; the captured number is the
    # stop's own, in µrad.
    read_as_injected(doc, PITCH_URAD_PER_M, "angular: the pitch of X")
    captured = list(shown["captured"].values())
    ok(captured and all(u == "µrad" for _, u in captured), f"angular: the captured stop's number in µrad: {captured}")

    # Its Results in the signs an engineer reads: the stops' check said "0.050 urad" (the
    # service's words, for terminals), and no number reads "-0.00" (a stop at X = 0 reads ~0).
    b.js("document.getElementById('tab-results').click();")
    wait(f"return !!document.querySelector('[data-show-run=\"{run}\"]');", "the angular run listed")
    b.js(f"document.querySelector('[data-show-run=\"{run}\"]').click();")
    panel = wait(f"return window.caldaq.result && window.caldaq.result.id === {run} && document.getElementById('result-values') && "
                 "[document.getElementById('result-panel').innerText, document.getElementById('result-quality').innerText];",
                 "the angular run's Results")
    summary = (doc.get("quality") or {}).get("summary", "")
    ok("urad" not in panel[1] and ("urad" not in summary or "µrad" in panel[1]),
       f"angular: the stops' check in µrad (stored: {summary!r}): {panel[1]!r}")
    bad = page_checks.ascii_units(panel[0])
    ok(not bad, f"angular: no 'um', 'urad' nor '-0.00' in its Results: {bad}")
    page_checks.shot(b, SHOTS, "k-angular-results-1366x768.png")
    b.js("document.getElementById('tab-run').click();")

    run, shown = run_kind("roll", "X", "", "roll of X")
    doc = get(url + f"api/runs/{run}")
    shown_as_stored(shown, doc, "Roll (µrad)", "roll")
    ok(doc["kind"] == "roll" and doc["settings"]["measure"]["component"] == "E_AX",
       f"stored as a roll run of X: {doc['kind']} {doc['settings']['measure']}")
    ok(not any(b.js(SHOWN, k) for k in (*BEAMS, "test.linear.direction", "test.linear.square")),
       "no beams, direction or square in the form of a roll test")
    read_as_injected(doc, ROLL_URAD_PER_M, "roll: the roll of X")
    captured = list(shown["captured"].values())
    ok(captured and all(u == "µrad" for _, u in captured), f"roll: the captured stop's number in µrad: {captured}")

    # --- 4. the kinds follow the form's instruments, not the applied set-up -----------------
    # The level removed in the form (not applied): roll is no longer offered (the kinds came
    # from the applied set-up and still offered it); the Run view names the unapplied edit.
    b.js("document.getElementById('tab-setup').click();")
    wait("return !!document.querySelector('[data-key=\"test.linear.measure\"]');", "the form again")
    # (a positioning test chosen: the roll test just run would stay offered, as chosen)
    ok(b.js(TYPE, "test.linear.measure", "positioning") == "ok", "typed test.linear.measure = positioning")
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
