"""Installation from the wheel, as docs/python.md builds it offline with Debian's pip: the wheel
holds the module without its debug information and the Python files, and installs into a
directory from which a fresh interpreter imports it and reads the demo's database."""
import os
import subprocess
import sys
import zipfile
from pathlib import Path

PYTHON_DIR = Path(__file__).resolve().parents[1]


def test_the_wheel_installs_and_imports(demo, tmp_path):
    build = os.environ.get("CALDAQ_BUILD_DIR")
    assert build, "set CALDAQ_BUILD_DIR to the CMake build holding the module (ctest does)"
    env = dict(os.environ, CALDAQ_BUILD_DIR=build, CALDAQ_WHEEL_WORK=str(tmp_path / "work"))
    dist = tmp_path / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "--no-index", "-w", str(dist), str(PYTHON_DIR)], env=env, check=True,
                   capture_output=True)
    wheels = list(dist.glob("caldaq-*.whl"))
    assert len(wheels) == 1
    size_mb = wheels[0].stat().st_size / 1e6
    with zipfile.ZipFile(wheels[0]) as z:
        names = z.namelist()
        module = [i for i in z.infolist()
                  if i.filename.startswith("caldaq/_caldaq") and i.filename.endswith(".so")]
        assert {"caldaq/__init__.py", "caldaq/_caldaq.pyi", "caldaq/py.typed"} <= set(names)
        assert len(module) == 1
        # Without debug information: the RelWithDebInfo module is about 96 MB, stripped 3.3 MB.
        assert module[0].file_size < 10e6 and size_mb < 5, (module[0].file_size, size_mb)
    (tmp_path / "size_mb.txt").write_text(f"{size_mb:.2f}\n")
    print(f"wheel {wheels[0].name}: {size_mb:.2f} MB, module {module[0].file_size / 1e6:.2f} MB")
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-index", "--target",
                    str(site), str(wheels[0])], check=True, capture_output=True)
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    clean["PYTHONPATH"] = str(site)
    code = ("import caldaq, sys; db = caldaq.open(sys.argv[1]); "
            "print(caldaq.__file__); print(len(db.runs()))")
    # From tmp_path: `python -c` looks in its working directory first (ctest's is build/python).
    out = subprocess.run([sys.executable, "-c", code, str(demo / "demo.sqlite")], env=clean,
                         cwd=tmp_path, check=True, capture_output=True, text=True).stdout.split()
    assert Path(out[0]).is_relative_to(site) and int(out[1]) == 2
    assert not (PYTHON_DIR / "caldaq.egg-info").exists()  # nothing written into the source tree
