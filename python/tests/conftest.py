"""Fixtures of the Python package's tests: the daq binary (CALDAQ_DAQ) whose JSON output every
function is checked against, and a copy of the demo's database and capture (the ctest fixture
"demo" in CALDAQ_DEMO_FIXTURE, else a `daq demo` made here)."""
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def daq_bin() -> str:
    path = os.environ.get("CALDAQ_DAQ") or shutil.which("daq")
    assert path and Path(path).exists(), "set CALDAQ_DAQ to the daq binary"
    return str(Path(path).resolve())  # the demo runs in its own directory


@pytest.fixture(scope="session")
def demo(daq_bin, tmp_path_factory) -> Path:
    """A directory holding demo.sqlite and demo.cdq (a copy: the tests may add to it)."""
    out = tmp_path_factory.mktemp("demo")
    src = os.environ.get("CALDAQ_DEMO_FIXTURE")
    if src and (Path(src) / "demo.sqlite").exists():
        for name in ("demo.sqlite", "demo.cdq"):
            shutil.copy(Path(src) / name, out / name)
    else:
        subprocess.run([daq_bin, "demo", "--quiet", "--db", "demo.sqlite", "--capture", "demo.cdq"],
                       cwd=out, check=True, capture_output=True)
    return out


@pytest.fixture(scope="session")
def cli(daq_bin):
    """Runs daq with arguments; returns its parsed JSON (a list for one object per line)."""
    def run(*args, cwd=None, lines=False):
        p = subprocess.run([daq_bin, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert p.returncode == 0, f"daq {' '.join(map(str, args))}: {p.stderr}"
        if lines:
            return [json.loads(x) for x in p.stdout.splitlines() if x.strip()]
        return json.loads(p.stdout)
    return run


@pytest.fixture(scope="session")
def cli_error(daq_bin):
    """Runs daq expecting failure; returns the message after 'daq: error: '."""
    def run(*args, cwd=None):
        p = subprocess.run([daq_bin, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert p.returncode != 0, f"daq {' '.join(map(str, args))} succeeded"
        line = [x for x in p.stderr.splitlines() if x.startswith("daq: error: ")][-1]
        return line[len("daq: error: "):]
    return run
