#!/usr/bin/env bash
# Issue 35: daq sync --from postgresql://... --machine NAME brings a machine's history into a
# local store (a laptop before a visit), against a real PostgreSQL server started here
# (tests/cli/pg_server.sh): the demo's runs (with a replay, a re-compensation, a compensation
# table and a ballbar calibration) sent, brought into a store whose run ids differ (every chunk's
# checksum checked, the UUIDs kept, every read command's output the same), brought again (nothing
# twice), cut and resumed, sent back (nothing twice), a result made on the laptop carried both
# ways, a damaged chunk on the server refused.
# Usage: pg_pull_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_visit
MACHINE=$("$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute('SELECT name FROM machines ORDER BY id').fetchone()[0])" "$DB")

# rows DB: what a store holds, by UUID (not by local id): runs, results, chunks with the md5 of
# their bytes, stops, compensation tables, calibrations; the same text for the same history.
rows() {
  "$PY" - "$1" <<'PY'
import hashlib, sqlite3, sys
c = sqlite3.connect(sys.argv[1])
md5 = lambda *v: hashlib.md5("|".join(str(x) for x in v).encode()).hexdigest()
lines = []
for r in c.execute("SELECT uuid, kind, axis, status, started_unix_ms, ended_unix_ms, settings_json FROM runs"):
    lines.append(("run",) + r)
for r in c.execute("SELECT u.uuid, s.standard, s.created_unix_ms, s.json, s.provenance_json, "
                   "s.superseded_by IS NULL FROM results s JOIN runs u ON u.id = s.run_id"):
    lines.append(("result", r[0], r[1], r[2], md5(r[3], r[4]), r[5]))
for u, seq, data in c.execute("SELECT r.uuid, k.seq, k.data FROM reading_chunks k JOIN runs r ON r.id = k.run_id"):
    lines.append(("chunk", u, seq, hashlib.md5(data).hexdigest()))
for r in c.execute("SELECT u.uuid, t.run_number, t.direction, t.target_index, t.deviation_um "
                   "FROM captured_targets t JOIN runs u ON u.id = t.run_id"):
    lines.append(("stop",) + r)
for r in c.execute("SELECT source, axis, format, created_unix_ms, json FROM compensations"):
    lines.append(("compensation", r[0], r[1], r[2], r[3], md5(r[4])))
for r in c.execute("SELECT bar, nominal_mm, calibrated_unix_ms FROM ballbar_calibrations"):
    lines.append(("calibration",) + r)
for l in lines:
    print(*l)
PY
}
# same_rows NAME A B: the two stores hold the same history (not vacuously: runs and chunks).
same_rows() {
  rows "$2" | sort >"$TMP/a.txt"
  rows "$3" | sort >"$TMP/b.txt"
  check "$1" 0 "^same [1-9][0-9]* lines, [1-9][0-9]* chunks$" -- bash -c \
    "diff '$TMP/a.txt' '$TMP/b.txt' | head -5 && cmp -s '$TMP/a.txt' '$TMP/b.txt' && echo same \$(wc -l <'$TMP/a.txt') lines, \$(grep -c ^chunk '$TMP/a.txt') chunks"
}

# same_targets NAME DB_A RUN_A DB_B RUN_B [OPTION...]: the two runs' stops exported alike (not
# vacuously: some rows); the options go to the second export (--version N).
same_targets() {
  check "$1" 0 "^same [1-9]" -- bash -c \
    "diff <('$DAQ' export $3 --what targets --db '$2') <('$DAQ' export $5 --what targets --db '$4' ${*:6}) && echo same \$('$DAQ' export $3 --what targets --db '$2' | wc -l)"
}

RUNS=$(value "$DB" "SELECT count(*) FROM runs")
CHUNKS=$(value "$DB" "SELECT count(*) FROM reading_chunks")
RESULTS=$(value "$DB" "SELECT count(*) FROM results")

