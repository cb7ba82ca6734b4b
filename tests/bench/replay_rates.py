#!/usr/bin/env python3
"""Replay speed per device kind at its highest rate (issue 32; docs/benchmarks.md).

Makes captures of the simulated shop (`daq sim --acquire --capture`: a linear run with the
IDS3010, PTU300, serial thermometer and SHDR feed, and a ballbar circle), turns each into a
capture of one device at its highest rate (`rate_capture`, tests/replay/rate_capture.cpp),
replays each with `/usr/bin/time -v daq replay` and prints, beside `daq bench ingest`
measured in the same run: readings, recorded seconds, wall, user+sys CPU, real-time factor
by CPU, the CPU per added reading (against the template capture's own replay) and its ratio
to the bench's per-reading costs, and peak RSS.

Usage: tests/bench/replay_rates.py --daq build/daq/daq --rate-capture \
           build/tests/replay/rate_capture [--dir /tmp/replay_rates] [--rounds 2]
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys

# The device kinds, their highest rates and why (docs/benchmarks.md gives the reasons).
KINDS = [
    # kind, template, rate (Hz), what
    ("ids3010", "lin", 10000, "IDS3010 getAxesDisplacement, JSON-RPC"),
    ("ptu300", "lin", 10, "PTU300 SEND lines at 4800 7E1"),
    ("gauge", "lin", 90, "serial thermometer (line gauge, polled) at 9600 8N1"),
    ("ballbar", "circ", 10000, "ballbar (line gauge, streaming), the issue's 10 kHz"),
    ("shdr", "lin", 1000, "MTConnect SHDR Xcom lines while moving"),
    ("halsampler", "lin", 1000, "halsampler lines (servo thread)"),
    ("temper", "lin", 200, "TEMPer HID reports (the 5 ms HID poll)"),
]


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def timed(cmd):
    """Runs cmd under /usr/bin/time -v: (stdout, wall s, cpu s, peak RSS MB). A replay stored
    incomplete (status 2) is measured all the same: it read and stored every reading."""
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if p.returncode != 0 and "but incomplete" not in p.stderr:
        sys.exit(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    err = p.stderr

    def field(name):
        return re.search(re.escape(name) + r":\s*(\S+)", err).group(1)

    wall_text = field("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    wall = 0.0
    for part in wall_text.split(":"):
        wall = wall * 60 + float(part)
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    return p.stdout + p.stderr, wall, cpu, int(field("Maximum resident set size (kbytes)")) / 1024


def recorded_s(path):
    """The capture's span in seconds (first to last record), read as docs/capture-format.md."""
    import struct

    with open(path, "rb") as f:
        data = f.read(16)
        hlen = struct.unpack_from("<I", data, 12)[0]
        f.seek(20 + hlen)
        first = last = None
        while True:
            head = f.read(16)
            if len(head) < 16:
                break
            magic, length, count, _ = struct.unpack("<IIII", head)
            if magic != 0x4B4C4243:
                break
            body = f.read(length)
            p = 0
            for _ in range(count):
                t, _, _, _, n = struct.unpack_from("<qHBBI", body, p)
                first = t if first is None else first
                last = t
                p += 16 + n
    return (last - first) / 1e9


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--daq", required=True)
    ap.add_argument("--rate-capture", required=True)
    ap.add_argument("--dir", default="/tmp/replay_rates")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--kinds", default=",".join(k[0] for k in KINDS))
    ap.add_argument("--bench-seconds", type=int, default=60)
    a = ap.parse_args()
    os.makedirs(a.dir, exist_ok=True)
    d = lambda name: os.path.join(a.dir, name)  # noqa: E731
    daq = os.path.abspath(a.daq)

    # The templates: the simulated shop's own captures, on simulated time.
    templates = {"lin": ["--test", "linear", "--position-feed"], "circ": ["--test", "circle"]}
    for name, args in templates.items():
        if not os.path.exists(d(name + ".cdq")):
            run([daq, "sim", "--acquire", *args, "--capture", d(name + ".cdq"), "--db",
                 d(name + ".sqlite"), "-o", d(name + ".toml")])

    wanted = a.kinds.split(",")
    rows = []
    for kind, template, rate, what in KINDS:
        if kind in wanted and not os.path.exists(d(kind + ".cdq")):
            run([a.rate_capture, d(template + ".cdq"), d(kind + ".cdq"), kind, str(rate)])

    def replay(capture, template):
        out = []
        for _ in range(a.rounds):
            db = d("replay.sqlite")
            shutil.copy(d(template + ".sqlite"), db)
            stdout, wall, cpu, rss = timed([daq, "replay", d(capture + ".cdq"), "--db", db])
            m = re.search(r"\((\d+) readings\)", stdout)
            if m:
                readings = int(m.group(1))
            else:  # incomplete: the stored run says how many
                run_id = re.search(r"stored as run (\d+) but incomplete", stdout).group(1)
                shown = run([daq, "show", run_id, "--db", db]).stdout
                readings = int(re.search(r"readings: (\d+)", shown).group(1))
                incomplete.add(capture)
            out.append((readings, wall, cpu, rss))
            os.remove(db)
        return out

    incomplete = set()
    base = {t: replay(t, t) for t in templates}
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    for kind, template, rate, what in KINDS:
        if kind in wanted:
            rows.append((kind, rate, what, template, replay(kind, template)))
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]

    # The bench's pipeline, same run.
    bench = run([daq, "bench", "ingest", "--seconds", str(a.bench_seconds), "--rounds", "3",
                 "--dir", a.dir]).stdout
    pipeline = float(re.search(r"pipeline without storage\s+(\d+) readings/s", bench).group(1))
    core = float(re.search(r"one core .*? ingests (\d+) readings/s", bench).group(1))
    pipeline_us, core_us = 1e6 / pipeline, 1e6 / core

    print(f"load average {' '.join(load_before)} before, {' '.join(load_after)} after the replays")
    print(f"bench ingest (median of 3 rounds): pipeline without storage {pipeline:.0f} readings/s"
          f" = {pipeline_us:.3f} us per reading; one core ingests {core:.0f} readings/s ="
          f" {core_us:.3f} us CPU per reading")
    for t in templates:
        b = base[t]
        print(f"template {t}: {b[0][0]} readings, {recorded_s(d(t + '.cdq')):.0f} s recorded, "
              f"CPU {', '.join(f'{x[2]:.2f}' for x in b)} s, peak RSS {max(x[3] for x in b):.1f} MB")
    print()
    print("| device | rate | readings | recorded | wall | CPU | x real time (CPU) | us CPU per "
          "added reading | x pipeline | x ingest (one core) | peak RSS |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for kind, rate, what, template, res in rows:
        rec = recorded_s(d(kind + ".cdq"))
        readings = res[0][0]
        cpu = statistics.median(x[2] for x in res)
        wall = statistics.median(x[1] for x in res)
        base_cpu = statistics.median(x[2] for x in base[template])
        added = readings - base[template][0][0]
        per = (cpu - base_cpu) / added * 1e6 if added > 0 else float("nan")
        if kind in incomplete:
            what += " (run stored incomplete)"
        print(f"| {what} | {rate:g} Hz | {readings:,} | {rec:.0f} s | {wall:.2f} s | "
              f"{cpu:.2f} s ({', '.join(f'{x[2]:.2f}' for x in res)}) | {rec / cpu:.0f}x | "
              f"{per:.2f} | {per / pipeline_us:.1f} | {per / core_us:.1f} | "
              f"{max(x[3] for x in res):.1f} MB |")


if __name__ == "__main__":
    main()
