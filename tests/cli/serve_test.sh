#!/usr/bin/env bash
# daq serve end to end, across processes: `daq sim` runs the SIMULATED shop in its own process
# and waits for a run to start in the run database; `daq serve` serves its configuration; a run
# started through the API makes the simulated machine run the program, stops are captured, and
# the run is stopped through the API and listed, with its report. Refusals at the door: no
# configuration, a capture directory that cannot be created, an open address without a token.
# (The page itself is driven in a browser by tests/web/operator_page_test.py.)
# Usage: serve_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
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
check needs_a_configuration 2 "give -c FILE \(a configuration\) or --simulate" -- "$DAQ" serve --port 0
check config_or_simulate 2 "excludes" -- "$DAQ" serve -c x.toml --simulate --port 0
touch "$TMP/a-file"
check capture_dir_refused 2 "--capture-dir $TMP/a-file/caps: cannot be created" -- \
  "$DAQ" serve --simulate --port 0 --db "$TMP/x.sqlite" --capture-dir "$TMP/a-file/caps"

# daq sim waits for a run to start in the database the server writes.
"$DAQ" sim --speed 10 --db "$TMP/serve.sqlite" -o "$TMP/sim.toml" >"$TMP/sim.log" 2>&1 &
SIM_PID=$!
for _ in $(seq 100); do [ -s "$TMP/sim.toml" ] && break; sleep 0.1; done
"$DAQ" serve -c "$TMP/sim.toml" --db "$TMP/serve.sqlite" --port 0 --capture-dir "$TMP/caps" \
  >"$TMP/serve.log" 2>&1 &
SERVE_PID=$!
URL=
for _ in $(seq 100); do
  URL=$(sed -nE 's#^daq serve: (http://[0-9.]+:[0-9]+/).*#\1#p' "$TMP/serve.log")
  [ -n "$URL" ] && break
  sleep 0.1
done
[ -n "$URL" ] || { echo "FAIL: daq serve did not start"; cat "$TMP/serve.log"; exit 1; }
check capture_dir_made 0 "" -- test -d "$TMP/caps"
check status_api 0 "\"running\":false.*\"tests\":\[\"linear\",\"circle\"\]" -- python3 -c "import urllib.request; print(urllib.request.urlopen('${URL}api/status').read().decode())"
# Start once the instruments stream (the server refuses with the reason before).
cat >"$TMP/run.py" <<PY
import json, time, urllib.request, urllib.error
url = "$URL"
def post(path, body):
    req = urllib.request.Request(url + path, data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req) as r:
            return r.status, json.load(r)
    except urllib.error.HTTPError as e:
        return e.code, json.load(e)
for _ in range(300):
    status = json.load(urllib.request.urlopen(url + "api/status"))
    if status["start"]["linear"]["ready"]:
        break
    time.sleep(0.1)
print("ready:", status["start"]["linear"])
started = post("api/runs/start", {"test": "linear"})
for _ in range(600):  # the simulated machine starts the program once the run has begun
    run = json.load(urllib.request.urlopen(url + "api/runs/1"))
    if run["targets"] >= 3:
        break
    time.sleep(0.1)
stopped = post("api/runs/stop", {})
print(f"start: {started[0]} captured: {run['targets']} stop: {stopped[0]} {stopped[1]}")
PY
check run_through_the_api 0 "start: 202.*captured: [3-9].*stop: 200" -- python3 "$TMP/run.py"
check sim_saw_the_run 0 "run 1 \(linear\) started" -- cat "$TMP/sim.log"
check served_log 0 "run 1 stopped: stopped from the web page" -- cat "$TMP/serve.log"
check stored 0 "aborted" -- "$DAQ" runs --db "$TMP/serve.sqlite"
check capture_named_by_run 0 "run-1.cdq" -- ls "$TMP/caps"
check show_names_the_capture 0 "capture: $TMP/caps/run-1.cdq" -- "$DAQ" show 1 --db "$TMP/serve.sqlite"
check report_of_aborted 0 "written to $TMP/r.html" -- "$DAQ" report 1 --db "$TMP/serve.sqlite" -o "$TMP/r.html"
check report_status 0 "This run is aborted \(stopped from the web page\)" -- cat "$TMP/r.html"
finish
