"""A 1-hour 10 kHz run streamed into numpy in bounded memory, and readings/s into numpy against
numpy reading the same run's CSV export (python/bench/long_run.py; numbers in docs/python.md)."""
import json
import os
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent.parent / "bench" / "long_run.py"


def step(*args):
    p = subprocess.run([sys.executable, str(BENCH), *map(str, args)], capture_output=True, text=True,
                       env=dict(os.environ))
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_an_hour_of_10_khz_streams_in_bounded_memory(tmp_path):
    db = tmp_path / "hour.sqlite"
    step("write", db, 3600)
    r = step("stream", db)
    assert r["readings"] == 3600 * 10_000 + 3600
    # The run's readings alone are 36 M x 16 bytes = 576 MB; the stream holds a chunk of each
    # series and 64 k readings at a time.
    assert r["peak_rss_mb"] < 150, r
    print(f"\nstreamed {r['readings']} readings in {r['seconds']:.2f} s "
          f"({r['readings_per_s'] / 1e6:.2f} M readings/s), peak RSS {r['peak_rss_mb']:.0f} MB")


def test_numpy_from_the_store_against_numpy_from_the_csv_export(tmp_path, daq_bin):
    db = tmp_path / "minutes.sqlite"
    step("write", db, 120)  # 2 minutes: the CSV path is the slow one
    s = step("stream", db)
    c = step("csv", db, daq_bin)
    assert s["readings"] == c["readings"] == 120 * 10_000 + 120
    assert abs(s["checksum"] - c["checksum"]) <= 1e-9 * max(1.0, abs(s["checksum"]))
    print(f"\nstore -> numpy: {s['readings_per_s'] / 1e6:.2f} M readings/s; CSV export + "
          f"np.loadtxt: {c['readings_per_s'] / 1e6:.3f} M readings/s "
          f"(loadtxt alone {c['readings_per_s_loadtxt_only'] / 1e6:.3f} M/s); "
          f"{s['readings_per_s'] / c['readings_per_s']:.0f}x")
    bench_dir = os.environ.get("CALDAQ_BENCH_DIR")
    if bench_dir:
        Path(bench_dir).mkdir(parents=True, exist_ok=True)
        (Path(bench_dir) / "readings_per_s.json").write_text(json.dumps({"store": s, "csv": c}, indent=1))
    assert s["readings_per_s"] > c["readings_per_s"]
