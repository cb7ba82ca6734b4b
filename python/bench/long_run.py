"""A generated long run of a 10 kHz channel (with 1 Hz air beside it), its streamed read into
numpy with the peak memory, and the same run read from `daq export --format csv` with numpy.

    python3 long_run.py write DB SECONDS     stores the run (bounded memory: one minute a batch)
    python3 long_run.py stream DB            streams it; prints JSON: readings, seconds, peak RSS
    python3 long_run.py csv DB DAQ           exports it to CSV and reads that with numpy

Each step runs in its own process so that its peak RSS (ru_maxrss) is its own.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import caldaq

RATE_HZ = 10_000


def peak_rss_mb() -> float:
    """This process's peak resident memory (VmHWM). Not getrusage's ru_maxrss: Linux keeps that
    across exec, so a child of a large process (pytest) would report its parent's peak."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmHWM in /proc/self/status")


def write(db: str, seconds: int) -> None:
    with caldaq.open(db, read_only=False) as s:
        machine = s.add_machine("bench")
        run = s.begin_run(machine, "bench", "X", "python long run")
        s.add_instrument(run, 0, "gauge", "generated", origin="simulated", origin_detail="long_run.py")
        s.add_instrument(run, 1, "ptu300", "generated", origin="simulated", origin_detail="long_run.py")
        s.set_time_origin(run, 0, 1_790_000_000_000_000_000)
        period_ns = 1_000_000_000 // RATE_HZ
        for minute in range(0, seconds, 60):
            n = min(60, seconds - minute) * RATE_HZ
            t = (np.arange(n, dtype=np.int64) + minute * RATE_HZ) * period_ns
            s.append_readings(run, t, 1e-3 * np.sin(t * 1e-9), device=0, quantity="length_m")
            ta = t[:: RATE_HZ]
            s.append_readings(run, ta, np.full(len(ta), 101325.0), device=1, quantity="air_pressure_pa")
        s.finish_run(run)
    print(json.dumps({"run": run, "peak_rss_mb": peak_rss_mb()}))


def stream(db: str) -> None:
    start = time.perf_counter()
    n = 0
    total = 0.0
    with caldaq.open(db) as s:
        run = s.runs()[-1]
        for c in s.iter_readings(run.id):
            n += len(c["value"])
            total += float(c["value"].sum())
    seconds = time.perf_counter() - start
    print(json.dumps({"readings": n, "seconds": seconds, "readings_per_s": n / seconds,
                      "checksum": total, "peak_rss_mb": peak_rss_mb()}))


def from_csv(db: str, daq: str) -> None:
    with caldaq.open(db) as s:
        run = s.runs()[-1].id
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "run.csv")
        start = time.perf_counter()
        with open(path, "w") as f:
            subprocess.run([daq, "export", str(run), "--db", db, "--format", "csv"], stdout=f, check=True)
        exported = time.perf_counter()
        # The numeric columns (time_s, device, channel, status, value, time_ns); utc, the device
        # name and the quantity are text.
        a = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(0, 2, 4, 6, 7, 8))
        done = time.perf_counter()
    n = a.shape[0]
    print(json.dumps({"readings": n, "export_seconds": exported - start,
                      "loadtxt_seconds": done - exported, "readings_per_s": n / (done - start),
                      "readings_per_s_loadtxt_only": n / (done - exported),
                      "checksum": float(a[:, 4].sum()), "peak_rss_mb": peak_rss_mb()}))


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "write":
        write(sys.argv[2], int(sys.argv[3]))
    elif cmd == "stream":
        stream(sys.argv[2])
    elif cmd == "csv":
        from_csv(sys.argv[2], sys.argv[3])
    else:
        sys.exit(f"unknown step {cmd}")
