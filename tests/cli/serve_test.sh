#!/usr/bin/env bash
# daq serve end to end: `daq sim` runs the SIMULATED shop in its own process; `daq serve`
# serves the live page for its configuration; headless Chromium (WebDriver) starts a linear
# run from the page, checks the live values and the update rate, and stops it; the API lists
# the run. A non-loopback address without a token is refused.
# Usage: serve_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
TESTS=$(cd "$2/.." && pwd)
TMP=$(mktemp -d)
SIM_PID= SERVE_PID=
cleanup() {
  [ -n "$SERVE_PID" ] && kill "$SERVE_PID" 2>/dev/null
  [ -n "$SIM_PID" ] && kill "$SIM_PID" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT
source "$(dirname "$0")/check.sh"

check refuses_open_address 2 "needs --token" -- "$DAQ" serve -c /dev/null --address 0.0.0.0 --port 0
# Speed 5; the part program starts 8 s after the simulation (the page starts the run first).
"$DAQ" sim --test linear --speed 5 --start-after-s 8 -o "$TMP/sim.toml" >"$TMP/sim.log" 2>&1 &
SIM_PID=$!
for _ in $(seq 100); do [ -s "$TMP/sim.toml" ] && break; sleep 0.1; done
"$DAQ" serve -c "$TMP/sim.toml" --db "$TMP/serve.sqlite" --port 0 >"$TMP/serve.log" 2>&1 &
SERVE_PID=$!
URL=
for _ in $(seq 100); do
  URL=$(sed -nE 's#^daq serve: (http://[0-9.]+:[0-9]+/).*#\1#p' "$TMP/serve.log")
  [ -n "$URL" ] && break
  sleep 0.1
done
[ -n "$URL" ] || { echo "FAIL: daq serve did not start"; cat "$TMP/serve.log"; exit 1; }
check status_api 0 "\"running\":false.*\"tests\":\[\"linear\"" -- python3 -c "import urllib.request; print(urllib.request.urlopen('${URL}api/status').read().decode())"
check live_page 0 "live page: run 1" -- python3 "$TESTS/web/live_page_test.py" "$URL" "$TMP/live.png"
check served_log 0 "run 1 stopped: stopped from the web page" -- cat "$TMP/serve.log"
check stored 0 "aborted" -- "$DAQ" runs --db "$TMP/serve.sqlite"
# The stopped run has too few stops to evaluate: its report says so and shows what was stored.
check report_of_aborted 0 "written to $TMP/r.html" -- "$DAQ" report 1 --db "$TMP/serve.sqlite" -o "$TMP/r.html"
check report_says_why 0 "The results cannot be evaluated: .*run 1" -- cat "$TMP/r.html"
check report_status 0 "This run is aborted \(stopped from the web page\)" -- cat "$TMP/r.html"
finish
