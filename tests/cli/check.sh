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

finish() {
  echo "$passes passed, $fails failed"
  [ "$fails" -eq 0 ]
}
