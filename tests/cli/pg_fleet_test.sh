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
check schema 0 "^13$" -- psql_value "SELECT version FROM caldaq.schema_version"
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
check verdicts_agree 0 "^21 runs agree$" -- verdicts_agree

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
eng_backends() {
  psql_value "SELECT string_agg(pid::text, ' ' ORDER BY pid) FROM pg_stat_activity WHERE usename = 'eng' AND backend_type = 'client backend'"
}
# Warmed before serving (docs/web.md): when the serve says where it listens, before any request,
# its 4 connections are open (each has read the first view), not only the one that checked the store.
check warmed_before_serving 0 "^4$" -- bash -c "echo '$(eng_backends)' | wc -w"
COUNTS="SELECT (SELECT count(*) FROM caldaq.runs) || ' ' || (SELECT count(*) FROM caldaq.results) || ' ' || (SELECT count(*) FROM caldaq.approvals)"
BEFORE=$(psql_value "$COUNTS")

check fleet_json 0 "" -- curl -sf -o "$TMP/fleet.json" "$URL/api/fleet"
check site_north 0 "" -- curl -sf -o "$TMP/north.json" "$URL/api/fleet/sites/Plant%20North/page/1"
check site_south 0 "" -- curl -sf -o "$TMP/south.json" "$URL/api/fleet/sites/Plant%20South/page/1"
MID=$("$PY" -c 'import json, sys; print(json.load(open(sys.argv[1]))["machines"][0]["id"])' "$TMP/north.json")
MIDB=$("$PY" -c 'import json, sys; print(json.load(open(sys.argv[1]))["machines"][0]["id"])' "$TMP/south.json")
SINCE=$("$PY" -c 'import datetime, sys; print(datetime.datetime.fromtimestamp(int(sys.argv[1]) / 1000 + 90 * 86400, datetime.timezone.utc).date())' "${T0% *}")
check machine_a 0 "" -- curl -sf -o "$TMP/a.json" "$URL/api/fleet/machines/$MID"
check machine_a_since 0 "" -- curl -sf -o "$TMP/a_since.json" "$URL/api/fleet/machines/$MID/since/$SINCE"
check machine_b 0 "" -- curl -sf -o "$TMP/b.json" "$URL/api/fleet/machines/$MIDB"
check fleet_checks 0 "^fleet ok$" -- "$PY" - "$TMP" $T0 "$TODAY" "$SINCE" <<'EOF'
import datetime, json, os, sys
tmp, t0, t0b = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
today, since = datetime.date.fromisoformat(sys.argv[4]), sys.argv[5]
load = lambda name: json.load(open(os.path.join(tmp, name)))  # noqa: E731
d, north, south = load("fleet.json"), load("north.json"), load("south.json")
ma, ma_since, mb = load("a.json"), load("a_since.json"), load("b.json")
DAY = 86_400_000
YEAR_DAYS = 365.25
def need(cond, what):
    if not cond:
        sys.exit(f"FAIL: {what}")
def date_of(ms):
    return datetime.datetime.fromtimestamp(ms / 1000, datetime.timezone.utc).date().isoformat()
