#!/usr/bin/env bash
# Issue 35: the fleet view (daq serve --db postgresql://...) against a real PostgreSQL server
# started here (tests/cli/pg_server.sh). Two laptops measure two machines of two sites offline
# (two `daq demo` stores, shaped by fleet_stores.py to known values), sync to the server, a reviewer
# approves one result; the fleet's JSON is checked against values computed by hand (the trend's
# projection, the due dates, the verdicts, what awaits approval), the fleet's verdicts against
# daq show's, every write refused, and the page in headless Chromium (pg_fleet_page.py: a machine
# name with markup shown as text, a screenshot at 1366x768).
# Usage: pg_fleet_test.sh DAQ_BINARY [SCREENSHOT_DIR]
set -u
DAQ=$1
SHOTS=${2:-}

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo  # laptop A's store: DB
A=$DB
B=$TMP/laptopB/demo.sqlite
mkdir "$TMP/laptopB"
# Laptop B measures its own machine (another daq demo: its own machine and run UUIDs).
(cd "$TMP/laptopB" && "$DAQ" demo --quiet --db demo.sqlite --capture demo.cdq >demo.log 2>&1) ||
  { cat "$TMP/laptopB/demo.log"; echo "FAIL: laptop B's demo"; exit 1; }
TODAY=$(date -u +%F)
T0=$("$PY" "$(dirname "$0")/fleet_stores.py" "$A" "$B" "$TODAY") || { echo "FAIL: fleet_stores.py"; exit 1; }
SERVE_PID=
trap '[ -n "$SERVE_PID" ] && kill $SERVE_PID 2>/dev/null; pg_stop; rm -rf "$TMP" "$PGTMP"' EXIT

check sync_a 0 "runs synced" -- "$DAQ" sync --db "$A" --to "$PG_URL" --quiet
check sync_b 0 "runs synced" -- "$DAQ" sync --db "$B" --to "$PG_URL" --quiet
check schema 0 "^8$" -- psql_value "SELECT version FROM caldaq.schema_version"
# A reviewer approves laptop A's first linear run (server run 1).
psql_value "CREATE ROLE rev LOGIN IN ROLE caldaq_reviewer; CREATE ROLE eng LOGIN IN ROLE caldaq_engineer; INSERT INTO caldaq.site_grants VALUES ('rev', '*'), ('eng', '*')" >/dev/null
check approve 0 "approved by rev" -- "$DAQ" approve 1 --db "postgresql:///caldaq?host=$PGTMP&user=rev"