# Refused: no machine, an unknown machine, an unreachable server (nothing created by any), both
# directions, not a URI.
check no_machine 2 "--from needs --machine NAME" -- "$DAQ" sync --db "$TMP/laptop.sqlite" --from "$PG_URL"
check unknown_machine 2 "no machine 'Mill 9' in the central store" -- \
  "$DAQ" sync --db "$TMP/laptop.sqlite" --from "$PG_URL" --machine "Mill 9"
check unknown_uuid 2 "no machine '0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b' in the central store" -- \
  "$DAQ" sync --db "$TMP/laptop.sqlite" --from "$PG_URL" --machine 0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b
check unknown_escaped 2 'no machine .Mill\\x1B\[2J. in the central store' -- \
  "$DAQ" sync --db "$TMP/laptop.sqlite" --from "$PG_URL" --machine $'Mill\e[2J'
check from_unreachable 2 "postgresql://127\.0\.0\.1:1/caldaq: connect" -- \
  "$DAQ" sync --db "$TMP/laptop.sqlite" --from postgresql://127.0.0.1:1/caldaq --machine "$MACHINE"
check refused_nothing_created 0 "^none$" -- bash -c "ls '$TMP'/laptop.sqlite* 2>/dev/null || echo none"
check both_ways 2 "give one of --to .* and --from" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --from "$PG_URL" --machine x
check from_not_uri 2 "--from: '/tmp/x.sqlite' is not a PostgreSQL URI" -- "$DAQ" sync --db "$DB" --from /tmp/x.sqlite --machine x

# The laptop already holds a run of its own: the runs brought get other ids than on the server
# and in the store that sent them (whose ids their checksums cover), so every checksum is
# checked across ids.
LAPTOP=$TMP/laptop.sqlite
check laptop_own_run 0 "" -- "$DAQ" replay "$DEMO_CDQ" --db "$LAPTOP"
# ... of another machine (a replay records the capture's machine: renamed, it is the bench's).
"$PY" -c "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); c.execute(\"UPDATE machines SET name = 'Bench'\"); c.commit()" "$LAPTOP"
check pull 0 "$RUNS runs of machine '$MACHINE' brought from .*: $RUNS new, $RESULTS new results; $CHUNKS chunks received \([1-9][0-9]* bytes\), 0 already here; 1 compensation tables, 1 ballbar calibrations, 0 approvals new; 0 runs' operator actions refreshed" -- \
  "$DAQ" sync --db "$LAPTOP" --from "$PG_URL" --machine "$MACHINE"
check pull_ids_shifted 0 "^$((RUNS + 1))$" -- value "$LAPTOP" "SELECT max(id) FROM runs"
"$PY" - "$LAPTOP" <<'PY'
import sqlite3, sys
c = sqlite3.connect(sys.argv[1]); c.execute("PRAGMA foreign_keys = OFF")
# A copy without the laptop's own run: the same history as the store that sent it.
c.execute("DELETE FROM reading_chunks WHERE run_id = 1"); c.execute("DELETE FROM results WHERE run_id = 1")
c.execute("DELETE FROM captured_targets WHERE run_id = 1"); c.execute("DELETE FROM instruments WHERE run_id = 1")
c.execute("DELETE FROM runs WHERE id = 1"); c.commit()
PY
same_rows pull_same_history "$DB" "$LAPTOP"
# Every chunk readable with its checksum for the laptop's ids, and the readings the same.
check pull_export_same 0 "^same [1-9]" -- bash -c \
  "diff <('$DAQ' export 1 --db '$DB') <('$DAQ' export 2 --db '$LAPTOP') >/dev/null && echo same \$('$DAQ' export 1 --db '$DB' | wc -l)"
# (the results numbered by each store: the laptop's own run took result 1)
check pull_show_same 0 "^same$" -- bash -c \
  "diff <('$DAQ' show 1 --db '$DB' | grep -v '^Run 1\|run 1\b' | sed 's/result [0-9]*/result N/g') <('$DAQ' show 2 --db '$LAPTOP' | grep -v '^Run 2\|run 2\b' | sed 's/result [0-9]*/result N/g') && echo same"