need(d["schema"] == "caldaq.fleet.v2" and d["today"] == today.isoformat(), "schema, today")
need(d["trend"]["min_runs"] == 3 and d["machines_per_page"] == 25, "the stated minimum of runs, the page size")
# The first view: the sites with their counts (sites in byte order), no machine's trends in it.
need(d["machines"] == 2, f"machines {d['machines']}")
need([(s["site"], s["machines"]) for s in d["sites"]] == [("Plant North", 1), ("Plant South", 1)], f"sites {d['sites']}")
# A's latest verdicts: the angular run fails (E_BX 10 > 8 urad); B's X fails on E.
need([s["failing_machines"] for s in d["sites"]] == [1, 1], f"failing machines {d['sites']}")
need("trends" not in json.dumps(d["sites"]), "no trend in the first view")
# A site's page: its machines, each with its verdicts and counts of values leaving or outside.
need(north["count"] == 1 and north["pages"] == 1 and north["page"] == 1 and north["first"] == 1, f"north page {north}")
a, b = north["machines"][0], south["machines"][0]
need(a["name"].startswith("Mill <script>window.pwned=1</script>"), f"A's name {a['name']!r}")
need(b["name"] == "Lathe 2", "B's name")
need(a["last_run_unix_ms"] == t0 + 120 * DAY, "A's last run: Y's, 120 days after the first")
va = {(v["kind"], v["test"]): v for v in a["verdicts"]}
vb = {(v["kind"], v["test"]): v for v in b["verdicts"]}
need(va[("linear", "X")]["verdict"] == "pass" and va[("linear", "X")]["started_unix_ms"] == t0 + 60 * DAY, f"A's X verdict {va}")
need(va[("linear", "Y")]["verdict"] == "pass" and va[("linear", "Y")]["started_unix_ms"] == t0 + 120 * DAY, f"A's Y verdict {va}")
# The profile runs' verdicts, by hand: straightness 3.0 <= 4 (by_length's limit for 500 mm, not
# the axis's 9), E_BX range 10 > 8 urad, E_AX 5 <= 8.
need(va[("straightness", "E_YX")]["verdict"] == "pass" and va[("straightness", "E_YX")]["started_unix_ms"] == t0 + 60 * DAY, f"A's E_YX {va}")
need(va[("angular", "E_BX")]["verdict"] == "fail" and va[("angular", "E_BX")]["failed"] == "E_BX", f"A's E_BX {va}")
need(va[("roll", "E_AX")]["verdict"] == "pass", f"A's E_AX {va}")
need(len(a["verdicts"]) == 6 and len(b["verdicts"]) == 3, f"verdict counts {len(a['verdicts'])}, {len(b['verdicts'])}")
need(vb[("linear", "X")]["verdict"] == "fail" and vb[("linear", "X")]["failed"] == "E", f"B's X verdict {vb}")
need(vb[("linear", "Z")]["verdict"] == "pass", f"B's Z verdict {vb}")
circle_b = [v for k, v in vb.items() if k[0] == "circle"]
need(len(circle_b) == 1 and circle_b[0]["test"].startswith("XY F"), f"B's circle test {circle_b}")
# Counts on the page of machines: A's X E, Y E and E_YX leaving; E_BX and its circle's backlash
# (the demo's own limit, which its circle fails) outside. B's X E and its circle's squareness (the
# limit half its value) outside.
need(a["trends"]["leaving"] == 3 and a["trends"]["outside"] == 2 and a["trends"]["series"] == 12, f"A's counts {a['trends']}")
need(b["trends"]["leaving"] == 0 and b["trends"]["outside"] == 2 and b["trends"]["series"] == 8, f"B's counts {b['trends']}")
# Trends (the machine opened), by hand: X's E = 4, 5, 6 um at 0, 30, 60 days: slope 1 um / 30 days
# = 365.25 / 30 um a year; the line E = 4 + t / 30 d reaches the 10 um limit at t = 180 d. No
# table of X: the whole history.
need(ma["schema"] == "caldaq.fleet-machine.v2" and ma["site"] == "Plant North" and ma["since_unix_ms"] is None, "machine doc")
ta = {(t["kind"], t["test"], t["key"]): t for t in ma["trends"]}
e = ta[("linear", "X", "E")]
need(e["runs"] == 3 and e["history_runs"] == 3 and e["latest"] == 6.0 and e["limit"] == 10.0, f"A's E series {e}")
need(abs(e["slope_per_year"] - YEAR_DAYS / 30) < 1e-9, f"A's E slope {e['slope_per_year']}")
need(abs(e["fit_at_last"] - 6.0) < 1e-9, f"A's E line at the last run {e['fit_at_last']}")
need(e["status"] == "leaving" and abs(e["projected_unix_ms"] - (t0 + 180 * DAY)) <= 1, f"A's E projection {e}")
need(e["projected_date"] == date_of(t0 + 180 * DAY), "projected date")
need(e["window"] == {"from_unix_ms": None, "from_date": None, "reason": "all history", "detail": ""}, f"X's window {e['window']}")
m = ta[("linear", "X", "M")]
need(m["status"] == "steady" and m["slope_per_year"] == 0 and m["projected_unix_ms"] is None, f"A's M {m}")
# Y: the compensation table of Y stored at 45 d starts the line: (60, 3), (90, 3.5), (120, 4):
# 0.5 um / 30 d = 6.0875 um a year, reaching 10 um at 120 + 6 / 0.5 x 30 = 480 d; 3 of 5 runs.
y = ta[("linear", "Y", "E")]
need(y["runs"] == 3 and y["history_runs"] == 5 and y["first_unix_ms"] == t0 + 60 * DAY, f"Y's E runs {y}")
need(abs(y["slope_per_year"] - 0.5 * YEAR_DAYS / 30) < 1e-9 and abs(y["fit_at_last"] - 4.0) < 1e-9, f"Y's E line {y}")
need(y["status"] == "leaving" and abs(y["projected_unix_ms"] - (t0 + 480 * DAY)) <= 1, f"Y's E projection {y}")
need(y["window"]["reason"] == "compensation" and y["window"]["from_unix_ms"] == t0 + 45 * DAY
     and y["window"]["from_date"] == date_of(t0 + 45 * DAY) and y["window"]["detail"].startswith("table ")
     and "of axis Y (csv)" in y["window"]["detail"], f"Y's window {y['window']}")
