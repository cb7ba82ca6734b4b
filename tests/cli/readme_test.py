"""Runs the README's "Using `daq`" block as a shell script, top to bottom, in a fresh directory
(so on a fresh demo database), as a newcomer would paste it, and fails if any command fails, if
a process it started is still running at its end, or if what it says it produces is missing.
The README is the user's first contact: a command in it that does not work on the demo's own
data, or that blocks, is a bug.

Usage: readme_test.py DAQ_BINARY SOURCE_DIR

How the block is run:
- `bash -e`: the first command that fails ends it, named with its status;
- `daq` is a stand-in first on the PATH that runs the built binary, notes its process id (each
  must have ended when the block has), and gives `daq serve` `--port 0` (any free port) so that
  a port in use on the test machine cannot fail it;
- the directory has `tests` linked to the repository's tests/ (the README's example files);
- HOME and XDG_DATA_HOME point into the directory, so the default database is a fresh one.
"""
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

daq, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
readme = open(os.path.join(source, "README.md"), encoding="utf-8").read()
block = re.search(r"## Using `daq`\n.*?```sh\n(.*?)```", readme, re.S)
assert block, "README.md has no ```sh block under '## Using `daq`'"
script = block.group(1)
commands = [c for c in (re.sub(r"\s+#.*$", "", line).strip() for line in script.splitlines()) if c]
daq_commands = [c for c in commands if c.startswith("daq ")]
assert len(daq_commands) >= 20, f"only {len(daq_commands)} daq commands found"
for c in commands:  # nothing outside the repository
    assert "../" not in c, f"a path outside the repository: {c}"

work = tempfile.mkdtemp(prefix="caldaq-readme-")
os.symlink(os.path.join(source, "tests"), os.path.join(work, "tests"))
bindir = os.path.join(work, ".bin")
os.mkdir(bindir)
pids = os.path.join(work, ".pids")
with open(os.path.join(bindir, "daq"), "w") as f:
    f.write(f"""#!/bin/sh
echo $$ >>'{pids}'
if [ "$1" = serve ]; then exec '{daq}' "$@" --port 0; fi
exec '{daq}' "$@"
""")
os.chmod(os.path.join(bindir, "daq"), 0o755)
env = dict(os.environ, HOME=work, XDG_DATA_HOME=os.path.join(work, "share"),
           PATH=bindir + os.pathsep + os.environ["PATH"], PS4="+ ")
env.pop("CALDAQ_DB", None)
passed = failed = 0


def check(name, ok, detail=""):
    global passed, failed
    if ok:
        passed += 1
        print(f"ok {name}")
    else:
        failed += 1
        print(f"FAIL {name}{': ' + detail if detail else ''}")


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie of the shell is no running process.
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


started = time.time()
recorded = []
try:
    shell = ("set -eE -o pipefail\n"
             "trap 'echo \"README block FAILED at: $BASH_COMMAND (exit $?)\"' ERR\n"
             "set -x\n" + script + "\nset +x\necho README-BLOCK-DONE\n")
    # Into a file, not a pipe: a background process left running would hold a pipe open and
    # the block would never seem to end.
    log = os.path.join(work, ".block.log")
    with open(log, "w") as f:
        r = subprocess.run(["bash", "-c", shell], cwd=work, env=env, stdout=f,
                           stderr=subprocess.STDOUT, timeout=1200)
    out = open(log, encoding="utf-8", errors="replace").read()
    took = time.time() - started
    done = r.returncode == 0 and "README-BLOCK-DONE" in out
    ran = len(re.findall(r"^\+ daq ", out, re.M))
    check(f"the block ran top to bottom ({ran} daq commands, {took:.0f} s)", done,
          f"exit {r.returncode}\n{out[-4000:]}")
    check(f"every daq command of the block ran ({ran} of {len(daq_commands)})",
          ran == len(daq_commands))
    check("daq serve listened", re.search(r"^daq serve: http://", out, re.M) is not None)
    # Every process the block started has ended with it (the README stops what it starts).
    recorded = [int(p) for p in open(pids).read().split()] if os.path.exists(pids) else []
    deadline = time.time() + 20
    while time.time() < deadline and any(alive(p) for p in recorded):
        time.sleep(0.2)
    left = [p for p in recorded if alive(p)]
    check("no process left running", not left, f"{len(left)} still running")
    # What the README's commands say they produce is there.
    for name in ["caldaq-demo.sqlite", "caldaq-demo.cdq", "caldaq-demo-circle.cdq", "deviations.csv", "ballbar.csv",
                 "readings-1.csv", "report-run-1.html", "report-run-2.pdf",
                 "campaign-report.html", "comparison-runs-1-3.html", "sim.toml", "run.cdq",
                 "map.html", "cec.mpf"]:
        check(f"{name} produced", os.path.exists(os.path.join(work, name)))
finally:
    for p in recorded:
        if alive(p):
            os.kill(p, signal.SIGKILL)
    subprocess.run(["rm", "-rf", work])
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
