#!/usr/bin/env bash
# Issue 35, central schema 12: what the fleet view and the sign-off count as a run's result, against
# a real PostgreSQL server started here (tests/cli/pg_server.sh).
# - The demo's linear run re-compensated on two laptops (alice's, then bob's: versions 2 and 3):
#   the fleet's JSON (/api/fleet, the machine's trend points and latest verdict) holds one point
#   per run, the current version's (bob's) E and M, computed here by hand from bob's stops (as
#   cli_pg_pull does), and one result awaiting approval; before, both laptops' results counted.
# - caldaq.approve records the approved result's own version (1, 2 or 3), not the current one.
# - daq's verdict stored with each result and read by the fleet: the circle's G at an exact tie
#   (2.0625 um against 2.062: cal::fixed_text writes 2.063, half away from zero: FAIL) and its
#   squareness just under one (2.0624999999999996 against 2.062: written 2.062: pass; the server's
#   former SQL took it at 15 digits, 2.0625, and rounded it to 2.063: a fail daq never showed).
# - A schema 11 server (results without verdicts, both laptops' results flagged current) migrated
#   by the next sync: every result judged by it, the flags by the new rule.
# Usage: pg_current_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo  # DB: run 1 linear (X), run 2 circle (XY)
SERVE_PID=
trap '[ -n "$SERVE_PID" ] && kill $SERVE_PID 2>/dev/null; pg_stop; rm -rf "$TMP" "$PGTMP"' EXIT
MACHINE=$(value "$DB" "SELECT name FROM machines")  # value: pg_server.sh's
# set_context DB RUN PYTHON: the run's settings' context edited (ctx) by a Python statement.
set_context() {
  "$PY" - "$1" "$2" "$3" <<'PY'
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
s = json.loads(db.execute("SELECT settings_json FROM runs WHERE id = ?", (int(sys.argv[2]),)).fetchone()[0])
ctx = s.setdefault("context", {})
exec(sys.argv[3])
db.execute("UPDATE runs SET settings_json = ? WHERE id = ?", (json.dumps(s), int(sys.argv[2])))
db.commit()
PY
}

# The circle (run 2): G 2.0625 um exactly (33/16: a tie at 3 decimals), squareness
# 2.0624999999999996 (the double below it), both against 2.062. By cal::fixed_text's rule
# (std::round of v x 1000, half away from zero): G is written 2.063 > 2.062, FAIL; the squareness
# 2.062, pass. The circle's verdict: FAIL of G alone.
"$PY" - "$DB" <<'PY'
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
rid, doc = db.execute("SELECT id, json FROM results WHERE run_id = 2 AND superseded_by IS NULL").fetchone()
d = json.loads(doc)
d["iso230_4"]["G_bi_um"] = 2.0625
sq = [x for x in d["diagnostics"] if x["key"] == "squareness"]
assert sq, "the demo's circle reports a squareness"
sq[0]["value"] = 2.0624999999999996
db.execute("UPDATE results SET json = ? WHERE id = ?", (json.dumps(d), rid))
db.commit()
PY
set_context "$DB" 2 'ctx["tolerances"] = {"G_um": 2.062, "diagnostics": {"squareness": 2.062}}'
check tie_shown 0 "G +2\.063 .*Squareness.* 2\.062 " -- bash -c "'$DAQ' show 2 --db '$DB' | tr '\n' ' '"
check sync 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check schema 0 "^13$" -- psql_value "SELECT version FROM caldaq.schema_version"
check tie_stored 0 "^fail G$" -- psql_value "SELECT verdict || ' ' || verdict_failed FROM caldaq.results WHERE run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 2)"