ym = ta[("linear", "Y", "M")]
need(ym["window"]["reason"] == "compensation" and ym["runs"] == 3 and ym["status"] == "steady", f"Y's M {ym}")
# E_YX: 2.0, 2.5, 3.0 um at 0, 30, 60 d: 0.5 um / 30 d, reaching 4 um at 120 d; Y's positioning
# table is no cross table: the whole history.
s = ta[("straightness", "E_YX", "straightness_um")]
need(s["symbol"] == "E_YX" and s["unit"] == "um" and s["runs"] == 3 and s["limit"] == 4.0, f"E_YX {s}")
need(s["status"] == "leaving" and abs(s["projected_unix_ms"] - (t0 + 120 * DAY)) <= 1, f"E_YX projection {s}")
need(s["window"]["reason"] == "all history", f"E_YX window {s['window']}")
p = ta[("angular", "E_BX", "range")]
need(p["unit"] == "urad" and p["latest"] == 10.0 and p["limit"] == 8.0 and p["status"] == "outside", f"E_BX {p}")
r = ta[("roll", "E_AX", "range")]
need(r["latest"] == 5.0 and r["status"] == "not enough history" and r["runs"] == 1, f"E_AX {r}")
g = [t for k, t in ta.items() if k[0] == "circle" and k[2] == "G"]
need(len(g) == 1 and g[0]["status"] == "not enough history" and g[0]["runs"] == 1
     and g[0]["test"] == "XY F1000 R100", f"A's G (the demo's limit, one run) {g}")
# A chosen day (90 d after the first run) later than Y's table: Y's line from it, 2 runs.
need(ma_since["since_unix_ms"] is not None and date_of(ma_since["since_unix_ms"]) == since, "since echoed")
ts = {(t["kind"], t["test"], t["key"]): t for t in ma_since["trends"]}
ys = ts[("linear", "Y", "E")]
need(ys["runs"] == 2 and ys["history_runs"] == 5 and ys["status"] == "not enough history"
     and ys["window"]["reason"] == "since chosen" and ys["window"]["from_date"] == since, f"Y since {ys}")
need(ts[("straightness", "E_YX", "straightness_um")]["runs"] == 0, "E_YX since: no run in the window")
# B: X's E 3.0 > 2.5 outside; Z: the control's compensation switched on at 60 d: 2.0 flat, steady
# (3 of 5 runs; over all five the line would rise).
tb = {(t["kind"], t["test"], t["key"]): t for t in mb["trends"]}
need(tb[("linear", "X", "E")]["status"] == "outside", "B's E outside (3.0 > 2.5)")
z = tb[("linear", "Z", "E")]
need(z["status"] == "steady" and z["runs"] == 3 and z["history_runs"] == 5 and abs(z["slope_per_year"]) < 1e-9, f"B's Z {z}")
need(z["window"]["reason"] == "controller compensation switched on" and z["window"]["from_unix_ms"] == t0b + 60 * DAY
     and z["window"]["detail"].startswith("run "), f"B's Z window {z['window']}")
gb = [t for k, t in tb.items() if k[0] == "circle" and k[2] == "G"]
need(len(gb) == 1 and gb[0]["status"] == "not enough history" and gb[0]["projected_unix_ms"] is None, f"B's G {gb}")
# Instruments: due dates against today, flagged past due and within 30 days.
ins = d["instruments"]
need(ins["count"] == len(ins["list"]) == ins["listed"], f"instruments listed {ins['count']} {ins['listed']}")
inst = {i["serial_number"]: i for i in ins["list"]}
need(inst["L-100"]["status"] == "past due" and inst["L-100"]["days_left"] == -10, f"L-100 {inst['L-100']}")
need(inst["T-7"]["status"] == "due soon" and inst["T-7"]["days_left"] == 12, f"T-7 {inst['T-7']}")
need(inst["P-3"]["status"] == "ok" and inst["P-3"]["days_left"] == 200, f"P-3 {inst['P-3']}")
need(inst["L-100"]["site"] == "Plant North" and inst["L-100"]["machine"] == a["name"], "L-100's machine and site")
need(ins["list"][0]["serial_number"] == "L-100", "the earliest due first")
others = [i for i in ins["list"] if i["site"] == "Plant South"]
need(others and all(i["status"] == "not stated" for i in others), f"B's instruments {others}")
need(ins["statuses"]["past due"] == 1 and ins["statuses"]["due soon"] == 1 and ins["statuses"]["ok"] == 1
     and ins["statuses"]["not stated"] == len(others), f"statuses {ins['statuses']}")
