#!/usr/bin/env python3
"""The operator's page shows what a stored run is (issue 29 with 26), driven in headless Chromium
against `daq serve -c` (NOT --simulate) with `daq sim`'s twins in another process, on a database
that also holds a simulated demo run, its replay and a suspect copy of that replay:

1. a run measured with the twins shows SIMULATED on the Run view from the run's stored origin
   (while it runs and once it ended), with the stored text, the same as /api/runs/N says;
2. any stored run's results open from the list: the replay says SIMULATED, REPLAYED; the suspect
   run names its suspect stops by target and the compensation table is refused as
   `daq compensate` refuses it;
3. the result values are the rows the terminal prints (`daq show N`: the same symbols, order and
   numbers), the deviation at each target is plotted for every stored stop;
4. the compensation table of a finished linear run is the file `daq compensate` writes with the
   command the page names (byte for byte), with its meaning and sign statement, SIMULATED said.

Usage: operator_page_results_test.py DAQ_BINARY ARTEFACT_DIR
"""
import json
import os
import re
import shlex
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok, post  # noqa: E402
from webdriver import Browser  # noqa: E402

DAQ, SHOTS = os.path.abspath(sys.argv[1]), sys.argv[2]
os.makedirs(SHOTS, exist_ok=True)
TMP = tempfile.mkdtemp(prefix="operator-page-results-")
DB = os.path.join(TMP, "runs.sqlite")
CAPTURE = os.path.join(TMP, "demo.cdq")
WAIT_S = 60  # generous: a 2-core machine under ctest -j3


def daq(*args):
    r = subprocess.run([DAQ, *args], capture_output=True, text=True, cwd=TMP)
    if r.returncode != 0:
        raise AssertionError(f"daq {' '.join(args)} failed ({r.returncode}): {r.stderr[-2000:]}")
    return r


def get(url):
    with urllib.request.urlopen(url, timeout=30) as r:
        return json.load(r)


def shot(b, name):
    page_checks.shot(b, SHOTS, name)


def terminal_rows(run):
    """(symbol, value, description) of the result block `daq show RUN` prints."""
    rows, inside = [], False
    for line in daq("show", str(run), "--db", DB).stdout.splitlines():
        if re.match(r"\s+\d+ targets, ", line):
            inside = True
            continue
        if inside and "verdict" in line:
            break
        m = re.match(r"^\s+(\S+)\s+(-?\d+\.\d{3}) um\s{3}(.*)$", line) if inside else None
        if m:
            rows.append([m.group(1), m.group(2), m.group(3).strip()])
    return rows


# --- the database: a simulated demo run, its replay, and a suspect copy of the replay ----------
daq("demo", "--linear-only", "--quiet", "--db", DB, "--capture", CAPTURE)  # run 1
daq("replay", CAPTURE, "--db", DB)  # run 2: SIMULATED, REPLAYED
daq("replay", CAPTURE, "--db", DB)  # run 3: made suspect (one stop 5 um off), as report_pages_test
con = sqlite3.connect(DB)
con.execute("UPDATE captured_targets SET deviation_um = deviation_um + 5 WHERE run_id = 3 AND "
            "run_number = 2 AND direction = '+' AND target_index = 3")
con.execute("UPDATE runs SET quality = NULL, quality_note = '' WHERE id = 3")
con.commit()
con.close()

# The twins in their own process (daq sim), the service on its configuration: no --simulate.
sim_log = open(os.path.join(TMP, "sim.log"), "w+")
sim = subprocess.Popen([DAQ, "sim", "--speed", "2", "--runs", "2", "--targets", "2", "-o", "sim.toml", "--db", DB],
                       stdout=sim_log, stderr=subprocess.STDOUT, cwd=TMP)
