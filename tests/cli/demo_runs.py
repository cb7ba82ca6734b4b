"""The demo's runs for a test (as check.sh's demo_runs does for the shell tests)."""
import glob
import os
import shutil


def demo_runs(work, make_demo):
    """Puts demo.sqlite of one `daq demo --quiet` into WORK and returns the path of its capture:
    copied from the ctest fixture "demo" (CALDAQ_DEMO_FIXTURE, tests/CMakeLists.txt) if there is
    one, else made by make_demo(), which runs the demo in WORK. The capture stays where the demo
    wrote it: the runs record its absolute path, by which `daq replay` finds the run it replays."""
    fixture = os.environ.get("CALDAQ_DEMO_FIXTURE")
    if fixture:
        for f in glob.glob(os.path.join(fixture, "demo.sqlite*")):
            shutil.copy(f, work)
        return os.path.join(fixture, "demo.cdq")
    make_demo()
    return os.path.join(work, "demo.cdq")
