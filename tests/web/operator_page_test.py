#!/usr/bin/env python3
"""The operator's page end to end (issue 16): headless Chromium (WebDriver) drives the page of
`daq serve --simulate` (the SIMULATED shop in the same process) as a new user would:

1. idle: every instrument streaming, air, pressure, humidity, n and material shown live;
2. set-up: a linear test typed into the form, a wrong value shown at its field as it is typed;
3. the part program shown and downloaded in a dialect, and the set-up saved as TOML: `daq gcode`
   on that TOML writes exactly the downloaded program;
4. a dead device (the air station's port gone): dashes, its state and reason, Start refused;
5. the linear test run from the page: the indicator passes through moving, settling or stable,
   and captured; at a stop the big number is a deviation of a few um; the stops table fills;
6. the results with their verdict and the report links (HTML and PDF served);
7. a ballbar test: the live polar trace, then its results;
8. Stop asks for confirmation; the page reflows at 600 px.

Screenshots of every phase are written to the artefact directory (in the build tree) for a
person to look at. The shop runs 10 times faster than real time while the set-up is typed and a
run is stopped, 20 times during the linear run (the page still shows every phase) and the
ballbar run (POST /api/simulation/speed; the simulated time line, and so every
reading, is the same at any pace). Usage: operator_page_test.py DAQ_BINARY ARTEFACT_DIR
"""
import concurrent.futures
import json
import math
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
TMP = tempfile.mkdtemp(prefix="operator-page-")
SPEED = 100


def shot(b, name):
    page_checks.shot(b, SHOTS, name)


def fetch(url, timeout=60):
    with urllib.request.urlopen(url, timeout=timeout) as r:
        return r.status, r.headers.get("Content-Type", ""), r.read()


# Sets a form field as typing would (the page checks the set-up on each input event).
TYPE = """const [key, value] = arguments;
  const input = [...document.querySelectorAll('[data-key]')].find(i => i.dataset.key === key);
  if (!input) return 'no field ' + key;
  if (input.type === 'checkbox') input.checked = value; else input.value = value;
  input.dispatchEvent(new Event('input', {bubbles: true}));
  input.dispatchEvent(new Event('change', {bubbles: true}));
  return 'ok';"""
FIELD_ERROR = """const box = [...document.querySelectorAll('[data-field]')].find(b => b.dataset.field === arguments[0]);
  return box && box.classList.contains('bad') ? box.querySelector('.err').textContent : null;"""
WHY = "return JSON.stringify([window.caldaq.page.status.start, window.caldaq.page.devices.devices]);"
VALID = "return document.getElementById('setup-status').className === 'ok';"
# Text that looks like a strings.en.json key shown raw (a missing string).
RAW_KEYS = r"""const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  const raw = [];
  for (let n; (n = walker.nextNode());) {
    const t = n.textContent.trim();
    if (/^(tab|f|setup|device|env|results|runs|table|start|motion|reading|progress|api|stop|chart|polar|circle|sim|conn)\.[A-Za-z_. ]+$/.test(t)) raw.push(t);
  }
  return raw;"""


def no_raw_keys(b, where):
    raw = b.js(RAW_KEYS)
    ok(not raw, f"{where}: every text comes from the language file (raw keys: {raw})")


def set_field(b, key, value):
    ok(b.js(TYPE, key, value) == "ok", f"typed {key} = {value!r}")


def wait_valid(b):
    b.wait(VALID, timeout_s=45, what="the set-up to be valid")


def page_state(b):
    return b.js("return window.caldaq.page;")


def simulation_speed(url, speed):
    status, body = post(url + "api/simulation/speed", {"speed": speed})
    ok(status == 200 and body["speed"] == speed, f"the SIMULATED shop now runs {speed}x: {body}")


# Chromium starts (about a second) while the service does.
browser = concurrent.futures.ThreadPoolExecutor(max_workers=1).submit(Browser, 1280, 1400)
serve_log = open(os.path.join(TMP, "serve.log"), "w+")
serve = subprocess.Popen([DAQ, "serve", "--simulate", "--speed", str(SPEED), "--port", "0",
                          "--db", os.path.join(TMP, "runs.sqlite"),
                          "--capture-dir", os.path.join(TMP, "captures"),
                          # the dead devices of part 4, allowed as an operator would
                          "--allow-device", f"{TMP}/no-such-*", "--allow-device", "127.0.0.1:1"],
                         stdout=serve_log, stderr=subprocess.STDOUT)
