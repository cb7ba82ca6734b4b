#!/usr/bin/env python3
"""The 21-error volumetric campaign on the operator's page (issue 29), driven in headless Chromium:

a short campaign on the simulated shop (`daq sim --measure` and `daq run linear`, as
docs/volumetric-walkthrough.md measures it): positioning E_XX, the two straightness runs of
the XY plane (E_YX, E_XY, read against one square) and positioning E_ZZ (every axis has a run:
the model's travel is known), the first of them dated a day earlier (a campaign over two days); then `daq serve -c` on that store. The Results view lists the 18
component tests and the three squarenesses, one line each (at 560 px too), each with its test and instrument, the next one to
measure in full above them; the measured
ones with the run `daq model build` uses for them (its --json `used`, the CLI's own code), their
day and where the other axes stood; the XY squareness measured from its two runs; the others
"to do"; the days; and the commands that build the model and its map. Under it the model itself
(GET /api/model): built by `daq model build`'s own function (the same runs used and errors
missing as `daq model build --allow-missing --json`), the 21 errors with what each adds to the
map and its summary as `daq model map --json` gives them, and the map's XY slice drawn.
Screenshots at 1366 x 768 and 560 px.

Waits: each simulated run about 15 s on a loaded 2-core machine; the page's load up to 60 s.
Usage: operator_page_campaign_test.py DAQ_BINARY SHOT_DIR
"""
import datetime
import json
import os
import sqlite3
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok  # noqa: E402

DAQ, SHOTS, TMP, DB = page_checks.test_dirs("operator-page-campaign-")
MACHINE = "SIMULATED YFXZ"


def measure(component):
    """One component's test on the simulated shop, as the walkthrough runs it: `daq sim` writes
    the configuration, then waits for the run to start in the store."""
    toml = os.path.join(TMP, "sim.toml")
    if os.path.exists(toml):
        os.remove(toml)
    log = open(os.path.join(TMP, f"sim-{component}.log"), "w")
    sim = subprocess.Popen([DAQ, "sim", "--measure", component, "--topology", "YFXZ", "--speed", "10",
                            "--db", DB, "-o", "sim.toml"], stdout=log, stderr=subprocess.STDOUT, cwd=TMP)
    try:
        deadline = time.time() + 60
        while not os.path.exists(toml) and sim.poll() is None and time.time() < deadline:
            time.sleep(0.1)
        r = subprocess.run([DAQ, "run", "linear", "-c", "sim.toml", "--db", DB], capture_output=True, text=True, cwd=TMP)
        ok(r.returncode == 0, f"{component} measured on the simulated shop: {r.stderr[-500:]}")
    finally:
        sim.wait(timeout=120)


for component in ("E_XX", "E_YX", "E_XY", "E_ZZ"):
    measure(component)
con = sqlite3.connect(DB)
con.execute("UPDATE runs SET started_unix_ms = started_unix_ms - 86400000, ended_unix_ms = ended_unix_ms - 86400000 WHERE id = 1")
con.commit()
days = [datetime.datetime.fromtimestamp(ms / 1000, datetime.timezone.utc).strftime("%Y-%m-%d")
        for (ms,) in con.execute("SELECT started_unix_ms FROM runs ORDER BY id")]
con.close()
cli = json.loads(subprocess.run([DAQ, "model", "build", "--machine", MACHINE, "--db", DB, "--allow-missing", "--json",
                                 "-o", os.path.join(TMP, "model.json")], capture_output=True, text=True, check=True).stdout)

