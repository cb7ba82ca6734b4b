"""`daq bench replay` on tiny templates (issue 32): one run of the command, its table and its
JSON checked for structure, and every device's replay stored complete with all its stops.

The templates are the smallest the simulated shop makes: a linear run of 2 runs x 2 targets
(2 x 2 x 2 = 8 stops, each direction at each target in each run: ISO 230-2's plan) and a circle
at 10,000 mm/min. Figures a wrong bench would get wrong, checked against values from outside
its code:
- the stops: 8 planned, 8 captured, none missed, for the template and every linear device (the
  1 kHz halsampler feed lost the last stop before the densified feed ran to the capture's end);
- the halsampler's readings: a line every 1 ms from the feed's first position to the capture's
  end, one reading each (column 0 only), so 1000 x the recorded seconds within 5 % (the feed's
  first position comes in the first second of the 30 s; the template's other readings, about
  1,300, are 4 %); the IDS3010's answers at 10 kHz only between the recorded polls: at most
  10,000 x the recorded seconds, and more than half of it;
- the real-time factor is the recorded seconds over the replay's CPU, recomputed here.

Usage: bench_replay_test.py DAQ_BINARY
"""
import json
import os
import re
import subprocess
import sys
import tempfile

daq = os.path.abspath(sys.argv[1])
fails = []


def check(name, ok, detail=""):
    if not ok:
        fails.append(f"{name}: {detail}")


KINDS = ["ids3010", "ptu300", "gauge", "ballbar", "shdr", "halsampler", "temper"]

with tempfile.TemporaryDirectory() as tmp:
    out_json = os.path.join(tmp, "bench.json")
    p = subprocess.run(
        [daq, "bench", "replay", "--runs", "2", "--targets", "2", "--circle-feed-mm-per-min",
         "10000", "--rounds", "1", "--bench-seconds", "2", "--dir", tmp, "--json", out_json],
        capture_output=True, text=True, timeout=900)
    text = p.stdout + p.stderr
    check("exit status", p.returncode == 0, f"{p.returncode}\n{text[-3000:]}")
    check("scratch removed", os.listdir(tmp) == ["bench.json"], str(os.listdir(tmp)))
    check("peer line", re.search(r"^peer \(the ingest bench's pipeline.*us CPU per reading "
                                 r"without storage", text, re.M), text[:2000])
    header = re.search(r"^\| device \| rate \| readings \| recorded \| wall \| CPU \| x real "
                       r"time \(CPU\) \| us CPU per added reading \| x pipeline \| x ingest \| "
                       r"peak RSS \| run \|$", text, re.M)
    check("table header", header, text[:3000])
    rows = [line for line in text.splitlines()
            if line.startswith("| ") and not line.startswith("| device") and "---" not in line]
    check("one row per device", len(rows) == len(KINDS), "\n".join(rows))
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        check("row cells", len(cells) == 12, row)
        linear = "ballbar" not in cells[0]
        want = "complete, 8 of 8 stops" if linear else "complete"
        check("row run complete", cells[-1] == want, row)

    doc = json.load(open(out_json)) if os.path.exists(out_json) else {}
    check("schema", doc.get("schema") == "caldaq.bench-replay.v1", str(doc)[:300])
    peer = doc.get("peer", {})
    check("peer figures", 0 < peer.get("pipeline_us_per_reading", 0) < 100 and
          0 < peer.get("ingest_us_per_reading", 0) < 100, str(peer))
    templates = {t["test"]: t for t in doc.get("templates", [])}
    check("templates", sorted(templates) == ["circle", "linear"], str(templates.keys()))
    for t in templates.values():
        r = t["rounds"][0]
        check(f"template {t['test']} complete", r["complete"], str(r))
        if t["test"] == "linear":
            check("template stops", r["stops"] == 8 and r["missed_stops"] == 0, str(r))
    devices = {d["kind"]: d for d in doc.get("devices", [])}
    check("devices", sorted(devices) == sorted(KINDS), str(devices.keys()))
    for kind, d in devices.items():
        r = d["rounds"][0]
        check(f"{kind} complete", d["complete"] and r["complete"] and r["note"] == "", str(r))
        if d["template"] == "linear":
            check(f"{kind} stops", r["stops"] == 8 and r["missed_stops"] == 0, str(r))
        base = templates.get(d["template"], {}).get("rounds", [{}])[0].get("readings", 0)
        check(f"{kind} denser", d["readings"] > base and d["added_readings"] == d["readings"] - base,
              f"{d['readings']} vs template {base}")
        check(f"{kind} real-time factor",
              abs(d["real_time_factor_cpu"] - d["recorded_s"] / d["cpu_s"]) < 1e-6 *
              d["real_time_factor_cpu"], str(d))
        check(f"{kind} peak RSS", 1000 < d["peak_rss_kib"] < 2_000_000, str(d["peak_rss_kib"]))
        check(f"{kind} recorded", 5 < d["recorded_s"] < 60, str(d["recorded_s"]))
        # The summary over the rounds, recomputed from each round's replay and template.
        o = d.get("over_rounds", {})
        tpl_rounds = templates.get(d["template"], {}).get("rounds", [])
        per = [(r["cpu_s"] - t["cpu_s"]) / d["added_readings"] * 1e6
               for r, t in zip(d["rounds"], tpl_rounds)]
        got = o.get("us_cpu_per_added_reading", [])
        check(f"{kind} per-round figures", len(got) == len(per) == 1 and
              all(abs(a - b) <= 1e-9 * abs(b) for a, b in zip(got, per)), f"{got} vs {per}")
        check(f"{kind} min and median", per and o.get("us_cpu_per_added_reading_min") == min(got)
              and o.get("us_cpu_per_added_reading_median") == got[0], str(o))
        check(f"{kind} ratios", abs(o.get("x_ingest_from_mins", 0) * o.get(
              "ingest_us_per_reading_min", 0) - o.get("us_cpu_per_added_reading_min", 1)) <
              1e-9 and o.get("ingest_us_per_reading_min") == peer.get("ingest_us_per_reading"),
              str(o))
        check(f"{kind} summary line", re.search(
            rf"^{kind}: us CPU per added reading min -?[0-9.]+, median -?[0-9.]+ \(.*\); "
            rf"ingest peer min [0-9.]+, median [0-9.]+; x ingest from the mins -?[0-9.]+, "
            rf"from the medians -?[0-9.]+$", text, re.M), text[-3000:])
    if "halsampler" in devices:
        d = devices["halsampler"]
        check("halsampler readings = 1 kHz x recorded",
              abs(d["readings"] - 1000 * d["recorded_s"]) < 0.05 * 1000 * d["recorded_s"],
              f"{d['readings']} readings in {d['recorded_s']} s")
    if "ids3010" in devices:
        d = devices["ids3010"]
        check("ids3010 readings up to 10 kHz x recorded",
              0.5 * 1e4 * d["recorded_s"] < d["readings"] <= 1e4 * d["recorded_s"],
              f"{d['readings']} readings in {d['recorded_s']} s")

    # A kind it does not know is refused before anything is made.
    p = subprocess.run([daq, "bench", "replay", "--kinds", "laser", "--dir", tmp],
                       capture_output=True, text=True, timeout=60)
    check("unknown kind refused", p.returncode == 2 and "'laser' is none of ids3010" in p.stderr,
          f"{p.returncode} {p.stderr}")

for f in fails:
    print("FAIL", f)
print(f"{'FAILED' if fails else 'passed'}: {len(fails)} failure(s)")
sys.exit(1 if fails else 0)