try:
    url = None
    for _ in range(200):
        serve_log.seek(0)
        m = re.search(r"daq serve: (http://[0-9.]+:[0-9]+/)", serve_log.read())
        if m:
            url = m.group(1)
            break
        if serve.poll() is not None:
            break
        time.sleep(0.02)
    serve_log.seek(0)
    ok(url, "daq serve --simulate started: " + (url or serve_log.read()))

    with browser.result() as b:
        # --- 1. idle ------------------------------------------------------------------------
        b.get(url)
        b.wait("return window.caldaq && window.caldaq.page && "
               "window.caldaq.page.status.start.linear.ready;", timeout_s=30,
               what="the instruments to stream (Start linear ready)")
        b.wait("return document.getElementById('env-n').textContent !== '—';", timeout_s=30,
               what="the refractive index while idle")
        env = b.js("""const g = id => document.getElementById(id).textContent;
            return {air: g('env-air'), p: g('env-p'), rh: g('env-rh'), n: g('env-n'),
                    material: g('env-material'), factor: g('env-factor')};""")
        print(json.dumps(env, ensure_ascii=False))
        # The simulated shop: air 20.6 degC, 1006.5 hPa, 42 %RH (Ciddor n - 1 = 2.69e-4),
        # the machine at 21.5 degC.
        ok(abs(float(env["air"].split()[0]) - 20.6) < 0.3, f"idle: air {env['air']}")
        ok(abs(float(env["p"].split()[0]) - 1006.5) < 2, f"idle: pressure {env['p']}")
        ok(abs(float(env["n"]) - 1.000269) < 5e-6, f"idle: n {env['n']}")
        ok(abs(float(env["material"].split()[0]) - 21.5) < 0.1, f"idle: material {env['material']}")
        src = b.js("return document.getElementById('env-source').textContent;")
        ok(src == "Air values from air (PTU300)", f"idle: the air values' source is named: {src!r}")
        states = b.js("return [...document.querySelectorAll('#devices li')].map(l => l.dataset.state);")
        # The shop's indicator and level (the component tests' probes) stream too.
        ok(states.count("streaming") == 5 and "open" in states,
           f"idle: laser, air, material, indicator, level streaming, the ballbar's port open: {states}")
        # Each instrument's line says what it is: its role in words, the product and serial
        # number where the driver names them (the shop's configuration), then its connection;
        # not the driver's key ("gauge · serial ..." said nothing of a ballbar or an indicator).
        details = b.js("return Object.fromEntries([...document.querySelectorAll('#devices li')]"
                       ".map(l => [l.dataset.device, l.querySelector('.dev-detail').textContent]));")
        said = {"laser": "laser · IDS3010 SIM-IDS-0001 · tcp 127.0.0.1:", "air": "air station · PTU300 SIM-PTU-0001 · serial ",
                "material": "thermometer · SIM-TH-0001 · serial ", "ballbar": "ballbar · SIM-BB-0001 · serial ",
                "indicator": "indicator · serial ", "level": "electronic level · serial "}
        ok(sorted(details) == sorted(said) and all(details[k].startswith(v) for k, v in said.items()),
           f"idle: each instrument by its role and device: {details}")
        ok(b.js("return document.getElementById('reading').textContent;") == "—",
           "idle: no run, no number")
        no_raw_keys(b, "idle")
        shot(b, "01-idle.png")

        # --- 2. set-up ----------------------------------------------------------------------
        b.js("document.getElementById('tab-setup').click();")
        b.wait("return !!document.querySelector('[data-key=\"test.linear.runs\"]');",
               what="the set-up form")
        wait_valid(b)
        for key, value in (("test.linear.first_mm", "0"), ("test.linear.last_mm", "100"),
                           ("test.linear.interval_mm", "50"), ("test.linear.random_fraction", ""),
                           ("test.linear.dwell_s", "4"), ("test.linear.runs", "0")):
            set_field(b, key, value)
        err = b.wait(FIELD_ERROR.replace("arguments[0]", "'test.linear.runs'"), timeout_s=30,
                     what="the runs field's error")
        ok("1 .. 1000" in err, f"validation as typed: runs = 0 -> '{err}'")
        set_field(b, "test.linear.feed_mm_per_min", "-5")
        err = b.wait(FIELD_ERROR.replace("arguments[0]", "'test.linear.feed_mm_per_min'"),
                     timeout_s=30, what="the feed field's error")
        ok("-5" in err, f"a second problem shown at once: feed = -5 -> '{err}'")
        ok(b.js("return document.getElementById('apply').disabled;"),
           "Use this set-up is disabled while there are problems")
        no_raw_keys(b, "set-up")
        shot(b, "02-setup-problems.png")
        set_field(b, "test.linear.runs", "2")
        set_field(b, "test.linear.feed_mm_per_min", "6000")
        wait_valid(b)
        # The whole form, instruments included (generated from the drivers' settings).
        ok(b.js("return document.querySelectorAll('.device-card').length;") == 6,
           "the instrument form has the six configured devices (the indicator and the level too)")
        # Each card's fields are the common keys and its driver's option table, as the drivers'
        # registry gives them (`daq devices --options --json`, run here as the reference).
        table = json.loads(subprocess.run([DAQ, "devices", "--options", "--json"],
                                          capture_output=True, text=True, check=True).stdout)
        common = [o["name"] for o in table["common"]]
        options = {d["name"]: [o["name"] for o in d["options"]] for d in table["drivers"]}
        cards = b.js("""return [...document.querySelectorAll('.device-card')].map(c => ({
            driver: c.querySelector('[data-device-driver]').value,
            choices: [...c.querySelectorAll('[data-device-driver] option')].map(o => o.value),
            fields: [...c.querySelectorAll('[data-option]')].map(f => f.dataset.option)}));""")
        ok(all(c["fields"] == common + options[c["driver"]] for c in cards),
           "each instrument card: the common keys and its driver's option table "
           f"{[(c['driver'], c['fields'][len(common):]) for c in cards]}")
        ok(all(c["choices"] == list(options) for c in cards),
           f"the driver choices are the registry's drivers: {cards[0]['choices']}")
        # Another driver chosen: the card's fields follow its table (then back).
        other = next(n for n in options if options[n] != options[cards[0]["driver"]])
        switch = """const c = document.querySelectorAll('.device-card')[0], s = c.querySelector('[data-device-driver]');
            s.value = arguments[0]; s.dispatchEvent(new Event('change', {bubbles: true}));
            return [...c.querySelectorAll('[data-option]')].map(f => f.dataset.option);"""
        ok(b.js(switch, other) == common + options[other],
           f"another driver ({other}) chosen: the card shows its options {options[other]}")
        b.js(switch, cards[0]["driver"])
        wait_valid(b)
        b.set_size(1280, 3400)
        time.sleep(0.3)
        shot(b, "02b-setup-whole-form.png")
        b.set_size(1280, 1400)
        ok(b.js(FIELD_ERROR, "test.linear.runs") is None, "the runs field is clear once fixed")

        # --- 3. part program and TOML -------------------------------------------------------
        b.js("document.getElementById('program-dialect').value = 'heidenhain';"
             "document.getElementById('program-show').click();")
        b.wait("return document.getElementById('program-text').textContent.includes('END PGM');",
               what="the Heidenhain program")
        fetch_blob = """const done = arguments[arguments.length - 1];
            fetch(document.getElementById(arguments[0]).href).then(r => r.text()).then(done);"""
        program = b.js_async(fetch_blob, "program-download")
        toml = b.js_async(fetch_blob, "toml-download")
        name = b.js("return document.getElementById('program-download').download;")
        ok(program == b.js("return document.getElementById('program-text').textContent;"),
           f"the downloaded program ({name}) is the one shown")
        path = os.path.join(TMP, "setup.toml")
        with open(path, "w") as f:
            f.write(toml)
        gcode = subprocess.run([DAQ, "gcode", "linear", "-c", path, "-d", "heidenhain"],
                               capture_output=True, text=True)
        ok(gcode.returncode == 0, f"daq gcode accepts the saved TOML: {gcode.stderr}")
        ok(gcode.stdout == program, "the page's program is byte for byte `daq gcode` of the "
           f"saved set-up ({len(program)} bytes, {program.count(chr(10))} lines)")
        ok(re.search(r"^last_mm = 100(\.0)?$", toml, re.M) and re.search(r"^runs = 2$", toml, re.M),
           "the TOML holds what was typed")
        shot(b, "03-program.png")
        b.js("document.getElementById('apply').click();")
        b.wait("return /Applied/.test(document.getElementById('apply-result').textContent);",
               what="the set-up to be applied")

        # --- 3b. a set-up applied elsewhere while the operator types ----------------------------
        # The page reloads its form when another client applies a set-up; it must never wipe what
        # the operator is typing (CI once lost the dead-device edits below to such a reload).
        set_field(b, "test.linear.dwell_s", "3")
        status, other = post(url + "api/setup/apply", {"setup": b.js("return window.caldaq.base;")})
        ok(status == 200, f"a set-up applied from another client while the operator types: "
           f"version {other.get('version')}")
        b.wait(f"return window.caldaq.page.status.setup.version === {other.get('version')};",
               what="the page to see the set-up applied elsewhere")
        time.sleep(1.0)  # ten status messages: a reload, if any, would have come by now
        dwell = b.js("""return [...document.querySelectorAll('[data-key]')]
            .find(i => i.dataset.key === 'test.linear.dwell_s').value;""")
        ok(dwell == "3", f"what the operator typed is kept when a set-up is applied elsewhere: {dwell!r}")
        wait_valid(b)
        b.js("document.getElementById('apply').click();")
        b.wait("return /Applied/.test(document.getElementById('apply-result').textContent) && "
               "window.caldaq.base.test.linear.dwell_s == 3;", what="the typed set-up applied",
               explain="return document.getElementById('apply-result').textContent;")

        # --- 4. dead devices -------------------------------------------------------------------
        # The air station's, the laser's and the ballbar's ports gone (the ballbar run on
        # a vanished port showed 0.00 um and "running" for a minute). The laser too: its
        # environment unit reports air as well, which the panel (and a run) would use.
        transport = """return [...document.querySelectorAll('[data-key]')]
            .find(i => i.dataset.key === arguments[0]).value;"""
        good_air = b.js(transport, "devices.air.transport")
        good_bar = b.js(transport, "devices.ballbar.transport")
        good_laser = b.js(transport, "devices.laser.transport")
        set_field(b, "devices.air.transport", f"serial {TMP}/no-such-port 4800 8N1")
        set_field(b, "devices.ballbar.transport", f"serial {TMP}/no-such-bar 115200 8N1")
        set_field(b, "devices.laser.transport", "tcp 127.0.0.1:1")
        wait_valid(b)
        b.js("document.getElementById('apply').click();")
        b.wait("return /Applied/.test(document.getElementById('apply-result').textContent) && "
               "window.caldaq.page.devices.devices.find(d => d.id === 'air').transport.includes('no-such-port');",
               what="the set-up with a dead air station",
               explain="return [document.getElementById('apply-result').textContent, "
                       "JSON.stringify(window.caldaq.page.devices.devices.map(d => [d.id, d.transport, d.state]))];")
        b.js("document.getElementById('tab-run').click();")
        b.wait("const d = window.caldaq.page.devices.devices.find(d => d.id === 'air');"
               "return d.state === 'reconnecting' || d.state === 'failed';", timeout_s=30,
               what="the air station reported as reconnecting")
        b.wait("return document.getElementById('env-air').textContent === '—';",
               what="the air temperature shown as dashes")
        b.wait("const d = window.caldaq.page.devices.devices.find(d => d.id === 'ballbar');"
               "return d.state === 'reconnecting' || d.state === 'failed';", timeout_s=30,
               what="the ballbar reported as reconnecting")
        dead = b.js("""const li = document.querySelector('#devices li[data-device=air]');
            return {state: li.dataset.state, text: li.textContent,
                    air: document.getElementById('env-air').textContent,
                    n: document.getElementById('env-n').textContent,
                    disabled: document.getElementById('start-linear').disabled,
                    circle_disabled: document.getElementById('start-circle').disabled,
                    bar: document.querySelector('#devices li[data-device=ballbar]').textContent,
                    bar_value: document.querySelector('#devices li[data-device=ballbar] .dev-values').textContent,
                    why: document.getElementById('start-why').textContent};""")
        print(json.dumps(dead, ensure_ascii=False))
        ok(dead["air"] == "—" and dead["n"] == "—",
           "dead air station: air and n are dashes, not the last values")
        ok("no-such-port" in dead["text"] and "No such file" in dead["text"],
           f"dead air station: its state and the reason shown ({dead['state']})")
        ok(dead["disabled"] and "no-such-port" in dead["why"] and "127.0.0.1:1" in dead["why"],
           f"Start linear refused naming both devices that are not ready: {dead['why']}")
        status, body = post(url + "api/runs/start", {"test": "linear"})
        ok(status == 409 and "air" in body["error"], f"the API refuses it too: {status} {body}")
        ok(dead["bar_value"] == "—" and "no-such-bar" in dead["bar"],
           f"dead ballbar: no value, its port and state shown: {dead['bar']}")
        ok(dead["circle_disabled"] and "no-such-bar" in dead["why"],
           "Start ballbar refused with the reason (not a run stuck on 0.00 µm)")
        status, body = post(url + "api/runs/start", {"test": "circle"})
        ok(status == 409 and "no-such-bar" in body["error"],
           f"the API refuses the ballbar test too: {status} {body}")
        no_raw_keys(b, "dead device")
        shot(b, "04-dead-devices.png")
        b.js("document.getElementById('tab-setup').click();")
        set_field(b, "devices.air.transport", good_air)
        set_field(b, "devices.ballbar.transport", good_bar)
        set_field(b, "devices.laser.transport", good_laser)
        wait_valid(b)
        b.js("document.getElementById('apply').click();")
        b.wait("return /Applied/.test(document.getElementById('apply-result').textContent);",
               what="the set-up with the air station's port again")
        b.js("document.getElementById('tab-run').click();")
        b.wait("return window.caldaq.page.status.start.linear.ready;", timeout_s=30,
               what="the air station back (Start ready)", explain=WHY)

        # --- 5. the linear test --------------------------------------------------------------
        status, body = post(url + "api/simulation/speed", {"speed": 0})
        ok(status == 400 and "1 to 100" in body["error"], f"speed 0 is refused: {status} {body}")
        # 20x: the page (10 updates/s) sees the shop every 2 s of simulated time, so each of the
        # 12 stops (1 s moving, 4 s standing) is seen moving and standing.
        simulation_speed(url, 20)
        # The first page state of each lit indicator, recorded in the page as the indicator
        # changes (a MutationObserver): this test's polls through WebDriver, slowed by the
        # screenshots, can miss a 1 s move on a loaded machine; the page itself does not.
        b.js("""window.__first = {};
            const snap = () => { const p = window.caldaq.page, r = p.run || {};
              const lit = [...document.querySelectorAll('#indicator span.on')].map(e => e.dataset.motion);
              const m = r.motion ? r.motion.state : null;
              if (!p.status.running || !m || lit.length !== 1 || lit[0] !== m || window.__first[m]) return;
              window.__first[m] = {motion: m, display: r.display || null,
                big: document.getElementById('reading').textContent,
                label: document.getElementById('reading-label').textContent,
                fits: document.getElementById('big').scrollWidth <= document.getElementById('big').clientWidth}; };
            new MutationObserver(snap).observe(document.getElementById('indicator'),
              {subtree: true, attributes: true, attributeFilter: ['class']});""")
        b.js("document.getElementById('start-linear').click();")
        b.wait("return window.caldaq.page.status.running;", what="the run to start")
        shots = {}
        at_stop = None
        deadline = time.time() + 120
        while time.time() < deadline:
            s = b.js("""const p = window.caldaq.page, r = p.run || {};
                return {running: p.status.running, last: p.status.last || null,
                        motion: r.motion ? r.motion.state : null, display: r.display || null,
                        captured: (r.stops || []).filter(x => !x.missed).map(x => x.deviation_um).pop(),
                        big: document.getElementById('reading').textContent,
                        label: document.getElementById('reading-label').textContent,
                        fits: document.getElementById('big').scrollWidth <= document.getElementById('big').clientWidth,
                        lit: [...document.querySelectorAll('#indicator span.on')].map(e => e.dataset.motion)};""")
            m = s["motion"]
            if s["running"] and m and m not in shots and s["lit"] == [m]:
                shot(b, {"moving": "05-moving.png", "settling": "06-settling.png",
                         "stable": "07-stable.png", "captured": "08-captured.png"}[m])
                shots[m] = s
            if s["running"] and m in ("stable", "captured") and s["display"] and at_stop is None:
                at_stop = s
            if not s["running"] and s["last"]:
                break
            time.sleep(0.02)
        seen = set(b.js("return [...window.caldaq.seen];"))
        print("indicator states seen:", sorted(seen))
        ok({"moving", "captured"} <= seen and (seen & {"settling", "stable"}),
           f"the indicator passed through moving, settling/stable and captured: {sorted(seen)}")
        last = b.js("return document.getElementById('last-stop').textContent;")
        t = re.search(r"settled in ([0-9.]+) s, stable ([0-9.]+) s", last)
        # The laser reads every 0.05 s of simulated time: a stop can be still from its first
        # reading in the window (settled in 0.00 s); it is stable for the trigger's 1.5 s.
        ok(t and float(t.group(1)) >= 0 and float(t.group(2)) >= 1.4,
           f"the last stop's timeline: stable for the trigger's dwell (1.5 s): '{last}'")
        ok(at_stop is not None, "a stop was seen on the page")
        d = at_stop["display"]
        value = float(at_stop["big"])
        # The simulated truth at 0 .. 100 mm: 8 um/m scale, 1 um pitch error, 4 um backlash:
        # every stop within +-4 um. STABLE shows the live deviation from the target; CAPTURED
        # the captured stop's value with its target (issue 29).
        label = "Captured at" if at_stop["motion"] == "captured" else "Deviation from"
        ok(d["mode"] == "deviation" and at_stop["label"].startswith(label)
           and abs(value) < 5.0, f"at a stop the number is a deviation: {at_stop['label']}: "
           f"{at_stop['big']} µm")
        shown = at_stop["captured"] if at_stop["motion"] == "captured" else d["value"]
        ok(abs(value - shown) < 0.006, "the number shown is the live value or, at CAPTURED, the captured one")
        first = b.js("return window.__first;")
        ok(all(x["fits"] for x in first.values()),
           f"the number and its unit fit the panel: {[(k, x['big'], x['fits']) for k, x in first.items()]}")
        moving = first.get("moving")
        ok(moving and moving["display"]["mode"] == "position"
           and moving["label"] == "Position (laser, compensated)",
           f"while moving the number is a position, said to be the compensated one: {moving and moving['big']} mm "
           f"({moving and moving['label']!r})")
        rows = b.js("return document.querySelectorAll('#stops tbody tr').length;")
        ok(rows == 12, f"the table of captured stops has all 12 stops: {rows}")
        last_run = b.js("return window.caldaq.page.status.last;")
        ok(last_run["status"] == "complete", f"the linear run completed: {last_run}")

        # --- 6. results ------------------------------------------------------------------------
        b.wait("return !document.getElementById('view-results').hidden && "
               "document.getElementById('report-html');", timeout_s=45, what="the results view")
        verdict = b.wait("return document.getElementById('result-verdict').textContent;",
                         what="the verdict")
        checks = b.js("return [...document.querySelectorAll('#verdict-table tbody tr')].map(r => r.textContent);")
        # The shop's 4 um backlash exceeds the B limit of 3 um: the run fails on B.
        ok(verdict == "FAIL" and any(c.startswith("B") and c.endswith("FAIL") for c in checks),
           f"results with verdicts: {verdict}; {checks}")
        html_link = b.js("return document.getElementById('report-html').href;")
        pdf_link = b.js("return document.getElementById('report-pdf').href;")
        status, ctype, body = fetch(html_link)
        ok(status == 200 and ctype.startswith("text/html") and b"<svg" in body,
           f"the HTML report link serves the report ({len(body)} bytes)")
        # The PDF is rendered by Chromium on the server (about 2 s): fetched meanwhile, checked
        # after the ballbar run.
        pdf = concurrent.futures.ThreadPoolExecutor(max_workers=1).submit(fetch, pdf_link, 120)
        listed = b.js("return [...document.querySelectorAll('#runs tbody tr')].map(r => r.textContent);")
        ok(listed and "complete" in listed[0], f"the stored runs list: {listed}")
        no_raw_keys(b, "results")
        shot(b, "09-results-linear.png")
        caps = sorted(os.listdir(os.path.join(TMP, "captures")))
        ok(caps == [f"run-{last_run['run']}.cdq"], f"the capture is named by its run: {caps}")

        # --- 7. the ballbar test --------------------------------------------------------------
        # 20x: each direction of the circle lasts a few seconds of wall time (at 50x the
        # counter-clockwise pass took about 1.4 s, and a WebDriver poll starved on a loaded CI
        # machine missed it, stop 39). The page itself records the longest trace it showed, so
        # no poll has to land inside the pass.
        simulation_speed(url, 20)
        b.js("document.getElementById('tab-run').click();")
        b.wait("return window.caldaq.page.status.start.circle.ready;", timeout_s=30,
               what="Start ballbar ready")
        b.js("window.__ccwSeen = 0; window.__ccwTimer = setInterval(() => {"
             " const t = window.caldaq.liveTrace;"  # the page's own trace, built from the new points
             " if (t) window.__ccwSeen = Math.max(window.__ccwSeen, t.ccw.length);"
             " }, 10);")
        b.js("document.getElementById('start-circle').click();")
        b.wait("return window.__ccwSeen > 150;", timeout_s=90, what="the polar trace",
               explain="return JSON.stringify({seen: window.__ccwSeen, run: window.caldaq.page.run"
                       " && {state: window.caldaq.page.run.state, ccw: window.caldaq.liveTrace"
                       " && window.caldaq.liveTrace.ccw.length}, last: window.caldaq.page.status.last});")
        b.js("clearInterval(window.__ccwTimer);")
        shot(b, "10-ballbar-live.png")
        # Measured, not asserted (a timing assert has no place in a test): the page's update
        # rate and the size of its state with the polar trace, while the bar streams.
        c0, t0 = b.js("return window.caldaq.messages;"), time.time()
        time.sleep(1.0)
        c1, t1 = b.js("return window.caldaq.messages;"), time.time()
        print(f"measured: {(c1 - c0) / (t1 - t0):.1f} page updates/s during the ballbar run, "
              f"{b.js('return window.caldaq.bytes;')} bytes per update")
        b.wait("const l = window.caldaq.page.status.last; return l && l.test === 'circle';",
               timeout_s=120, what="the ballbar run to end")
        ok(b.js("return window.caldaq.page.status.last.status;") == "complete",
           "the ballbar run completed")
        b.wait("return !document.getElementById('view-results').hidden && "
               "/circle/.test(document.getElementById('result-head').textContent) && "
               "document.getElementById('result-values');", timeout_s=45, what="its results")
        g = b.js("return [...document.querySelectorAll('#result-values tbody tr')].map(r => r.textContent);")
        ok(g and g[0].startswith("G"), f"ballbar results: {g[:3]}")
        shot(b, "11-results-ballbar.png")
        status, ctype, body = pdf.result()
        ok(status == 200 and ctype == "application/pdf" and body.startswith(b"%PDF"),
           f"the PDF link (of the linear run) serves a PDF ({len(body)} bytes)")

        # --- 8. Stop asks for confirmation; the layout at 600 px -----------------------------
        # The run must go on for the checks below (seconds on a starved machine): at 2x its twelve
        # stops of 3 s dwell take over 20 s.
        simulation_speed(url, 2)
        b.js("document.getElementById('tab-run').click();")
        b.wait("return window.caldaq.page.status.start.linear.ready;", timeout_s=30,
               what="Start linear ready again")
        b.js("document.getElementById('start-linear').click();")
        third = b.wait("return window.caldaq.page.status.running && window.caldaq.page.status.run.id;",
                       timeout_s=45, what="the third run")
        b.js("document.getElementById('stop').click();")
        ok(b.js("return document.getElementById('confirm-stop').open;"), "Stop asks first")
        shot(b, "12-stop-confirmation.png")
        b.js("document.getElementById('confirm-no').click();")
        time.sleep(0.5)
        # Running still, or (on a starved machine) ended by itself, never aborted by this click.
        kept = b.js("const s = window.caldaq.page.status; return s.running ? 'running' : "
                    "(s.last && s.last.run === arguments[0] ? s.last.status : 'gone');", third)
        ok(kept in ("running", "complete", "incomplete"), f"Keep running keeps it running: {kept}")
        b.set_size(560, 1000)
        time.sleep(0.5)
        overflow = b.js("return document.documentElement.scrollWidth - window.innerWidth;")
        cols = b.js("return getComputedStyle(document.querySelector('.run-grid')).gridTemplateColumns.split(' ').length;")
        ok(overflow <= 0 and cols == 1, f"at 560 px one column, nothing wider than the screen "
           f"({overflow} px over)")
        ok(b.js("const g = document.getElementById('big'); return g.scrollWidth <= g.clientWidth;"),
           "at 560 px the number and its unit fit the screen")
        others = b.js("return window.caldaq.page.devices.devices.filter(d => d.role === 'ballbar').map(d => d.state);")
        ok(others and others[0] in ("open", "streaming"),
           f"a linear run leaves the ballbar watched (not silent): {others}")
        shot(b, "13-narrow-560px.png")
        if kept == "running":
            b.js("document.getElementById('stop').click();")
            b.js("document.getElementById('confirm-yes').click();")
            b.wait("const l = window.caldaq.page.status.last; return l && l.status === 'aborted';",
                   timeout_s=45, what="the confirmed stop",
                   explain="return JSON.stringify(window.caldaq.page.status.last);")
        else:
            print(f"note: the third run ended by itself ({kept}) before Stop could be confirmed "
                  "(a starved machine); the confirmation was checked above")
        # The page's rule for a device that dies during a run, on hand-made states (the shop has
        # no switch to unplug the laser mid-run): the same run state shows the number while the
        # laser streams, and dashes with the laser's state once it is silent, never the value.
        b.set_size(1280, 1400)
        dying = b.js("""const page = structuredClone(window.caldaq.page);
            const laser = page.devices.devices.find(d => d.role === 'laser');
            page.status.running = true;
            page.run = {schema: 'caldaq.live.v1', state: 'measuring', time_s: 1e6, message: '',
                        display: {mode: 'deviation', value: 1.234, unit: 'µm', decimals: 2, target_mm: 50},
                        motion: {state: 'stable', stable_fraction: 0.5}, stops: [],
                        stop: {number: 3, count: 12}};
            laser.state = 'streaming';
            show(page);
            const before = document.getElementById('reading').textContent;
            laser.state = 'silent'; laser.reason = 'no reading for 2 s';
            show(page);
            return {before, after: document.getElementById('reading').textContent,
                    label: document.getElementById('reading-label').textContent};""")
        ok(dying["before"] == "1.23" and dying["after"] == "—" and "silent" in dying["label"],
           f"a laser that falls silent during a run: dashes and why, not its last value: {dying}")
        ok(b.js("return JSON.stringify(window.__errors);") == "[]", "no script error on the page")
    print(f"operator page: {page_checks.passes} checks passed; screenshots in {SHOTS}")
finally:
    try:
        browser.result(timeout=30).close()  # closed already unless the service failed to start
    except Exception:
        pass
    page_checks.stop_service(serve)
    shutil.rmtree(TMP, ignore_errors=True)