# Awaiting approval: every current result but the approved one (run 1's): A has 14 runs (X three,
# Y five, its circle, three straightness, an angular and a roll run), B 7 (X, its circle, Z five),
# one result each; 21 - 1 = 20.
aw = d["awaiting_approval"]
need(aw["count"] == 20 and aw["listed"] == 20, f"awaiting {aw['count']}")
need(1 not in [r["run"] for r in aw["results"]], "run 1 (approved) not awaiting")
need(aw["results"][0]["started_unix_ms"] >= aw["results"][-1]["started_unix_ms"], "newest first")
print("fleet ok")
EOF
check machine_history 0 '"points":\[\[[0-9]+,4(\.0)?,1,10(\.0)?\],\[[0-9]+,5(\.0)?,[0-9]+,10(\.0)?\],\[[0-9]+,6(\.0)?,[0-9]+,10(\.0)?\]\]' -- \
  curl -sf "$URL/api/fleet/machines/$MID"
check bad_since 0 "404 .*'2026-02-30' is not a date" -- sh -c "curl -s -w '%{http_code} ' -o '$TMP/since' '$URL/api/fleet/machines/$MID/since/2026-02-30'; cat '$TMP/since'"
check no_site 0 "404 .*no machine of site 'Plant West' on page 1" -- sh -c "curl -s -w '%{http_code} ' -o '$TMP/site' '$URL/api/fleet/sites/Plant%20West/page/1'; cat '$TMP/site'"
check no_page 0 "404" -- curl -s -o /dev/null -w "%{http_code}" "$URL/api/fleet/sites/Plant%20North/page/2"
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
check page 0 "page ok" -- "$PY" "$(dirname "$0")/pg_fleet_page.py" "$URL" "${SHOTS:-$TMP}" few "$SINCE"

# Paging: 30 machines more at Plant North (no runs), 25 a page in byte order of their names:
# page 1 Machine 01 - 25, page 2 Machine 26 - 30 and then "Mill <script>..." ('a' < 'i').
psql_value "INSERT INTO caldaq.machines(name, uuid, site) SELECT format('Machine %s', lpad(i::text, 2, '0')), gen_random_uuid(), 'Plant North' FROM generate_series(1, 30) AS i" >/dev/null
check north_page_2 0 "" -- curl -sf -o "$TMP/north2.json" "$URL/api/fleet/sites/Plant%20North/page/2"
check paged_json 0 "^paged ok$" -- "$PY" - "$TMP/north2.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
names = [m["name"] for m in d["machines"]]
if (d["count"], d["pages"], d["page"], d["first"]) != (31, 2, 2, 26) or len(names) != 6:
    sys.exit(f"FAIL: page 2 {d['count']} {d['pages']} {d['page']} {d['first']} {names}")
if names[:5] != [f"Machine {i}" for i in range(26, 31)] or not names[5].startswith("Mill <script>"):
    sys.exit(f"FAIL: page 2's names {names}")
print("paged ok")
EOF
check paged_page 0 "page ok" -- "$PY" "$(dirname "$0")/pg_fleet_page.py" "$URL" "${SHOTS:-$TMP}" paged

# A few connections, kept (issue 35): the serve's connections to the server (login eng) stay
# between requests, at most 4 of them however many requests come at once, and the same ones
# answer the next requests (a connection per request, as before, left none open between them).
at_once() {  # 24 requests for machine MID, 12 at a time: how many answered as the first did
  local i n=0
  for i in $(seq 24); do curl -sf -o "$TMP/c$i.json" "$URL/api/fleet/machines/$MID" & [ $((i % 12)) -eq 0 ] && wait; done
  for i in $(seq 24); do cmp -s "$TMP/c1.json" "$TMP/c$i.json" && n=$((n + 1)); done
  echo "$n answered alike"
}
check pool_at_once 0 "^24 answered alike$" -- at_once
KEPT=$(eng_backends)
check pool_bounded 0 "^[1-4]$" -- bash -c "echo '$KEPT' | wc -w"
curl -sf -o /dev/null "$URL/api/fleet"
check pool_reused 0 "^$KEPT$" -- eng_backends
# The server restarted under the running serve: its kept connections are broken; the next
# request is answered (on a new connection), as are those after it.
check pg_restart 0 "" -- pg_as_owner "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m fast -w restart -l "$PG_DIR/server.log"
check after_restart 0 "^200 .*caldaq.fleet.v2" -- bash -c "curl -s -o '$TMP/after.json' -w '%{http_code} ' '$URL/api/fleet'; cat '$TMP/after.json'"
check after_restart_all 0 "^24 answered alike$" -- at_once
AFTER=$(eng_backends)
check new_connections 0 "^differ [1-4]$" -- bash -c "[ '$AFTER' != '$KEPT' ] && echo differ \$(echo '$AFTER' | wc -w)"
kill $SERVE_PID
wait $SERVE_PID 2>/dev/null
SERVE_PID=
finish
