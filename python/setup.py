"""A wheel of the caldaq package, built offline with Debian's own tools (docs/python.md):

    pip wheel --no-build-isolation --no-deps -w dist python/

The C++ module is built by the project's CMake (in $CALDAQ_BUILD_DIR, default build/ at the
top of the source tree, configured there if it is not yet) and copied into the wheel with the
pure-Python files. --no-build-isolation makes pip use the installed setuptools and wheel
(python3-setuptools, python3-wheel) instead of fetching them.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def project_version() -> str:
    for line in (ROOT / "CMakeLists.txt").read_text().splitlines():
        if line.startswith("project(caldaq VERSION "):
            return line.split()[2]
    return "0"


class CMakeBuild(build_ext):
    def build_extension(self, ext: Extension) -> None:
        build = Path(os.environ.get("CALDAQ_BUILD_DIR", ROOT / "build")).resolve()
        if not (build / "CMakeCache.txt").exists():
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                            f"-DPython3_EXECUTABLE={sys.executable}", "-DCALDAQ_PYTHON=ON"], check=True)
        jobs = os.environ.get("JOBS", "2")
        subprocess.run(["cmake", "--build", str(build), "-j", jobs, "--target", "_caldaq"], check=True)
        built = build / "python" / "caldaq"
        target = Path(self.get_ext_fullpath(ext.name)).parent
        target.mkdir(parents=True, exist_ok=True)
        for f in built.iterdir():
            if f.name.startswith("_caldaq") and f.suffix == ".so":
                module = Path(self.get_ext_fullpath(ext.name))
                shutil.copy(f, module)
                strip_debug_info(module)
            elif f.suffix in (".pyi",) or f.name == "py.typed":
                shutil.copy(f, target / f.name)


def strip_debug_info(module: Path) -> None:
    """The build's RelWithDebInfo module carries its debug information (93 of its 96 MB); the
    wheel's copy goes without it (binutils' strip, as `cmake --install --strip`)."""
    strip = shutil.which(os.environ.get("STRIP", "strip"))
    if strip is None:
        print(f"caldaq: no strip found: {module.name} keeps its debug information", file=sys.stderr)
        return
    subprocess.run([strip, "--strip-debug", str(module)], check=True)


# Where setuptools works (its build/ and caldaq.egg-info/): python/ unless CALDAQ_WHEEL_WORK says
# elsewhere (the test builds its wheel without writing into the source tree).
WORK = os.environ.get("CALDAQ_WHEEL_WORK")
OPTIONS = {"build": {"build_base": str(Path(WORK) / "build")},
           "egg_info": {"egg_base": WORK}} if WORK else {}

setup(
    name="caldaq",
    options=OPTIONS,
    version=project_version(),
    description="caldaq's run store, analysis library and captures for Python",
    packages=["caldaq"],
    package_dir={"caldaq": "caldaq"},
    package_data={"caldaq": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("caldaq._caldaq", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    install_requires=["numpy"],
    python_requires=">=3.9",
    zip_safe=False,
)