check pull_results_superseded 0 "^$(value "$DB" "SELECT count(*) FROM results WHERE superseded_by IS NOT NULL")$" -- \
  value "$LAPTOP" "SELECT count(*) FROM results WHERE superseded_by IS NOT NULL"

# Brought again: nothing twice, every chunk here checked against the server's checksum.
check pull_again 0 "$RUNS runs .*: 0 new, 0 new results; 0 chunks received \(0 bytes\), $CHUNKS already here; 0 compensation tables, 0 ballbar calibrations, 0 approvals new; 0 runs' operator actions refreshed" -- \
  "$DAQ" sync --db "$LAPTOP" --from "$PG_URL" --machine "$MACHINE"
same_rows pull_again_same "$DB" "$LAPTOP"

# The operator's actions refreshed on a pull: a manual capture and a skip of run 2 recorded at the
# machine after the laptop brought the run (written into its store as daq run writes them), sent,
# and brought again: the laptop has them as the server has them, once.
"$PY" - "$DB" <<'PY'
import sqlite3, sys
c = sqlite3.connect(sys.argv[1])
for row in [(1764000000000, 'capture', 'web page', 3, 150.0, 'captured by hand: 12.3 um'),
            (1764000001000, 'skip', 'keyboard (daq run)', 4, 200.0, 'skipped: the probe was off')]:
    c.execute("INSERT INTO operator_actions(run_id, time_unix_ms, action, source, operator, "
              "run_number, direction, target_index, nominal_mm, detail) "
              "VALUES (2, ?, ?, ?, 'J. Smith', 1, '+', ?, ?, ?)", row)
c.commit()
PY
LAPTOP2=$(value "$LAPTOP" "SELECT id FROM runs WHERE uuid = '$(value "$DB" "SELECT uuid FROM runs WHERE id = 2")'")
check actions_none_yet 0 "^0$" -- value "$LAPTOP" "SELECT count(*) FROM operator_actions WHERE run_id = $LAPTOP2"
check actions_sent 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check actions_refreshed 0 "0 new, 0 new results; 0 chunks received .*, 0 approvals new; 1 runs' operator actions refreshed" -- \
  "$DAQ" sync --db "$LAPTOP" --from "$PG_URL" --machine "$MACHINE"
check actions_here 0 "operator actions \(2\): +2025-11-24T16:00:00Z capture from the web page by J\. Smith: captured by hand: 12\.3 um +2025-11-24T16:00:01Z skip from the keyboard \(daq run\) by J\. Smith: skipped: the probe was off" -- \
  bash -c "'$DAQ' show $LAPTOP2 --db '$LAPTOP' | tr '\n' ' '"
check actions_same 0 "^same$" -- bash -c \
  "diff <('$DAQ' show 2 --json --db '$DB' | '$PY' -c 'import json, sys; print(json.load(sys.stdin)[\"operator_actions\"])') <('$DAQ' show $LAPTOP2 --json --db '$LAPTOP' | '$PY' -c 'import json, sys; print(json.load(sys.stdin)[\"operator_actions\"])') && echo same"
check actions_once 0 "0 runs' operator actions refreshed" -- "$DAQ" sync --db "$LAPTOP" --from "$PG_URL" --machine "$MACHINE"
check actions_count 0 "^2$" -- value "$LAPTOP" "SELECT count(*) FROM operator_actions WHERE run_id = $LAPTOP2"