# Run 1 re-compensated on two laptops, alice's sent first (version 2), bob's then (3: current).
ALICE=$TMP/alice.sqlite
BOB=$TMP/bob.sqlite
check alice_pull 0 "" -- "$DAQ" sync --db "$ALICE" --from "$PG_URL" --machine "$MACHINE" --quiet
check bob_pull 0 "" -- "$DAQ" sync --db "$BOB" --from "$PG_URL" --machine "$MACHINE" --quiet
RUN1=$(psql_value "SELECT uuid FROM caldaq.runs WHERE id = 1")
A1=$(value "$ALICE" "SELECT id FROM runs WHERE uuid = '$RUN1'")
B1=$(value "$BOB" "SELECT id FROM runs WHERE uuid = '$RUN1'")
check alice_recompensate 0 "" -- "$DAQ" recompensate "$A1" --alpha-ppm 9.0 --db "$ALICE"
check bob_recompensate 0 "" -- "$DAQ" recompensate "$B1" --alpha-ppm 14.0 --db "$BOB"
# E and M (ISO 230-2) by hand from each laptop's stops: the mean deviation per target and
# direction; E the range of those means, M the range of the two directions' mean at each target
# (hand_em.py).
EM1=$("$PY" "$(dirname "$0")/hand_em.py" "$DB" 1)
EM2=$("$PY" "$(dirname "$0")/hand_em.py" "$ALICE" "$A1")
EM3=$("$PY" "$(dirname "$0")/hand_em.py" "$BOB" "$B1")
check em_differ 0 "^3$" -- bash -c "printf '%s\n' '$EM1' '$EM2' '$EM3' | sort -u | wc -l"
# E's limit half-way between alice's E and bob's: one of them passes, the other fails.
LIMIT=$("$PY" -c "import sys; print(f'{(float(sys.argv[1]) + float(sys.argv[2])) / 2:.3f}')" "${EM2% *}" "${EM3% *}")
BOB_VERDICT=$("$PY" -c "import sys; print('pass' if float(sys.argv[1]) < float(sys.argv[2]) else 'fail')" "${EM3% *}" "$LIMIT")
ALICE_VERDICT=$("$PY" -c "import sys; print('pass' if float(sys.argv[1]) < float(sys.argv[2]) else 'fail')" "${EM2% *}" "$LIMIT")
check verdicts_differ 0 "^differ$" -- bash -c "[ '$BOB_VERDICT' != '$ALICE_VERDICT' ] && echo differ"
set_context "$ALICE" "$A1" "ctx['tolerances'] = {'E_um': $LIMIT}"
set_context "$BOB" "$B1" "ctx['tolerances'] = {'E_um': $LIMIT}"
check alice_send 0 "kept as a new version" -- env USER=alice "$DAQ" sync --db "$ALICE" --to "$PG_URL" --run "$A1" --quiet
check bob_send 0 "kept as a new version" -- env USER=bob "$DAQ" sync --db "$BOB" --to "$PG_URL" --run "$B1" --quiet
check current_v3 0 "^3$" -- psql_value "SELECT current_version FROM caldaq.runs WHERE id = 1"
# The server's result ids of each version's current result (daq show --version N --json).
current_of() {
  "$DAQ" show 1 --version "$1" --json --db "$PG_URL" | "$PY" -c '
import json, sys
c = [r["id"] for r in json.load(sys.stdin)["results"] if r["current"]]
print(*c)'
}
R1=$(current_of 1)
R2=$(current_of 2)
R3=$(current_of 3)
check three_results 0 "^3$" -- bash -c "printf '%s\n' '$R1' '$R2' '$R3' | grep -c '^[0-9][0-9]*$'"
# daq's verdicts stored with each result (bob's pass or fail by hand, alice's the other).
check verdict_bob 0 "^$BOB_VERDICT$" -- psql_value "SELECT verdict FROM caldaq.results WHERE run_uuid = '$RUN1' AND source_result_id = $R3"
check verdict_alice 0 "^$ALICE_VERDICT$" -- psql_value "SELECT verdict FROM caldaq.results WHERE run_uuid = '$RUN1' AND source_result_id = $R2"

# The fleet view, by a login of the engineers' role (as pg_fleet_test.sh).
psql_value "CREATE ROLE rev LOGIN IN ROLE caldaq_reviewer; CREATE ROLE eng LOGIN IN ROLE caldaq_engineer; INSERT INTO caldaq.site_grants VALUES ('rev', '*'), ('eng', '*')" >/dev/null
REV="postgresql:///caldaq?host=$PGTMP&user=rev"
start_serve() {
  "$DAQ" serve --db "postgresql:///caldaq?host=$PGTMP&user=eng" --port 0 >"$TMP/serve.log" 2>&1 &
  SERVE_PID=$!
  for _ in $(seq 100); do grep -q "http://" "$TMP/serve.log" && break; sleep 0.1; done
  URL=http://127.0.0.1:$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$TMP/serve.log")
}
stop_serve() {
  kill "$SERVE_PID"
  wait "$SERVE_PID" 2>/dev/null
  SERVE_PID=
}
# fleet_checks NAME AWAITING_RUN1: the fleet's JSON against the hand values: one point per run
# (run 1's E and M bob's), run 1's latest verdict bob's result's (by hand), the circle's FAIL of G
# alone, and AWAITING_RUN1 results of run 1 awaiting approval (bob's, or none).
fleet_checks() {
  curl -sf -o "$TMP/fleet.json" "$URL/api/fleet" && curl -sf -o "$TMP/site.json" "$URL/api/fleet/first-site" &&
    curl -sf -o "$TMP/machine.json" "$URL/api/fleet/machines/$("$PY" -c 'import json, sys; print(json.load(open(sys.argv[1]))["machines"][0]["id"])' "$TMP/site.json")" || {
    echo "the fleet's JSON not read"
    return 1
  }
  "$PY" - "$TMP" "$EM3" "$LIMIT" "$BOB_VERDICT" "$R3" "$1" <<'PY'
import json, os, sys
tmp, em3, limit, verdict, r3, awaiting = sys.argv[1], sys.argv[2].split(), float(sys.argv[3]), sys.argv[4], int(sys.argv[5]), int(sys.argv[6])
load = lambda n: json.load(open(os.path.join(tmp, n)))  # noqa: E731
fleet, site, machine = load("fleet.json"), load("site.json"), load("machine.json")
failures = []
def need(cond, what):  # every failure told, not only the first
    if not cond:
        failures.append(what)
series = {(s["kind"], s["test"], s["key"]): s["points"] for s in machine["series"]}
for key, hand in (("E", em3[0]), ("M", em3[1])):
    pts = series.get(("linear", "X", key), [])
    need(len(pts) == 1, f"{key}: one point per run, not {pts}")
    need(pts and pts[0][2] == 1 and f"{pts[0][1]:.6f}" == hand, f"{key}: run 1's point {pts[0]}, by hand {hand} (bob's)")
need([p[3] for p in series.get(("linear", "X", "E"), [])] == [limit], f"E's limit {series.get(('linear', 'X', 'E'))}")
trend = [t for t in machine["trends"] if (t["kind"], t["test"], t["key"]) == ("linear", "X", "E")]
need(len(trend) == 1 and trend[0]["history_runs"] == 1 and f"{trend[0]['latest']:.6f}" == em3[0], f"E's trend {trend}")
verdicts = {(v["kind"], v["test"]): v for v in site["machines"][0]["verdicts"]}
x = verdicts[("linear", "X")]
need(x["run"] == 1 and x["result"] == r3 and x["verdict"] == verdict, f"X's latest verdict {x}, by hand {verdict} of result {r3}")
circle = [v for k, v in verdicts.items() if k[0] == "circle"]
need(len(circle) == 1 and circle[0]["verdict"] == "fail" and circle[0]["failed"] == "G", f"the circle's verdict {circle}")
aw = [r for r in fleet["awaiting_approval"]["results"] if r["run"] == 1]
need(len(aw) == awaiting and all(r["result"] == r3 for r in aw), f"run 1 awaiting approval {aw}")
need(fleet["awaiting_approval"]["count"] == awaiting + 1, f"awaiting {fleet['awaiting_approval']['count']}: run 1's and the circle's")
if failures:
    sys.exit("FAIL: " + "\nFAIL: ".join(failures))
print("fleet ok")
PY
}
start_serve
check fleet_current 0 "^fleet ok$" -- fleet_checks 1

