# Sourced by the tests/cli/*_test.sh scripts: one assertion on a command's exit status and
# output, counted; `finish` prints the tally and fails the script if any check failed.
fails=0
passes=0

check() {  # check NAME EXPECTED_EXIT PATTERN -- command...
  local name=$1 want=$2 pattern=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL $name: exit $rc, expected $want"
    echo "$out" | head -40
    fails=$((fails + 1))
    return
  fi
  if ! grep -qE -- "$pattern" <<<"$out"; then
    echo "FAIL $name: output lacks /$pattern/"
    echo "$out" | head -40
    fails=$((fails + 1))
    return
  fi
  passes=$((passes + 1))
}

# check_file FILE <<'END' ... END: what FILE must hold, as a table: each line "NAME PATTERN"
# (PATTERN, as check's, runs to the end of the line and is taken as written: no quoting, no
# expansion) is `check NAME 0 PATTERN -- cat FILE`; empty lines and lines of '#' are skipped.
check_file() {
  local file=$1 name pattern
  while read -r name pattern; do
    [[ -z $name || $name == \#* ]] && continue
    check "$name" 0 "$pattern" -- cat "$file"
  done
}

# scratch_dir [PID_VARIABLE...]: TMP, a new directory removed when the script exits, and SIM_PID
# (a `daq sim` the script starts) and each named variable (other processes it starts, e.g.
# RUN_PID) set empty now and, if they hold a process that still runs, killed then.
scratch_dir() {
  TMP=$(mktemp -d)
  scratch_pids="SIM_PID $*"
  local v
  for v in $scratch_pids; do printf -v "$v" '%s' ''; done
  trap scratch_cleanup EXIT
}
scratch_cleanup() {
  local v
  for v in $scratch_pids; do [ -n "${!v}" ] && kill "${!v}" 2>/dev/null; done
  rm -rf "$TMP"
}

finish() {
  echo "$passes passed, $fails failed"
  [ "$fails" -eq 0 ]
}

# The Python interpreter itself, not a version manager's shim (pyenv's costs ~0.07 s a call).
PY=$(python3 -c 'import sys; print(sys.executable)')

# demo_runs DIR: DIR/demo.sqlite and demo.log of one `daq demo --quiet`, and DEMO_CDQ its
# capture: copied from (the capture read in) the ctest fixture "demo" (CALDAQ_DEMO_FIXTURE,
# tests/CMakeLists.txt), else made here. The capture stays where the demo wrote it: the runs
# record its absolute path, by which `daq replay` finds the run it replays.
demo_runs() {
  if [ -n "${CALDAQ_DEMO_FIXTURE:-}" ]; then
    cp "$CALDAQ_DEMO_FIXTURE"/demo.sqlite* "$CALDAQ_DEMO_FIXTURE"/demo.log "$1/" ||
      { echo "FAIL: no demo fixture in $CALDAQ_DEMO_FIXTURE"; exit 1; }
    DEMO_CDQ=$CALDAQ_DEMO_FIXTURE/demo.cdq
  else
    (cd "$1" && "$DAQ" demo --quiet --db demo.sqlite --capture demo.cdq >demo.log 2>&1) ||
      { cat "$1/demo.log"; exit 1; }
    DEMO_CDQ=$1/demo.cdq
  fi
}