with page_checks.served_page(DAQ, TMP, ["-c", os.path.join(TMP, "sim.toml"), "--db", DB]) as (serve, url, b):
    b.get(url)
    b.js("document.getElementById('tab-results').click();")
    head = b.wait("const h = document.getElementById('vol-head').textContent; return /Volumetric/.test(h) && h;",
                  timeout_s=60, what="the campaign's checklist")
    ok(head == f"Volumetric campaign of {MACHINE}: 5 of 21 errors measured",
       f"4 component tests and the XY squareness of 21: {head!r}")
    rows = b.js("return Object.fromEntries([...document.querySelectorAll('#vol-table tbody tr')].map(r => "
                "[r.dataset.component, [...r.cells].map(c => c.textContent)]));")
    ok(len(rows) == 21, f"a row for each of the 18 components and 3 squarenesses: {len(rows)}")
    for component, ids in cli["used"].items():
        if component.startswith("E_") and len(component) == 4:
            ok(rows[component][3] == str(ids[0]),
               f"{component}: run {rows[component][3]}, the one `daq model build` uses ({ids})")
    ok(rows["E_XX"][4] == days[0] and rows["E_YX"][4] == days[1],
       f"each with its day: E_XX {rows['E_XX'][4]}, E_YX {rows['E_YX'][4]}")
    titles = b.js("return Object.fromEntries([...document.querySelectorAll('#vol-table tbody tr')].map(r => [r.dataset.component, r.cells[1].title]));")
    ok(rows["E_XX"][1] == "Positioning of X" and titles["E_XX"] == "Positioning of X: the laser along X" and rows["E_XX"][2] == "laser",
       f"the test by its short name (its set-up in words on pointing) and its instrument: {rows['E_XX'][:3]} {titles['E_XX']!r}")
    ok(rows["E_YX"][1] == "Straightness of X in Y" and "against a square" in rows["E_YX"][5] and
       rows["E_YX"][5].startswith("other axes at "), f"the set-up as measured: {rows['E_YX']}")
    ok(rows["E_BX"][3] == "to do" and rows["E_BX"][4] == "" and rows["E_BX"][1] == "Angle of X about B" and
       titles["E_BX"] == "Angle of X about B: two laser beams side by side, reflectors apart across the travel",
       f"what is left: {rows['E_BX']}")
    # The next step to measure (the first left in the walkthrough's order) in full above the
    # table, and marked in it.
    # (E_BX: the walkthrough's first test, docs/volumetric-walkthrough.md; this campaign measured
    # positioning and straightness only)
    current = b.js("return [...document.querySelectorAll('#vol-table tr.current')].map(r => r.dataset.component);")
    first_left = "E_BX"
    nxt = b.js("return document.getElementById('camp-next').textContent;")
    ok(current == [first_left] and nxt.startswith(f"Next: {first_left}, ") and "Instrument: " in nxt and
       "put the other axes at targets of their own angular runs" in nxt, f"the next step {first_left} in full: {nxt!r}")
    ok(rows["E_C0Y"][3] == f"{cli['used']['E_YX'][0]}, {cli['used']['E_XY'][0]}" and rows["E_C0Y"][4] == "",
       f"the XY squareness from its two straightness runs: {rows['E_C0Y']}")
    ok(rows["E_B0Z"][3] == "to do", "the ZX squareness still to do")
    text = b.js("return document.getElementById('vol-box').textContent;")
    ok(f"{days[0]}: 1 measured: E_XX" in text and f"{days[1]}: 3 measured: E_YX, E_XY, E_ZZ" in text,
       "the campaign's progress by day")
    ok("16 still to measure. The model below is built from the runs measured so far" in text and
       f"From the command line: `daq model build --machine '{MACHINE}' --db '{DB}' -o model.json`" in text and
       "daq model map model.json" in text, "the model is below; the commands that build it and its map")
    b.js("document.getElementById('vol-panel').scrollIntoView();")
    page_checks.shot(b, SHOTS, "c01-campaign-1366x768.png")
    page_checks.fits_narrow(b, SHOTS, "c02-campaign-560.png", "the checklist fits 560 px")
    # At 560 px one line a step (a row was two to six lines: the checklist 2,700 px tall), its
    # table as wide as the screen, and the next step's line on screen once the checklist's head is.
    b.set_size(560, 900)
    narrow = b.wait("const rows = [...document.querySelectorAll('#vol-table tbody tr')]; if (rows[0].cells[2].offsetParent !== null) return false;"
                    " const line = 1.25 * parseFloat(getComputedStyle(rows[0].cells[0]).fontSize);"
                    " const box = document.querySelector('#vol-box .scroll-x');"
                    " document.getElementById('vol-head').scrollIntoView();"
                    " const next = document.getElementById('camp-next').getBoundingClientRect();"
                    " return {tallest: Math.max(...rows.map(r => r.getBoundingClientRect().height)), line,"
                    " wide: box.scrollWidth - box.clientWidth, table: document.getElementById('vol-table').getBoundingClientRect().height,"
                    " next: next.bottom <= window.innerHeight};", timeout_s=10, what="the checklist at 560 px")
    ok(narrow["tallest"] <= 2 * narrow["line"] and narrow["wide"] <= 0 and narrow["table"] < 1000 and narrow["next"],
       f"560 px: one line a step, nothing scrolls sideways, the next step on screen: {narrow}")
    b.set_size(1366, 768)

    # --- the model of these runs and its map, as the CLI builds and maps it ----------------
    model = page_checks.get_json(url + "api/model")
    ok(model["schema"] == "caldaq.model-view.v1" and model["state"] == "partial" and model["machine"] == MACHINE,
       f"GET /api/model: a partial model of {MACHINE}: {model['state']!r}")
    ok(model["build"]["used"] == cli["used"] and model["build"]["missing"] == cli["missing"] and
       model["build"]["origin"] == cli["origin"] == "SIMULATED",
       f"the runs used and the errors missing are `daq model build`'s: {model['build']['used']} vs {cli['used']}")
    cmap = json.loads(subprocess.run([DAQ, "model", "map", os.path.join(TMP, "model.json"), "--json"],
                                     capture_output=True, text=True, check=True).stdout)
    ok(model["map"] is not None and model["map"]["grid"] == cmap["grid"] and
       abs(model["map"]["summary"]["max_norm_um"] - cmap["summary"]["max_norm_um"]) < 1e-9 and
       model["map"]["summary"]["max_norm_um"] > 1,
       f"the map's summary is `daq model map --json`'s: {model['map'] and model['map']['summary']} vs {cmap['summary']}")
    want = {c["error"]: page_checks.fixed(c['max_norm_um'], 2) for c in cmap["contributions"]}
    shown = b.wait("const r = [...document.querySelectorAll('#model-table tbody tr')]; return r.length === 21 && "
                   "Object.fromEntries(r.map(x => [x.dataset.error, [...x.cells].map(c => c.textContent)]));",
                   timeout_s=60, what="the model's 21 errors on the page")
    measured = [e for e in want if e not in cli["missing"]]
    ok(measured and all(shown[e][3] == want[e] for e in measured) and len(want) == 21,
       f"each measured error's contribution as `daq model map` ranks it: E_XX {shown['E_XX']} vs {want['E_XX']}")
    # An error not measured has no number (the model takes it as zero: a 0.00 would read as a
    # measurement): a dash in both value columns, "not measured", and the note under the table.
    ok(all(shown[e][2:] == ["not measured", "—", "—"] for e in cli["missing"]) and len(cli["missing"]) == 16,
       f"each error not measured shows a dash, no number: {shown['E_BX']}")
    ok(shown["E_XX"][1] == ", ".join(map(str, cli["used"]["E_XX"])) and shown["E_XX"][2] == "measured" and
       shown["E_BX"][1] == "—", f"measured errors with their runs: {shown['E_XX']} {shown['E_BX']}")
    note = b.js("const n = document.getElementById('model-note'); return !n.hidden && n.textContent;")
    ok(note and note.startswith("— not measured") and "as zero" in note, f"the note says what the dash means: {note!r}")
    state = b.js("return document.getElementById('model-state').textContent;")
    ok(state == f"Partial model: {len(cli['missing'])} of 21 errors not measured yet, taken as zero "
       "(as `daq model build --allow-missing`).", f"the page says the model is partial: {state!r}")
    painted = b.wait("const c = document.getElementById('model-map'); if (c.hidden) return false; "
                     "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0; "
                     "for (let i = 0; i < d.length; i += 4) if (d[i + 2] > 200 && d[i] < 120) n++; return n;",
                     timeout_s=30, what="the model's map drawn")
    ok(painted > 200, f"the map's error arrows are drawn ({painted} blue pixels)")
    b.js("document.getElementById('model-box').scrollIntoView();")
    page_checks.shot(b, SHOTS, "c03-model-1366x768.png")
    page_checks.fits_narrow(b, SHOTS, "c04-model-560.png", "the model's table and map fit 560 px")
    page_checks.no_script_error(b)
