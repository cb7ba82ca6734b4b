#!/usr/bin/env python3
"""A rotary axis's positioning run on the operator's page (issue 29 with 36): its Results plot
every stored stop in arcsec at its target angle (degrees), the stored means dotted and the limit
as a band, as the other kinds are plotted (it had no plot at all).

The run is the simulated C axis's (`daq sim --test rotary --acquire`), judged by E 30" and B 2";
the shop injects 6" of backlash on C (ShopTruth::Rotary): at every target the up stops lie about
6" below the down ones, and B fails. Driven in headless Chromium against `daq serve --simulate`
on that database, at 1366 x 768 and 560 px.
Usage: operator_page_rotary_test.py DAQ_BINARY ARTEFACT_DIR
"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
import page_checks  # noqa: E402
from page_checks import ok  # noqa: E402

DAQ, SHOTS, TMP, DB = page_checks.test_dirs("operator-page-rotary-")
E_LIMIT, B_LIMIT = 30.0, 2.0
with open(os.path.join(TMP, "tol.toml"), "w") as f:
    f.write(f"[tolerances.C]\nE_arcsec = {E_LIMIT}\nB_arcsec = {B_LIMIT}\n")
subprocess.run([DAQ, "sim", "--test", "rotary", "--runs", "2", "--acquire", "--tolerances", "tol.toml",
                "-o", "rot.toml", "--db", DB], cwd=TMP, check=True, capture_output=True)

with page_checks.served_page(DAQ, TMP, page_checks.simulated(DB)) as (serve, url, b):
    wait = page_checks.waiter(b, TMP, "return JSON.stringify({view: window.caldaq.view, result: window.caldaq.resultPlot, "
                              "errors: window.__errors});", 60)
    doc = page_checks.get_json(url + "api/runs/1")
    ok(doc["kind"] == "rotary" and doc["axis"] == "C" and len(doc["stops"]) == 36,
       f"run 1 is the C axis's rotary run, 9 targets x 2 runs x 2 directions: {doc['kind']} {doc['axis']} {len(doc['stops'])}")
    b.get(url)
    b.js("document.getElementById('tab-results').click();")
    wait("return !!document.querySelector('[data-show-run=\"1\"]');", "the rotary run listed")
    b.js("document.querySelector('[data-show-run=\"1\"]').click();")
    plot = wait("const p = window.caldaq.plots && window.caldaq.plots['result-plot']; const box = document.getElementById('result-plot-box');"
                " if (!(window.caldaq.result && window.caldaq.result.id === 1 && window.caldaq.resultPlot.run === 1 && p && !box.hidden)) return false;"
                " const c = document.getElementById('result-plot'), g = c.getContext('2d');"
                " return {title: document.getElementById('result-plot-title').textContent, drawn: p,"
                " colours: p.points.map(q => [...g.getImageData(Math.round(q.px[0]), Math.round(q.px[1]), 1, 1).data])};",
                "the rotary run's plot")
    drawn = plot["drawn"]
    ok(plot["title"] == "Angular positioning deviation at each target (arcsec): every stop as stored, the means dotted",
       f"its title names the deviation and its unit: {plot['title']!r}")
    ok(drawn["unit"] == "arcsec" and drawn["at"] == "°" and "0.0 °" in drawn["texts"] and "360.0 °" in drawn["texts"],
       f"in arcsec over 0 to 360°: {drawn['texts']}")
    stored = sorted((s["nominal_mm"], s["direction"], round(s["deviation_um"], 9)) for s in doc["stops"])
    shown = sorted((p["x_mm"], p["direction"], round(p["value"], 9)) for p in drawn["points"])
    ok(shown == stored, f"every stored stop drawn at its angle with its value ({len(shown)} of {len(stored)})")
    ok(all(max(c[:3]) > 150 for c in plot["colours"]), f"each point painted where it is said to be: {plot['colours'][:4]}")
    # The injected backlash: at each target the up stops 6" below the down ones (5 to 7.5").
    by = {}
    for x, d, v in shown:
        by.setdefault(x, {}).setdefault(d, []).append(v)
    gaps = {x: sum(v["down"]) / len(v["down"]) - sum(v["up"]) / len(v["up"]) for x, v in by.items()}
    ok(len(gaps) == 9 and all(5.0 <= g <= 7.5 for g in gaps.values()),
       f"the 6\" backlash injected on C: down - up at each target {[round(g, 2) for g in gaps.values()]}")
    # The band: E's limit (30") wide, centred on the middle of the directions' means (by hand
    # from the stored means: (max + min) / 2).
    targets = next(r for r in doc["results"] if r["current"])["result"]["targets"]
    means = [t[k] for t in targets for k in ("mean_up", "mean_down")]
    mid = (max(means) + min(means)) / 2
    band = drawn["band"]
    ok(band and all(abs(v - (mid - E_LIMIT / 2)) < 1e-9 for v in band["lo"]) and all(abs(v - (mid + E_LIMIT / 2)) < 1e-9 for v in band["hi"])
       and "limit E 30.000 arcsec: the means fit in the green band" in drawn["texts"],
       f"the limit E 30\" as a band about the means' middle {mid:.3f}\": {band} {drawn['texts']}")
    verdict = b.js("return [document.getElementById('result-verdict').textContent, document.getElementById('result-failed').innerText];")
    ok(verdict[0] == "FAIL" and verdict[1].startswith("B ") and "over its limit 2.000 arcsec" in verdict[1],
       f"B over its 2\" limit: {verdict}")
    ok(not page_checks.ascii_units(b.js("return document.getElementById('result-panel').innerText;")),
       "no 'um' nor '-0.00' in its Results")
    page_checks.shot(b, SHOTS, "r-rotary-results-1366x768.png")
    b.set_size(560, 900)
    wait("const p = window.caldaq.plots['result-plot']; return p && p.points.length === 36 && "
         "document.getElementById('result-plot').width < 560;", "the plot redrawn 560 px wide")
    b.js("document.getElementById('result-plot').scrollIntoView();")
    page_checks.shot(b, SHOTS, "r-rotary-plot-560.png")
    b.set_size(1366, 768)
    page_checks.fits_narrow(b, SHOTS, "r-rotary-results-560.png", "560 px: the rotary Results fit")
    page_checks.no_script_error(b)