# A run brought while it was still running there (a sync during its acquisition leaves it so on
# the server: here run 2 set back to running, its last chunk not there yet) stays running here
# until a later pull brings its end with its last chunk, not only the chunk.
UUID2=$(psql_value "SELECT uuid FROM caldaq.runs WHERE id = 2")
ENDED2=$(psql_value "SELECT ended_unix_ms FROM caldaq.runs WHERE id = 2")
LAST2=$(psql_value "SELECT max(seq) FROM caldaq.reading_chunks WHERE run_uuid = '$UUID2'")
psql_value "CREATE TABLE caldaq.held AS SELECT * FROM caldaq.reading_chunks WHERE run_uuid = '$UUID2' AND seq = $LAST2; DELETE FROM caldaq.reading_chunks WHERE run_uuid = '$UUID2' AND seq = $LAST2; UPDATE caldaq.runs SET status = 'running', ended_unix_ms = NULL WHERE id = 2" >/dev/null
RUNNING=$TMP/running.sqlite
check pull_while_running 0 "runs of machine" -- "$DAQ" sync --db "$RUNNING" --from "$PG_URL" --machine "$MACHINE" --quiet
check running_here 0 "^running None $LAST2$" -- \
  value "$RUNNING" "SELECT status || ' ' || ifnull(ended_unix_ms, 'None') || ' ' || (SELECT count(*) FROM reading_chunks k WHERE k.run_id = r.id) FROM runs r WHERE uuid = '$UUID2'"
psql_value "INSERT INTO caldaq.reading_chunks SELECT * FROM caldaq.held; DROP TABLE caldaq.held; UPDATE caldaq.runs SET status = 'complete', ended_unix_ms = $ENDED2 WHERE id = 2" >/dev/null
check pull_after_end 0 "0 new, 0 new results; 1 chunks received" -- "$DAQ" sync --db "$RUNNING" --from "$PG_URL" --machine "$MACHINE" --quiet
check ended_here 0 "^complete $ENDED2 $((LAST2 + 1))$" -- \
  value "$RUNNING" "SELECT status || ' ' || ifnull(ended_unix_ms, 'None') || ' ' || (SELECT count(*) FROM reading_chunks k WHERE k.run_id = r.id) FROM runs r WHERE uuid = '$UUID2'"
same_rows running_same_history "$DB" "$RUNNING"

# Sent back from the laptop: nothing twice on the server (the results known by their content,
# the chunks by their checksums for the ids of the store that first sent them).
check send_back 0 "$RUNS runs synced .*: 0 new; 0 chunks sent \(0 bytes\), $CHUNKS already there" -- \
  "$DAQ" sync --db "$LAPTOP" --to "$PG_URL" --verify
check send_back_results 0 "^$RESULTS$" -- psql_value "SELECT count(*) FROM caldaq.results"
check send_back_chunks 0 "^$CHUNKS$" -- psql_value "SELECT count(*) FROM caldaq.reading_chunks"

# A result made on the laptop (a re-analysis) goes to the server once and from there to the
# store that sent the run, where it supersedes the result it superseded on the laptop.
check laptop_analyse 0 "" -- "$DAQ" analyse 2 --store --db "$LAPTOP"
check laptop_send 0 "0 new" -- "$DAQ" sync --db "$LAPTOP" --to "$PG_URL" --quiet
check laptop_send_again 0 "0 new" -- "$DAQ" sync --db "$LAPTOP" --to "$PG_URL" --quiet
check laptop_result_once 0 "^$((RESULTS + 1))$" -- psql_value "SELECT count(*) FROM caldaq.results"
check back_home 0 "0 new, 1 new results; 0 chunks received" -- \
  "$DAQ" sync --db "$DB" --from "$PG_URL" --machine "$MACHINE" --quiet
check back_home_superseded 0 "^$(value "$LAPTOP" "SELECT count(*) FROM results WHERE superseded_by IS NOT NULL")$" -- \
  value "$DB" "SELECT count(*) FROM results WHERE superseded_by IS NOT NULL"
same_rows back_home_same "$DB" "$LAPTOP"

# A pull cut mid-transaction (after its 10th chunk, pages of 4: two committed), then resumed:
# nothing lost, nothing twice.
CUT=$TMP/cut.sqlite
check cut 75 "" -- env CALDAQ_SYNC_CUT_AFTER_CHUNKS=10 "$DAQ" sync --db "$CUT" --from "$PG_URL" --machine "$MACHINE" --chunks-per-transaction 4
check cut_committed 0 "^8$" -- value "$CUT" "SELECT count(*) FROM reading_chunks"
check resume 0 "$RUNS runs .*: $((RUNS - 1)) new, [0-9]+ new results; $((CHUNKS - 8)) chunks received .*, 8 already here" -- \
  "$DAQ" sync --db "$CUT" --from "$PG_URL" --machine "$MACHINE" --chunks-per-transaction 4 --quiet
