"""Runs every command of the README's "Using `daq`" block, in order, in a fresh directory (so on
a fresh demo database), and fails if any fails. The README is the user's first contact: a
command in it that does not work on the demo's own data is a bug.

Usage: readme_test.py DAQ_BINARY SOURCE_DIR

How the block is run:
- `daq` is the built binary; a trailing `# comment` is not part of the command;
- the directory has `tests` linked to the repository's tests/ (the README's example profile);
- HOME and XDG_DATA_HOME point into the directory, so the default database is a fresh one;
- a command ending in `&` runs in the background until the end (`daq sim`: the next command
  starts once it has written its configuration);
- `daq serve` runs until it says it listens (after its device check's lines), then is stopped;
  it gets `--port 0` (any free port) so that a port in use on the test machine cannot fail it.
"""
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import time

daq, source = sys.argv[1], sys.argv[2]
readme = open(os.path.join(source, "README.md"), encoding="utf-8").read()
block = re.search(r"## Using `daq`\s*```sh\n(.*?)```", readme, re.S)
assert block, "README.md has no ```sh block under '## Using `daq`'"
commands = []
for line in block.group(1).splitlines():
    code = re.sub(r"\s+#.*$", "", line).strip()  # no # inside the README's commands' quotes
    if code:
        commands.append(code)
assert len(commands) >= 20, f"only {len(commands)} commands found"

work = tempfile.mkdtemp(prefix="caldaq-readme-")
os.symlink(os.path.join(source, "tests"), os.path.join(work, "tests"))
env = dict(os.environ, HOME=work, XDG_DATA_HOME=os.path.join(work, "share"))
env.pop("CALDAQ_DB", None)
background = []
passed = failed = 0


def argv_of(code):
    words = shlex.split(code)
    assert words[0] == "daq", f"not a daq command: {code}"
    return [daq] + words[1:]


def stop(p):
    if p.poll() is None:
        p.send_signal(signal.SIGINT)
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


try:
    for code in commands:
        started = time.time()
        if code.endswith("&"):
            argv = argv_of(code[:-1].strip())
            log = open(os.path.join(work, f"background-{len(background)}.log"), "w")
            p = subprocess.Popen(argv, cwd=work, env=env, stdout=log, stderr=subprocess.STDOUT)
            background.append(p)
            if "-o" in argv:  # e.g. daq sim -o sim.toml: wait for the file it writes
                out = os.path.join(work, argv[argv.index("-o") + 1])
                while not (os.path.exists(out) and os.path.getsize(out) > 0):
                    assert p.poll() is None and time.time() - started < 60, f"{code}: no {out}"
                    time.sleep(0.1)
            print(f"ok (background) {code}")
            passed += 1
            continue
        argv = argv_of(code)
        if argv[1] == "serve":
            argv += ["--port", "0"]
            p = subprocess.Popen(argv, cwd=work, env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, text=True)
            lines = []  # the device check's lines come first
            while not (lines and lines[-1].startswith("daq serve: http://")):
                line = p.stdout.readline()
                if not line:
                    break
                lines.append(line)
            line = lines[-1] if lines else ""
            stop(p)
            if line.startswith("daq serve: http://"):
                print(f"ok {code}  ->  {line.strip()}")
                passed += 1
            else:
                print(f"FAIL {code}: {''.join(lines)}{p.stdout.read()}")
                failed += 1
            continue
        r = subprocess.run(argv, cwd=work, env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True, timeout=600)
        took = time.time() - started
        if r.returncode == 0:
            print(f"ok {code}  ({took:.1f} s)")
            passed += 1
        else:
            print(f"FAIL {code}: exit {r.returncode}\n{r.stdout[-3000:]}")
            failed += 1
    # What the README's commands say they produce is there.
    for name in ["caldaq-demo.sqlite", "caldaq-demo.cdq", "deviations.csv", "ballbar.csv",
                 "report-run-1.html", "campaign-report.html", "comparison-runs-1-3.html",
                 "sim.toml", "run.cdq"]:
        if os.path.exists(os.path.join(work, name)):
            passed += 1
        else:
            print(f"FAIL: {name} was not produced")
            failed += 1
finally:
    for p in background:
        stop(p)
    subprocess.run(["rm", "-rf", work])
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