serve = None
b = None
try:
    deadline = time.time() + WAIT_S
    while not (os.path.exists(os.path.join(TMP, "sim.toml")) and "devices in" in page_checks.log_tail(TMP, "sim.log")):
        if sim.poll() is not None or time.time() > deadline:
            raise AssertionError("daq sim did not start: " + page_checks.log_tail(TMP, "sim.log"))
        time.sleep(0.1)
    serve, url = page_checks.start_service(DAQ, TMP, ["-c", os.path.join(TMP, "sim.toml"), "--db", DB])
    b = Browser(1366, 768)

    def wait(script, what, timeout_s=WAIT_S, explain=None):
        """b.wait, and on a time-out what the page showed and the service's and the twins' logs."""
        try:
            return b.wait(script, timeout_s=timeout_s, what=what, explain=explain or
                          "return JSON.stringify({view: window.caldaq.view, status: window.caldaq.page && "
                          "window.caldaq.page.status, head: document.getElementById('result-head').textContent, "
                          "origin: document.getElementById('run-origin').textContent, comp: window.caldaq.comp, "
                          "errors: window.__errors}).slice(0, 3000);")
        except AssertionError as e:
            raise AssertionError(f"{e}\n--- serve.log:\n{page_checks.log_tail(TMP)}\n--- sim.log:\n"
                                 f"{page_checks.log_tail(TMP, 'sim.log')}") from None

    # --- 1. the Run view: the run's stored origin while it runs and once it ended -------------
    b.get(url)
    wait("return window.caldaq.page && window.caldaq.page.status && window.caldaq.page.status.start.linear.ready;", "Start linear ready")
    ok(b.js("return document.getElementById('sim-badge').hidden;") and
       not b.js("return window.caldaq.page.status.simulated;"), "not --simulate: no SIMULATED shop badge")
    b.js("document.getElementById('start-linear').click();")
    run_id = wait("const s = window.caldaq.page.status; return s.running && s.run && s.run.id;", "the run to start")
    ok(run_id == 4, f"the run from the page is run 4: {run_id}")
    stored = get(url + f"api/runs/{run_id}")["origin"]
    # The instruments of one origin named together, its detail said once (it was repeated for
    # each instrument: five lines above the fold).
    ok(stored["label"] == "SIMULATED" and re.match(r"[a-z0-9_-]+((, | and )[a-z0-9_-]+)* simulated \(", stored["text"]) and "laser" in stored["text"]
       and stored["text"].count("twin of") == 1,
       f"stored with its instruments as the twins they are, the twins named together: {stored['label']}: {stored['text'][:120]}")
    BANNER = ("const g = document.getElementById('run-origin'); return !g.hidden && "
              "[g.querySelector('.word').textContent, g.textContent, parseFloat(getComputedStyle(g.querySelector('.word')).fontSize)];")
    word, text, size = wait(BANNER, "the run's origin on the Run view")
    ok(word == "SIMULATED" and text == f"SIMULATED Run {run_id}, as stored: {stored['text']}",
       f"while it runs, the Run view says SIMULATED with the stored origin: {text[:120]!r}")
    ok(size >= 30, f"prominently: {size:.0f} px")
    shot(b, "r01-run-origin-running-1366x768.png")
    # Its end, whatever it is (a stop the trigger misses under load makes it incomplete): the
    # origin is the run's, not its outcome's.
    wait(f"const l = window.caldaq.page.status.last; return l && l.run === {run_id};", "the run's end", timeout_s=120)
    b.js("document.getElementById('tab-run').click();")
    wait("return document.getElementById('big').classList.contains('ended');", "the Run view showing the ended run")
    word, text, _ = b.js(BANNER)
    ok(word == "SIMULATED" and text == f"SIMULATED Run {run_id}, as stored: {stored['text']}",
       f"once it ended, still from the stored origin: {text[:100]!r}")
    ok(b.js("return window.caldaq.page.status.last.origin.label;") == "SIMULATED", "the status carries it")
    shot(b, "r02-run-origin-ended-1366x768.png")

    # --- 2. the results: any stored run from the list ----------------------------------------
    b.js("document.getElementById('tab-results').click();")
    wait(f"return document.getElementById('result-head').textContent.startsWith('Run {run_id}:') && "
         "document.querySelectorAll('#runs button[data-show-run]').length === 4;", "the results of run 4 and the list")
    origins = b.js("return [...document.querySelectorAll('#runs tbody tr')].map(r => [r.dataset.run, r.cells[5].textContent]);")
    ok(origins == [["4", "SIMULATED"], ["3", "SIMULATED, REPLAYED"], ["2", "SIMULATED, REPLAYED"], ["1", "SIMULATED"]],
       f"each stored run's origin in the list: {origins}")

    # The suspect run: its stops named by target, its compensation table refused.
    b.js("document.querySelector('#runs button[data-show-run=\"3\"]').click();")
    wait("return document.getElementById('result-head').textContent.startsWith('Run 3:') && "
         "!!document.getElementById('quality-suspect');", "run 3's results")
    suspect = b.js("return document.getElementById('quality-suspect').textContent;")
    doc3 = get(url + "api/runs/3")
    # The service's sentence says "um" (for terminals); the page says µm.
    micro = lambda t: re.sub(r"(\d) um\b", r"\1 µm", t)  # noqa: E731
    ok(doc3["quality"]["state"] == "suspect" and "SUSPECT STOPS: " in suspect and
       all(f"target {s['target_index'] + 1}: {micro(s['reason'])}" in suspect for s in doc3["quality"]["suspect_stops"]),
       f"run 3 suspect, each suspect stop named by its target: {suspect[:200]!r}")
    ok(" um" in doc3["quality"]["summary"] and not re.search(r"\d um\b", suspect) and re.search(r"\d µm", suspect),
       f"the page writes µm where the service's sentence says um: {suspect[:160]!r}")
    ok(any(s["target_index"] == 3 and s["run"] == 2 for s in doc3["quality"]["suspect_stops"]) and "target 4: run 2 " in suspect,
       "the stop made 5 µm off among them (run 2 up at target 4)")
    b.js("document.getElementById('comp-show').click();")
    c = wait("const c = window.caldaq.comp; return c && c.run === 3 && c.n >= 1 && c;", "the answer for run 3's table")
    refusal = b.js("return document.getElementById('comp-error').textContent;")
    cli = subprocess.run([DAQ, "compensate", "--run", "3", "--start-mm", "0", "--interval-mm", "50", "--points", "11",
                          "--db", DB], capture_output=True, text=True)
    # The same refusal as the command's, but what to do said for the page, not its options.
    page_why = refusal[len("No table: "):].split("measure the test again")[0].strip()
    ok(not c["ok"] and c["status"] == 409 and refusal.startswith("No table: ") and "--accept-suspect" not in refusal
       and "measure the test again (Run view, Start)" in refusal
       and cli.returncode != 0 and len(page_why) > 40 and page_why in cli.stderr and "--accept-suspect" in cli.stderr,
       f"its compensation table refused as the command refuses it, in the page's words: {refusal[:160]!r}")
    ok(b.js("return document.getElementById('comp-table').rows.length;") == 0, "and no table shown")
    shot(b, "r03-suspect-run-1366x768.png")

    # The replay: REPLAYED, the terminal's rows, every stop plotted.
    b.js("document.querySelector('#runs button[data-show-run=\"2\"]').click();")
    wait("return document.getElementById('result-head').textContent.startsWith('Run 2:') && "
         "window.caldaq.resultPlot && window.caldaq.resultPlot.run === 2;", "run 2's results")
    banner = b.js("const g = document.getElementById('result-origin'); return g.hidden ? null : g.textContent;")
    ok(banner and banner.startswith("SIMULATED, REPLAYED") and "laser" in banner
       and banner.count(" replay (capture ") == 1,
       f"the replay says SIMULATED, REPLAYED from its stored origin: {banner and banner[:90]!r}")
    shown_rows = b.js("return [...document.querySelectorAll('#result-values tbody tr')].map(r => "
                      "[r.cells[0].textContent, r.cells[1].textContent, r.cells[2].textContent]);")
    printed = terminal_rows(2)
    ok(len(printed) >= 10 and [[s, v + " µm", d] for s, v, d in printed] == shown_rows,
       f"the values are the terminal's rows, in its order: {[r[0] for r in shown_rows]}")
    doc2 = get(url + "api/runs/2")
    plot = b.js("const c = document.getElementById('result-plot'); return [window.caldaq.resultPlot.points, "
                "!document.getElementById('result-plot-box').hidden, c.getBoundingClientRect().width];")
    ok(plot[0] == len(doc2["stops"]) == doc2["targets"] == 110 and plot[1] and plot[2] > 300,
       f"every stored stop plotted against its target: {plot}")
    ok(b.js("const r = document.getElementById('result-plot').getBoundingClientRect(); return r.bottom <= window.innerHeight;"),
       "the plot above the fold on 1366 x 768")
    shot(b, "r04-replayed-results-1366x768.png")

    # --- 4. its compensation table: what `daq compensate` writes ----------------------------
    b.js("document.getElementById('comp-format').value = 'fanuc';")
    b.js("document.getElementById('comp-show').click();")
    c = wait("const c = window.caldaq.comp; return c && c.run === 2 && c.ok && c.format === 'fanuc' && c;", "run 2's table")
    page = b.js("""const g = id => document.getElementById(id);
        return {meaning: g('comp-meaning').textContent, command: g('comp-command').textContent,
                text: g('comp-text').textContent, origin: g('comp-origin').hidden ? null : g('comp-origin').textContent,
                head: [...g('comp-table').tHead.rows[0].cells].map(c => c.textContent),
                rows: g('comp-table').tBodies[0].rows.length, predicted: g('comp-predicted').textContent,
                download: g('comp-download').hidden ? null : g('comp-download').download};""")
    m = re.search(r"from the command line \(it also stores it for daq verify\): (daq compensate .*)$", page["command"])
    ok(m and "--run 2 " in m.group(1) and m.group(1).endswith("-f fanuc"), f"the command named: {page['command']!r}")
    written = os.path.join(TMP, "fanuc.nc")
    cli = subprocess.run([DAQ, *shlex.split(m.group(1))[1:], "--db", DB, "-o", written], capture_output=True, text=True)
    ok(cli.returncode == 0, f"that command runs: {cli.stderr[-300:]}")
    ok(open(written, encoding="utf-8").read() == page["text"], "the page's table is the file it writes, byte for byte")
    ok(page["meaning"] in cli.stderr and "the values are the correction" in page["meaning"] and "FANUC" in page["meaning"],
       f"with the meaning and sign statement the command prints: {page['meaning'][:120]!r}")
    ok(page["origin"] and page["origin"].startswith("SIMULATED, REPLAYED") and "not a measurement of a real machine" in page["origin"],
       f"and SIMULATED said with the table: {page['origin']!r}")
    ok(page["head"] == ["Position (mm)", "Correction (mm, at the position)"] and page["rows"] == 11, f"its values: {page['head']}, {page['rows']} rows")
    ok(re.match(r"Predicted: largest mean deviation \d+\.\d{3} µm before, \d+\.\d{3} µm left", page["predicted"]),
       f"what it is predicted to leave: {page['predicted']!r}")
    ok(page["download"] == "run-2-X-fanuc.nc", f"to download: {page['download']}")
    # Stored from the page as the command stores it (the command above stored one too).
    def stored():
        with sqlite3.connect(DB) as c:
            return c.execute("SELECT id, format, json FROM compensations WHERE source_run_id = 2 ORDER BY id").fetchall()
    before = stored()
    ok(len(before) == 1 and b.js("return !document.getElementById('comp-store').hidden;"),
       f"the command stored one; the page offers to store it: {len(before)}")
    b.js("document.getElementById('comp-store').click();")
    said = wait("const t = document.getElementById('comp-stored').textContent; return /Stored as compensation/.test(t) && t;",
                "the table stored from the page")
    after = stored()
    ok(len(after) == 2 and after[1][1] == "fanuc" and said.startswith(f"Stored as compensation {after[1][0]} (fanuc)"),
       f"stored with the run from the page: {said!r}")
    mine, cmd = json.loads(after[1][2]), json.loads(after[0][2])
    ok(mine["text"] == page["text"] and mine["table"] == cmd["table"] and mine["predicted"] == cmd["predicted"]
       and mine["origin"] == cmd["origin"], "the same record `daq compensate --run` stores (text, table, prediction, origin)")
    status, body = post(url + "api/compensation", {"run": 2, "format": "csv", "store": "yes"})
    ok(status == 400 and "store" in body["error"], f"store must be true or false: {status} {body}")
    b.js("document.getElementById('comp').scrollIntoView();")
    shot(b, "r05-compensation-fanuc-1366x768.png")

    # The API: a bad body 400, an unknown format 400 naming the known ones, no run 404.
    status, body = post(url + "api/compensation", {"run": 2})
    ok(status == 400 and "format" in body["error"], f"a body without a format: {status} {body}")
    status, body = post(url + "api/compensation", {"run": 2, "format": "excel"})
    ok(status == 400 and "known: csv" in body["error"], f"an unknown format: {status} {body['error'][:80]}")
    status, body = post(url + "api/compensation", {"run": 99, "format": "csv"})
    ok(status == 404, f"no such run: {status} {body}")

    # --- 5. the diagnostic limits of the circle's plane in the set-up form --------------------
    b.js("document.getElementById('tab-setup').click();")
    wait("return !!document.querySelector('[data-diagnostics=\"XY\"]') && "
         "document.getElementById('setup-status').className === 'ok';", "the set-up form with the XY diagnostics")
    diag = b.js("""const d = document.querySelector('[data-diagnostics="XY"]');
        const f = k => d.querySelector(`[data-field="tolerances.XY.diagnostics.${k}"]`);
        return {open: d.open, summary: d.querySelector('summary').textContent,
                fields: [...d.querySelectorAll('[data-field]')].map(x => x.dataset.field.split('.').pop()),
                backlash: [f('backlash_X').querySelector('label').textContent, f('backlash_X').querySelector('input').value,
                           f('backlash_X').querySelector('.u').textContent],
                squareness: [f('squareness').querySelector('label').textContent, f('squareness').querySelector('input').value,
                             f('squareness').querySelector('.u').textContent]};""")
    ok(diag["open"] and "2 given" in diag["summary"], f"the plane's diagnostic limits shown, open: {diag['summary']!r}")
    ok(diag["backlash"] == ["Backlash X", "3", "µm"] and diag["squareness"] == ["Squareness", "30", "µm/m"],
       f"each in words with its unit and the set-up's value: {diag['backlash']} {diag['squareness']}")
    ok({"radius_error", "servo_mismatch", "vibration", "backlash_Y", "stick_slip_X", "cyclic_Y"} <= set(diag["fields"]),
       f"every diagnostic a limit can be given for: {diag['fields']}")
    ok(b.js(page_checks.TYPE, "tolerances.XY.diagnostics.backlash_X", "-1") == "ok", "typed: backlash X limit -1")
    bad = wait("const f = document.querySelector('[data-field=\"tolerances.XY.diagnostics.backlash_X\"]'); "
               "return f.classList.contains('bad') && f.querySelector('.err').textContent;", "the refusal at the field")
    ok("backlash_X" in bad or "limit" in bad, f"a negative limit refused at its field: {bad!r}")
    ok(b.js(page_checks.TYPE, "tolerances.XY.diagnostics.backlash_X", "2") == "ok", "typed: backlash X limit 2")
    toml = wait("return document.getElementById('setup-status').className === 'ok' && "
                "/backlash_X = 2(\\.0)?\\b/.test(window.caldaq.toml || '') && window.caldaq.toml;", "the limit in the TOML")
    ok(re.search(r"\[tolerances\.XY\.diagnostics\][^\[]*backlash_X = 2(\.0)?\b", toml), "under [tolerances.XY.diagnostics]")
    b.js("document.getElementById('tab-run').click();")
    pending = wait("const t = document.getElementById('pending-edits'); return !t.hidden && t.textContent;", "the edit named")
    ok("Backlash X (XY) 3 → 2" in pending, f"the unapplied limit named on the Run view: {pending!r}")
    b.js("document.getElementById('tab-setup').click();")
    b.js("document.querySelector('[data-diagnostics=\"XY\"]').scrollIntoView();")
    shot(b, "r07-diagnostic-limits-1366x768.png")
    b.js("document.getElementById('apply').click();")
    wait("return /applied/i.test(document.getElementById('apply-result').textContent);", "the set-up applied")
    applied = get(url + "api/setup")["setup"]["tolerances"]["XY"]["diagnostics"]
    ok(applied == {"squareness": 30, "backlash_X": 2}, f"applied: the service's set-up has the limit: {applied}")

    b.set_size(560, 900)
    time.sleep(0.5)
    b.js("document.getElementById('tab-results').click();")
    b.js("window.scrollTo(0, 0);")
    wide = b.js("return [...document.querySelectorAll('#view-results *')].filter(e => e.getBoundingClientRect().right > "
                "window.innerWidth + 1).slice(0, 5).map(e => e.tagName + '#' + e.id + '.' + e.className + ' ' + "
                "Math.round(e.getBoundingClientRect().right));")
    ok(b.js("return document.documentElement.scrollWidth - window.innerWidth;") <= 0, f"560 px: the results fit {wide}")
    shot(b, "r06-results-560px.png")
    ok(b.js("return JSON.stringify(window.__errors);") == "[]", "no script error on the page")
    print(f"operator page results: {page_checks.passes} checks passed; screenshots in {SHOTS}")
finally:
    if b:
        b.close()
    if serve:
        page_checks.stop_service(serve)
    page_checks.stop_service(sim)
    shutil.rmtree(TMP, ignore_errors=True)