same_rows resume_same "$LAPTOP" "$CUT"

# Conflicts kept as versions: run 1 re-compensated on two laptops, alice's and bob's, each sent.
# The server keeps the three sets of stops (none overwritten) with who sent them, from where and
# when, and both new results; the newest is what the read commands read; daq show names them.
ALICE=$TMP/alice.sqlite
BOB=$TMP/bob.sqlite
RUN1=$(psql_value "SELECT uuid FROM caldaq.runs WHERE id = 1")
check alice_pull 0 "" -- "$DAQ" sync --db "$ALICE" --from "$PG_URL" --machine "$MACHINE" --quiet
check bob_pull 0 "" -- "$DAQ" sync --db "$BOB" --from "$PG_URL" --machine "$MACHINE" --quiet
check alice_recompensate 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 9.0 --db "$ALICE"
check bob_recompensate 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 14.0 --db "$BOB"
check alice_send 0 "; 1 runs' stops differ from the server's: kept as a new version" -- \
  env USER=alice "$DAQ" sync --db "$ALICE" --to "$PG_URL" --run 1 --quiet
check bob_send 0 "; 1 runs' stops differ from the server's: kept as a new version" -- \
  env USER=bob "$DAQ" sync --db "$BOB" --to "$PG_URL" --run 1 --quiet
check versions_kept 0 "^1 2 3$" -- psql_value "SELECT string_agg(version::text, ' ' ORDER BY version) FROM caldaq.run_versions WHERE run_uuid = '$RUN1'"
check stops_kept 0 "^3$" -- psql_value "SELECT count(DISTINCT version) FROM caldaq.captured_targets WHERE run_uuid = '$RUN1'"
check others_one_version 0 "^1$" -- psql_value "SELECT max(current_version) FROM caldaq.runs WHERE uuid <> '$RUN1'"
check versions_who 0 "^2 alice .*alice.sqlite\|3 bob .*bob.sqlite$" -- \
  psql_value "SELECT string_agg(version || ' ' || sent_by || ' ' || sent_from || ' ' || sent_store, '|' ORDER BY version) FROM caldaq.run_versions WHERE run_uuid = '$RUN1' AND version > 1"
check both_results_current 0 "^2$" -- psql_value "SELECT count(*) FROM caldaq.results WHERE run_uuid = '$RUN1' AND superseded_by IS NULL"
check show_versions 0 "versions \(3; the run was changed in more than one place, none overwritten\): +version 1: [0-9]+ stops, sent .* +version 2: [0-9]+ stops, sent [0-9T:-]+.* by alice from .* \(.*alice.sqlite\) +version 3 \(current, shown\): [0-9]+ stops, sent .* by bob from .*bob.sqlite" -- \
  bash -c "'$DAQ' show 1 --db '$PG_URL' | tr '\n' ' '"
check show_json_versions 0 "^3 bob True$" -- bash -c \
  "'$DAQ' show 1 --json --db '$PG_URL' | '$PY' -c 'import json, sys; v = json.load(sys.stdin)[\"versions\"]; print(len(v), v[-1][\"sent_by\"], v[-1][\"current\"])'"
# The current version's stops are bob's, as his laptop has them.
same_targets current_is_bobs "$BOB" 1 "$PG_URL" 1
# Sent again by either: nothing new; the current version stays bob's.
check alice_again 0 "0 new; 0 chunks sent \(0 bytes\), [0-9]+ already there$" -- \
  env USER=alice "$DAQ" sync --db "$ALICE" --to "$PG_URL" --run 1 --quiet