# Sign-off: each version's result approved records its own version, the current one or not.
check approve_v1 0 "result $R1 approved by rev .*version 1 of its stops" -- "$DAQ" approve 1 --result "$R1" --db "$REV"
check approve_v2 0 "result $R2 approved by rev .*version 2 of its stops" -- "$DAQ" approve 1 --result "$R2" --db "$REV"
check approve_v3 0 "result $R3 approved by rev .*version 3 of its stops" -- "$DAQ" approve 1 --result "$R3" --db "$REV"
check approvals_recorded 0 "^$R1:1 $R2:2 $R3:3$" -- psql_value \
  "SELECT string_agg(s.source_result_id || ':' || a.run_version, ' ' ORDER BY s.source_result_id) FROM caldaq.approvals AS a JOIN caldaq.results AS s ON s.run_uuid = a.run_uuid AND s.fingerprint = a.result_fingerprint WHERE a.run_uuid = '$RUN1'"
# The run's result before alice's re-compensation: superseded in versions 2 and 3, current in 1.
check approve_again 2 "result $R1 is approved already" -- "$DAQ" approve 1 --result "$R1" --db "$REV"
# Version 1's report names version 1's approval; the current version's report bob's.
check show_v1_approved 0 "approved by rev" -- bash -c "'$DAQ' show 1 --version 1 --db '$PG_URL'"
check fleet_approved 0 "^fleet ok$" -- fleet_checks 0
stop_serve

# A schema 11 server: the results without verdicts, every result without a superseder flagged
# current (as schema 11's fleet flagged them); the next sync migrates it and judges every result.
pg_undo_central_12
psql_value "UPDATE caldaq.fleet_results SET current = true, verdict = 'none', failed = ''; UPDATE caldaq.fleet_values SET current = true" >/dev/null
check old_server 0 "^11 [1-9]" -- psql_value "SELECT version || ' ' || (SELECT count(*) FROM caldaq.results) FROM caldaq.schema_version"
TOTAL=$(psql_value "SELECT count(*) FROM caldaq.results")
check migrate_judges 0 "\"verdicts_judged\": $TOTAL\b" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --run 2 --json
check migrated 0 "^13 0$" -- psql_value "SELECT version || ' ' || (SELECT count(*) FROM caldaq.results WHERE verdict IS NULL) FROM caldaq.schema_version"
check migrated_verdicts 0 "^$BOB_VERDICT $ALICE_VERDICT fail G$" -- psql_value \
  "SELECT (SELECT verdict FROM caldaq.results WHERE run_uuid = '$RUN1' AND source_result_id = $R3) || ' ' || (SELECT verdict FROM caldaq.results WHERE run_uuid = '$RUN1' AND source_result_id = $R2) || ' ' || (SELECT verdict || ' ' || verdict_failed FROM caldaq.results WHERE run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 2))"
start_serve
check fleet_migrated 0 "^fleet ok$" -- fleet_checks 0
stop_serve
finish