# The fleet's verdicts are daq's own: each current result's verdict as daq show --json gives it
# (verdict.cpp), against the fleet tables' (the server's triggers), for every run.
verdicts_agree() {
  local run show fleet n=0
  for run in $(psql_value "SELECT id FROM caldaq.runs ORDER BY id"); do
    show=$("$DAQ" show "$run" --db "$PG_URL" --json | "$PY" -c '
import json, sys
for r in sorted(json.load(sys.stdin)["results"], key=lambda r: r["id"]):
    if r["current"]:
        v = r.get("verdict") or {}
        s = {True: "pass", False: "fail"}.get(v.get("pass"), "none")
        print(s, ",".join(sorted(c["symbol"] for c in v.get("checks", []) if not c["pass"])))')
    fleet=$(psql_value "SELECT verdict || ' ' || replace(failed, ', ', ',') FROM caldaq.fleet_results WHERE run_id = $run AND current ORDER BY result_id")
    if [ "$show" != "$fleet" ]; then echo "run $run: daq show '$show', fleet '$fleet'"; return 1; fi
    n=$((n + 1))
  done
  echo "$n runs agree"
}
check verdicts_agree 0 "^6 runs agree$" -- verdicts_agree

# The fleet view: a reader that refuses what would write or acquire.
check refuse_config 2 "the fleet view, which only reads the central store: it takes no set-up" -- \
  "$DAQ" serve --db "$PG_URL" --simulate --port 0
check refuse_capture 2 "records no captures" -- "$DAQ" serve --db "$PG_URL" --capture-dir "$TMP/c" --port 0
check refuse_absent 2 "no caldaq central store in this database" -- \
  "$DAQ" serve --db "postgresql:///postgres?host=$PGTMP&user=caldaq" --port 0
"$DAQ" serve --db "postgresql:///caldaq?host=$PGTMP&user=eng" --port 0 >"$TMP/serve.log" 2>&1 &
SERVE_PID=$!
for _ in $(seq 100); do grep -q "http://" "$TMP/serve.log" && break; sleep 0.1; done
check serve_line 0 "the fleet view of postgresql:///caldaq.*reader only" -- cat "$TMP/serve.log"
PORT=$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$TMP/serve.log")
URL=http://127.0.0.1:$PORT
COUNTS="SELECT (SELECT count(*) FROM caldaq.runs) || ' ' || (SELECT count(*) FROM caldaq.results) || ' ' || (SELECT count(*) FROM caldaq.approvals)"
BEFORE=$(psql_value "$COUNTS")

check fleet_json 0 "" -- curl -sf -o "$TMP/fleet.json" "$URL/api/fleet"
check fleet_checks 0 "^fleet ok$" -- "$PY" - "$TMP/fleet.json" "$T0" "$TODAY" <<'EOF'
import datetime, json, sys
d = json.load(open(sys.argv[1]))
t0, today = int(sys.argv[2]), datetime.date.fromisoformat(sys.argv[3])
DAY = 86_400_000
def need(cond, what):
    if not cond:
        sys.exit(f"FAIL: {what}")
need(d["schema"] == "caldaq.fleet.v1" and d["today"] == today.isoformat(), "schema, today")
need(d["trend"]["min_runs"] == 3, "the stated minimum of runs")
# Machines by site (sites in byte order), the names as stored (markup is text in JSON).
need([s["site"] for s in d["sites"]] == ["Plant North", "Plant South"], f"sites {[s['site'] for s in d['sites']]}")
a, b = d["sites"][0]["machines"], d["sites"][1]["machines"]
need(len(a) == 1 and len(b) == 1, "one machine a site")
a, b = a[0], b[0]
need(a["name"].startswith("Mill <script>window.pwned=1</script>"), f"A's name {a['name']!r}")
need(b["name"] == "Lathe 2", "B's name")
need(a["last_run_unix_ms"] == t0 + 60 * DAY, "A's last run: the copy 60 days after the first")
# Latest verdicts: A's X linear is the run 60 days on (E 6 <= 10, M 2 <= 8): pass; B's fails on E.
va = {(v["kind"], v["test"]): v for v in a["verdicts"]}
vb = {(v["kind"], v["test"]): v for v in b["verdicts"]}
need(va[("linear", "X")]["verdict"] == "pass" and va[("linear", "X")]["started_unix_ms"] == t0 + 60 * DAY, f"A's X verdict {va}")
need(vb[("linear", "X")]["verdict"] == "fail" and vb[("linear", "X")]["failed"] == "E", f"B's X verdict {vb}")
circle_b = [v for k, v in vb.items() if k[0] == "circle"]
need(len(circle_b) == 1 and circle_b[0]["test"].startswith("XY F"), f"B's circle test {circle_b}")
# Trends, by hand: E = 4, 5, 6 um at 0, 30, 60 days: slope 1 um / 30 days = 365.25 / 30 um a
# year; the line E = 4 + t / 30 d reaches the 10 um limit at t = 180 d.
ta = {(t["kind"], t["test"], t["key"]): t for t in a["trends"]}
e = ta[("linear", "X", "E")]
need(e["runs"] == 3 and e["latest"] == 6.0 and e["limit"] == 10.0, f"A's E series {e}")
need(abs(e["slope_per_year"] - 365.25 / 30) < 1e-9, f"A's E slope {e['slope_per_year']}")
need(abs(e["fit_at_last"] - 6.0) < 1e-9, f"A's E line at the last run {e['fit_at_last']}")
need(e["status"] == "leaving" and abs(e["projected_unix_ms"] - (t0 + 180 * DAY)) <= 1, f"A's E projection {e}")
need(e["projected_date"] == datetime.datetime.fromtimestamp((t0 + 180 * DAY) / 1000, datetime.timezone.utc).date().isoformat(), "projected date")
m = ta[("linear", "X", "M")]
need(m["status"] == "steady" and m["slope_per_year"] == 0 and m["projected_unix_ms"] is None, f"A's M {m}")
g = [t for k, t in ta.items() if k[0] == "circle" and k[2] == "G"]
need(len(g) == 1 and g[0]["status"] == "not enough history" and g[0]["runs"] == 1
     and g[0]["test"] == "XY F1000 R100", f"A's G (the demo's limit, one run) {g}")
tb = {(t["kind"], t["test"], t["key"]): t for t in b["trends"]}
need(tb[("linear", "X", "E")]["status"] == "outside", "B's E outside (3.0 > 2.5)")
gb = [t for k, t in tb.items() if k[0] == "circle" and k[2] == "G"]
need(len(gb) == 1 and gb[0]["status"] == "not enough history" and gb[0]["projected_unix_ms"] is None, f"B's G {gb}")
# Instruments: due dates against today, flagged past due and within 30 days.
inst = {i["serial_number"]: i for i in d["instruments"]}
need(inst["L-100"]["status"] == "past due" and inst["L-100"]["days_left"] == -10, f"L-100 {inst['L-100']}")
need(inst["T-7"]["status"] == "due soon" and inst["T-7"]["days_left"] == 12, f"T-7 {inst['T-7']}")
need(inst["P-3"]["status"] == "ok" and inst["P-3"]["days_left"] == 200, f"P-3 {inst['P-3']}")
need(inst["L-100"]["site"] == "Plant North" and inst["L-100"]["machine"] == a["name"], "L-100's machine and site")
others = [i for i in d["instruments"] if i["site"] == "Plant South"]
need(others and all(i["status"] == "not stated" for i in others), f"B's instruments {others}")
# Awaiting approval: every current result but the approved one (run 1's): A has 4 runs (its linear
# run, two copies, its circle), B 2, one result each; 6 - 1 = 5.
aw = d["awaiting_approval"]
need(aw["count"] == 5 and aw["listed"] == 5, f"awaiting {aw['count']}")
need(1 not in [r["run"] for r in aw["results"]], "run 1 (approved) not awaiting")
need(aw["results"][0]["started_unix_ms"] >= aw["results"][-1]["started_unix_ms"], "newest first")
print("fleet ok")
EOF
MID=$("$PY" -c 'import json, sys; print(json.load(open(sys.argv[1]))["sites"][0]["machines"][0]["id"])' "$TMP/fleet.json")
check machine_history 0 '"points":\[\[[0-9]+,4(\.0)?,1,10(\.0)?\],\[[0-9]+,5(\.0)?,[0-9]+,10(\.0)?\],\[[0-9]+,6(\.0)?,[0-9]+,10(\.0)?\]\]' -- \
  curl -sf "$URL/api/fleet/machines/$MID"
check no_machine 0 "404" -- curl -s -o /dev/null -w "%{http_code}" "$URL/api/fleet/machines/999"
check bad_machine 0 "404" -- curl -s -o /dev/null -w "%{http_code}" "$URL/api/fleet/machines/1x"
# Every write refused, saying why; nothing changed on the server.
post() {  # post PATH: the status and the answer of POST {} to PATH
  local code
  code=$(curl -s -o "$TMP/answer" -w "%{http_code}" -X POST -H "Content-Type: application/json" -d '{}' "$URL$1")
  echo "$code $(cat "$TMP/answer")"
}
for path in /api/runs/start /api/runs/stop /api/setup/apply /api/compensation /api/anything; do
  check "refused_$path" 0 "^403 .*only reads the central store: nothing is written from this page" -- post "$path"
done
check nothing_written 0 "^$BEFORE$" -- psql_value "$COUNTS"
check page_served 0 "<title>caldaq — fleet</title>" -- curl -sf "$URL/"

# The page in headless Chromium: rendered, the markup name as text, a screenshot to look at.
check page 0 "page ok" -- "$PY" "$(dirname "$0")/pg_fleet_page.py" "$URL" "${SHOTS:-$TMP}"
kill $SERVE_PID
wait $SERVE_PID 2>/dev/null
SERVE_PID=
finish