check still_three 0 "^3 3$" -- psql_value "SELECT count(*) || ' ' || max(r.current_version) FROM caldaq.run_versions v JOIN caldaq.runs r ON r.uuid = v.run_uuid WHERE v.run_uuid = '$RUN1'"
# A store without the conflict reads as one version: nothing named.
check show_one_version 0 "^none$" -- bash -c "'$DAQ' show 2 --db '$PG_URL' | grep -q versions && echo named || echo none"

# Every version readable, and one brought (issue 35): daq show, export and analyse read version N
# of run 1 with --version N; a laptop that lacks the run brings alice's version with --version
# RUN:N. The stops compared are those of the stores that sent each version (version 1: the
# store first sent; 2: alice's laptop), read there, never the server's own output.
ALICE1=$(value "$ALICE" "SELECT id FROM runs WHERE uuid = '$RUN1'")
check versions_differ 0 "^differ$" -- bash -c \
  "cmp -s <('$DAQ' export 1 --what targets --db '$DB') <('$DAQ' export $ALICE1 --what targets --db '$ALICE') && echo same || echo differ"
same_targets version1_is_first "$DB" 1 "$PG_URL" 1 --version 1
same_targets version2_is_alices "$ALICE" "$ALICE1" "$PG_URL" 1 --version 2
check show_version1 0 "version 1 \(shown\): [0-9]+ stops.* version 3 \(current\): .*the stops counted above are version 1's, not the current version's" -- \
  bash -c "'$DAQ' show 1 --version 1 --db '$PG_URL' | tr '\n' ' '"
check show_json_version2 0 "^2 False$" -- bash -c \
  "'$DAQ' show 1 --version 2 --json --db '$PG_URL' | '$PY' -c 'import json, sys; v = [x for x in json.load(sys.stdin)[\"versions\"] if x[\"shown\"]]; print(v[0][\"version\"], v[0][\"current\"]) if len(v) == 1 else print(v)'"
check analyse_version2_is_alices 0 "^same [1-9]" -- bash -c \
  "diff <('$DAQ' analyse $ALICE1 --db '$ALICE') <('$DAQ' analyse 1 --version 2 --db '$PG_URL') && echo same \$('$DAQ' analyse $ALICE1 --db '$ALICE' | wc -l)"
check no_version4 2 "run 1 has no version 4 \(it has 1 to 3" -- "$DAQ" show 1 --version 4 --db "$PG_URL"
# Results tied to their version (central schema 11): a version's current results are those
# computed from its stops, never another version's beside them (before, version 1's stops were
# shown beside alice's and bob's results, both current). E and M (ISO 230-2) computed here from
# the stops of the store that sent each version, never from daq's output: the mean deviation per
# target and direction; E the range of those means, M the range of their bidirectional means
# (the mean of the two directions' at each target).
# The current results of daq show --json (stdin): "COUNT E M ..." of each.
cat >"$TMP/shown_em.py" <<'PY'
import json, sys
current = [r for r in json.load(sys.stdin)["results"] if r["current"]]
axis = lambda r: r["result"]["axis"]
print(len(current), *(f"{axis(r)[k]['value_um']:.6f}" for r in current for k in ("E_bi", "M")))
PY
BOB1=$(value "$BOB" "SELECT id FROM runs WHERE uuid = '$RUN1'")
EM1=$("$PY" "$(dirname "$0")/hand_em.py" "$DB" 1)
EM2=$("$PY" "$(dirname "$0")/hand_em.py" "$ALICE" "$ALICE1")
EM3=$("$PY" "$(dirname "$0")/hand_em.py" "$BOB" "$BOB1")
check em_differ 0 "^3$" -- bash -c "printf '%s\n' '$EM1' '$EM2' '$EM3' | sort -u | wc -l"
check results_version1 0 "^1 $EM1$" -- bash -c "'$DAQ' show 1 --version 1 --json --db '$PG_URL' | '$PY' '$TMP/shown_em.py'"
check results_version2 0 "^1 $EM2$" -- bash -c "'$DAQ' show 1 --version 2 --json --db '$PG_URL' | '$PY' '$TMP/shown_em.py'"
check results_current 0 "^1 $EM3$" -- bash -c "'$DAQ' show 1 --json --db '$PG_URL' | '$PY' '$TMP/shown_em.py'"
# The report of version 2: page one names it and gives its E (3 decimals, as printed).
E2=$(printf '%.3f' "${EM2% *}")
check report_version2 0 "written to" -- "$DAQ" report 1 --version 2 --db "$PG_URL" -f pdf -o "$TMP/v2.pdf"
check report_version2_page1 0 "^named $E2$" -- bash -c \
  "pdftotext -f 1 -l 1 '$TMP/v2.pdf' - | tr '\n' ' ' | grep -q \"Version 2 of 3 of the run's stops: sent by alice\" && pdftotext -f 1 -l 1 '$TMP/v2.pdf' - | grep -o -m1 '$E2' | sed 's/^/named /'"
check report_version_local 2 "run 1 has no version 2 here: a local store keeps one version" -- \
  "$DAQ" report 1 --version 2 --db "$DB"
check report_version_one_run 2 "--version N is for the report of one RUN" -- \
  "$DAQ" report 1 2 --version 2 --db "$PG_URL"
check local_one_version 2 "run $ALICE1 has no version 2 here: a local store keeps one version" -- \
  "$DAQ" export "$ALICE1" --version 2 --db "$ALICE"
VISIT2=$TMP/visit-v2.sqlite
check pull_version_bad 2 "--version '1': give RUN:N" -- \
  "$DAQ" sync --db "$VISIT2" --from "$PG_URL" --machine "$MACHINE" --version 1
check pull_version_none 2 "run 1 has no version 9" -- \
  "$DAQ" sync --db "$VISIT2" --from "$PG_URL" --machine "$MACHINE" --version 1:9
check pull_version_refused_nothing 0 "^none$" -- bash -c "ls '$VISIT2'* 2>/dev/null || echo none"
check pull_version 0 "runs of machine" -- \
  "$DAQ" sync --db "$VISIT2" --from "$PG_URL" --machine "$MACHINE" --version "$RUN1:2" --quiet
VISIT1=$(value "$VISIT2" "SELECT id FROM runs WHERE uuid = '$RUN1'")
same_targets pulled_is_alices "$ALICE" "$ALICE1" "$VISIT2" "$VISIT1"
# With version 2's results only: alice's, current; not bob's beside her stops.
check pulled_results_alices 0 "^1 $EM2$" -- bash -c "'$DAQ' show $VISIT1 --json --db '$VISIT2' | '$PY' '$TMP/shown_em.py'"
check pull_version_here 2 "run $VISIT1 \($RUN1\) is here already" -- \
  "$DAQ" sync --db "$VISIT2" --from "$PG_URL" --machine "$MACHINE" --version 1:1
# Sent back: its stops are version 2's, so nothing new (still three versions, bob's current).
check pulled_version_sent 0 "0 new; 0 chunks sent" -- "$DAQ" sync --db "$VISIT2" --to "$PG_URL" --run "$VISIT1" --quiet
check pulled_still_three 0 "^3 3$" -- psql_value "SELECT count(*) || ' ' || max(r.current_version) FROM caldaq.run_versions v JOIN caldaq.runs r ON r.uuid = v.run_uuid WHERE v.run_uuid = '$RUN1'"
check to_no_version 2 "--version is for --from" -- "$DAQ" sync --db "$VISIT2" --to "$PG_URL" --version 1:1

# Damage on the server is found, and nothing of it stored: a changed byte in a chunk to bring;
# a changed checksum of a chunk the laptop has.
psql_value "UPDATE caldaq.reading_chunks SET data = set_byte(data, 3, (get_byte(data, 3) + 1) % 256) WHERE seq = 2 AND run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 1)" >/dev/null
check damaged 2 "run 1 \(.*\): the server's reading chunk 2 does not match its checksum .*nothing of it was stored" -- \
  "$DAQ" sync --db "$TMP/fresh.sqlite" --from "$PG_URL" --machine "$MACHINE" --quiet
check damaged_not_stored 0 "^0$" -- value "$TMP/fresh.sqlite" "SELECT count(*) FROM reading_chunks"
psql_value "UPDATE caldaq.reading_chunks SET crc = crc # 1 WHERE seq = 0 AND run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 1)" >/dev/null
check damaged_here 2 "run 1 \(.*\): the local reading chunk 0 differs from the server's \(checksum .* there, .* here\); nothing of it was overwritten" -- \
  "$DAQ" sync --db "$LAPTOP" --from "$PG_URL" --machine "$MACHINE" --quiet

# Machines known by their UUID, not by name: another site's machine of the same name (a replay
# into a store of its own makes one) is another machine on the server, and a name two machines
# have is refused where it would pick one; the UUID picks it.
SITE2=$TMP/site2.sqlite
check site2_run 0 "" -- "$DAQ" replay "$DEMO_CDQ" --db "$SITE2"
check site2_send 0 "1 runs synced .*: 1 new" -- "$DAQ" sync --db "$SITE2" --to "$PG_URL" --site "Plant 2" --quiet
check two_machines 0 "^2 2$" -- psql_value "SELECT count(*) || ' ' || count(DISTINCT uuid) FROM caldaq.machines WHERE name = '$MACHINE'"
check site2_machine_own 0 "^1$" -- psql_value "SELECT count(*) FROM caldaq.runs r JOIN caldaq.machines m ON m.id = r.machine_id WHERE m.uuid = '$(value "$SITE2" "SELECT uuid FROM machines")'"
check name_ambiguous 2 "2 machines are named '$MACHINE' \(UUIDs .*\): name one by its UUID" -- \
  "$DAQ" sync --db "$TMP/visit.sqlite" --from "$PG_URL" --machine "$MACHINE"
check by_uuid 0 "1 runs of machine .* 1 new" -- \
  "$DAQ" sync --db "$TMP/visit.sqlite" --from "$PG_URL" --machine "$(value "$SITE2" "SELECT uuid FROM machines")" --quiet
check by_uuid_same 0 "^$(value "$SITE2" "SELECT uuid FROM machines")$" -- value "$TMP/visit.sqlite" "SELECT uuid FROM machines"
check other_site_here 2 "this store's machine '$MACHINE' is another one \(UUID .*\) than the server's" -- \
  "$DAQ" sync --db "$TMP/visit.sqlite" --from "$PG_URL" --machine "$(value "$DB" "SELECT uuid FROM machines")"

# A server of central schema 4 (machines by name, before their UUIDs) migrated by a sync: its
# machines are adopted by the first store that sends a machine of their name, not duplicated.
pg_undo_central_8
pg_undo_central_7
psql_value "DELETE FROM caldaq.runs WHERE machine_id = (SELECT id FROM caldaq.machines WHERE uuid = '$(value "$SITE2" "SELECT uuid FROM machines")'); DELETE FROM caldaq.machines WHERE uuid = '$(value "$SITE2" "SELECT uuid FROM machines")'; DROP INDEX caldaq.machines_by_name; ALTER TABLE caldaq.machines DROP COLUMN uuid; ALTER TABLE caldaq.machines ADD UNIQUE (name); DROP FUNCTION caldaq.approve(uuid, text); DROP TABLE caldaq.approvals; UPDATE caldaq.schema_version SET version = 4" >/dev/null
check old_server 0 "^4 1$" -- psql_value "SELECT version || ' ' || (SELECT count(*) FROM caldaq.machines) FROM caldaq.schema_version"
check migrate_5 0 "0 new" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --run 2 --quiet
check adopted 0 "^13 1 $(value "$DB" "SELECT uuid FROM machines")$" -- \
  psql_value "SELECT (SELECT version FROM caldaq.schema_version) || ' ' || count(*) || ' ' || max(uuid::text) FROM caldaq.machines"

finish
