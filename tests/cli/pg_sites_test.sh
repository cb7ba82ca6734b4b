#!/usr/bin/env bash
# Issue 35: a site sees only its machines unless granted more (central schema 7), against a real
# PostgreSQL server started here (tests/cli/pg_server.sh). Two laptops of two sites send their
# machines' runs; an engineer of site A neither reads (runs, show, export, report, analyse, sync
# --from, or SQL on any table of a run) nor writes (SQL inserts, updates, deletes; a sync of a
# machine the server holds under B) site B's rows; a reviewer of A cannot approve B's run, not
# even through caldaq.approve itself; a login granted B through a group role can; a grant of all
# sites ('*') sees both; a login of no grant sees nothing. A machine moved by the administrator
# takes its runs along. A server of central schema 6, with its runs and approvals, migrated in
# place: the machines' sites taken from their runs' configuration ([customer] site), else
# 'unassigned', the approvals kept, the grants to be made.
# Usage: pg_sites_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo  # DB: the demo's runs (site A's laptop); the server, empty


# Site B's laptop: a machine of its own (a replay of the demo's capture, the machine renamed).
SITEB=$TMP/siteb.sqlite
check siteb_run 0 "" -- "$DAQ" replay "$DEMO_CDQ" --db "$SITEB"
"$PY" -c "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); c.execute(\"UPDATE machines SET name = 'Lathe 7'\"); c.commit()" "$SITEB"
RUNS_A=$(value "$DB" "SELECT count(*) FROM runs")

# The administrator (the server's owner) migrates the server by sending site A's runs, naming the
# site; then makes the logins and grants the sites (docs/storage.md, "Sites").
check owner_sends_a 0 "$RUNS_A runs synced .*central schema 13.*: $RUNS_A new" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --site "Plant A" --quiet
check site_a 0 "^Plant A Plant A $RUNS_A$" -- psql_value \
  "SELECT m.site || ' ' || max(r.site) || ' ' || count(*) FROM caldaq.machines m JOIN caldaq.runs r ON r.machine_id = m.id GROUP BY m.site"
psql_value "CREATE ROLE eng_a LOGIN IN ROLE caldaq_engineer; CREATE ROLE eng_b LOGIN IN ROLE caldaq_engineer;
  CREATE ROLE rev_a LOGIN IN ROLE caldaq_reviewer; CREATE ROLE plant_b_reviewers NOLOGIN;
  CREATE ROLE rev_b LOGIN IN ROLE caldaq_reviewer, plant_b_reviewers;
  CREATE ROLE auditor LOGIN IN ROLE caldaq_reviewer; CREATE ROLE newcomer LOGIN IN ROLE caldaq_engineer;
  INSERT INTO caldaq.site_grants VALUES ('eng_a', 'Plant A'), ('rev_a', 'Plant A'),
    ('eng_b', 'Plant B'), ('plant_b_reviewers', 'Plant B'), ('auditor', '*')" >/dev/null
check grant_unknown_role 1 "role \"nobody_here\" does not exist" -- \
  psql_value "INSERT INTO caldaq.site_grants VALUES ('nobody_here', 'Plant A')"
check engineer_cannot_grant 1 "permission denied for table site_grants" -- \
  sql eng_b "INSERT INTO caldaq.site_grants VALUES ('eng_b', 'Plant A')"
# The sites each login's session has: its own grant, its group role's, every site.
SESSION_SITES="$(sql eng_b 'SELECT caldaq.session_sites()') $(sql rev_b 'SELECT caldaq.session_sites()') $(sql auditor 'SELECT caldaq.session_sites()')"
check session_sites 0 "^\{\"Plant B\"\} \{\"Plant B\"\} \{\*\}$" -- echo "$SESSION_SITES"

# Engineer B sends B's laptop: a site it may not write is refused, nothing stored; without --site
# its one site is taken.
check b_refused_site 2 "machine 'Lathe 7' \(.*\) would be of site 'Plant A', which this login may not write \(it may write 'Plant B'\): give --site, or ask the administrator" -- \
  "$DAQ" sync --db "$SITEB" --to "$(as eng_b)" --site "Plant A" --quiet
check b_nothing_stored 0 "^1 $RUNS_A$" -- psql_value "SELECT (SELECT count(*) FROM caldaq.machines) || ' ' || (SELECT count(*) FROM caldaq.runs)"
check b_sends 0 "1 runs synced .*: 1 new" -- "$DAQ" sync --db "$SITEB" --to "$(as eng_b)" --quiet
check b_site 0 "^Lathe 7 Plant B Plant B$" -- psql_value \
  "SELECT m.name || ' ' || m.site || ' ' || r.site FROM caldaq.machines m JOIN caldaq.runs r ON r.machine_id = m.id WHERE m.site <> 'Plant A'"
RUNB=$(psql_value "SELECT id FROM caldaq.runs WHERE site = 'Plant B'")
UUIDB=$(psql_value "SELECT uuid FROM caldaq.runs WHERE site = 'Plant B'")
RUNS_ALL=$((RUNS_A + 1))

# What engineer A reads: its site's runs only, on every read command.
ENGA=$(as eng_a)
check a_runs 0 "\($RUNS_A runs\)" -- "$DAQ" runs --db "$ENGA"
check a_runs_json 0 "^$RUNS_A False$" -- bash -c \
  "'$DAQ' runs --json --db '$ENGA' | '$PY' -c 'import json, sys; r = json.load(sys.stdin)[\"runs\"]; print(len(r), any(x[\"id\"] == $RUNB for x in r))'"
check a_show_b 2 "no run $RUNB \(see daq runs\)" -- "$DAQ" show "$RUNB" --db "$ENGA"
check a_export_b 2 "no run $RUNB" -- "$DAQ" export "$RUNB" --db "$ENGA"
check a_report_b 2 "no run $RUNB" -- "$DAQ" report "$RUNB" --db "$ENGA" -o "$TMP/b.html"
check a_analyse_b 2 "no run $RUNB" -- "$DAQ" analyse "$RUNB" --db "$ENGA"
check a_pull_b 2 "no machine 'Lathe 7' in the central store" -- \
  "$DAQ" sync --db "$TMP/a-visit.sqlite" --from "$ENGA" --machine "Lathe 7"
check a_show_own 0 "run 1: linear" -- "$DAQ" show 1 --db "$ENGA"
# ... and in SQL, on every table of a run (the owner sees B's rows there).
ROWS_B="(SELECT count(*) FROM caldaq.machines WHERE site = 'Plant B') + (SELECT count(*) FROM caldaq.runs WHERE uuid = '$UUIDB')"
for t in instruments reading_chunks captured_targets missed_stops results operator_actions suspect_stops run_versions approvals; do
  ROWS_B="$ROWS_B + (SELECT count(*) FROM caldaq.$t WHERE run_uuid = '$UUIDB')"
done
OWNER_B=$(psql_value "SELECT $ROWS_B")
check owner_sees_b 0 "^[1-9][0-9]+$" -- echo "$OWNER_B"
check a_sql_sees_nothing_of_b 0 "^0$" -- sql eng_a "SELECT $ROWS_B"
check a_compensations 0 "^0$" -- sql eng_a "SELECT count(*) FROM caldaq.compensations WHERE site = 'Plant B'"
# Writes for B refused, or touching nothing.
check a_insert_machine_b 1 "new row violates row-level security policy for table \"machines\"" -- \
  sql eng_a "INSERT INTO caldaq.machines(name, uuid, site) VALUES ('intruder', gen_random_uuid(), 'Plant B')"
check a_insert_result_b 1 "new row violates row-level security policy for table \"results\"" -- \
  sql eng_a "INSERT INTO caldaq.results(run_uuid, source_result_id, standard, json, created_unix_ms, provenance_json, fingerprint) VALUES ('$UUIDB', 99, 'x', '{}', 0, '{}', 'x')"
check a_insert_chunk_b 1 "new row violates row-level security policy for table \"reading_chunks\"" -- \
  sql eng_a "INSERT INTO caldaq.reading_chunks VALUES ('$UUIDB', 999, 0, 0, 0, 0, 0, 0, 2, 0, true, '')"
check a_move_own_run_to_b 1 "new row violates row-level security policy for table \"runs\"" -- \
  sql eng_a "UPDATE caldaq.runs SET site = 'Plant B' WHERE id = 1"
check a_update_b 0 "^UPDATE 0$" -- sql eng_a "UPDATE caldaq.runs SET note = 'x' WHERE uuid = '$UUIDB'"
check a_delete_b 0 "^DELETE 0$" -- sql eng_a "DELETE FROM caldaq.reading_chunks WHERE run_uuid = '$UUIDB'"
check a_cannot_move_machines 1 "permission denied for table machines" -- \
  sql eng_a "UPDATE caldaq.machines SET site = 'Plant A'"
check b_untouched 0 "^$OWNER_B 0$" -- psql_value "SELECT ($ROWS_B) || ' ' || ((SELECT count(*) FROM caldaq.machines WHERE name = 'intruder') + (SELECT count(*) FROM caldaq.runs WHERE note = 'x'))"
# A copy of B's laptop sent by A: the server holds that machine under B.
cp "$SITEB" "$TMP/copy.sqlite"
check a_sends_b_copy 2 "the server holds machine 'Lathe 7' \(.*\) under a site this login may not read or write \(it may write 'Plant A'\); nothing of it was sent" -- \
  "$DAQ" sync --db "$TMP/copy.sqlite" --to "$ENGA" --quiet
check a_sends_own 0 "$RUNS_A runs synced .*: 0 new" -- "$DAQ" sync --db "$DB" --to "$ENGA" --quiet

# Reviewers approve their sites' runs only; the server's own check, not only what a login sees.
RESULTB=$(psql_value "SELECT fingerprint FROM caldaq.results WHERE run_uuid = '$UUIDB' AND superseded_by IS NULL")
check rev_a_approves_a 0 "run 1: result [0-9]+ approved by rev_a" -- "$DAQ" approve 1 --db "$(as rev_a)"
check rev_a_not_b 2 "no run $RUNB" -- "$DAQ" approve "$RUNB" --db "$(as rev_a)"
check rev_a_not_b_sql 1 "run $UUIDB is not of a site login rev_a may approve" -- \
  sql rev_a "SELECT * FROM caldaq.approve('$UUIDB', '$RESULTB')"
check rev_b_approves_b 0 "run $RUNB: result [0-9]+ approved by rev_b" -- "$DAQ" approve "$RUNB" --db "$(as rev_b)"
check approvals_two 0 "^rev_a Plant A\|rev_b Plant B$" -- psql_value \
  "SELECT string_agg(a.approved_by || ' ' || r.site, '|' ORDER BY a.approved_by) FROM caldaq.approvals a JOIN caldaq.runs r ON r.uuid = a.run_uuid"

# All sites ('*'): both machines, both sites' runs; no grant: nothing.
check auditor_runs 0 "\($RUNS_ALL runs\)" -- "$DAQ" runs --db "$(as auditor)"
check auditor_show_b 0 "approved by rev_b at .* on the central server" -- "$DAQ" show "$RUNB" --db "$(as auditor)"
check auditor_pull_b 0 "1 runs of machine 'Lathe 7' brought .*: 1 new, .*1 approvals new" -- \
  "$DAQ" sync --db "$TMP/audit.sqlite" --from "$(as auditor)" --machine "Lathe 7"
check newcomer_nothing 0 "\(0 runs\)" -- "$DAQ" runs --db "$(as newcomer)"
# A store of a machine new to the server whose runs name no site (new UUIDs, settings without a
# context): the newcomer's login may write none, the owner's every site; neither knows which.
cp "$SITEB" "$TMP/nosite.sqlite"
"$PY" - "$TMP/nosite.sqlite" <<'PY'
import sqlite3, sys, uuid
c = sqlite3.connect(sys.argv[1])
c.execute("UPDATE machines SET uuid = ?", (str(uuid.uuid4()),))
c.execute("UPDATE runs SET uuid = ?, settings_json = '{}'", (str(uuid.uuid4()),))
c.commit()
PY
check newcomer_no_site 2 "machine 'Lathe 7' \(.*\) is new to the server and no site is known for it \(no --site, no \[customer\] site in its configuration; this login may write none: the administrator grants sites in caldaq.site_grants" -- \
  "$DAQ" sync --db "$TMP/nosite.sqlite" --to "$(as newcomer)" --quiet
check owner_no_site 2 "is new to the server and no site is known for it .*this login may write every site\): give --site SITE" -- \
  "$DAQ" sync --db "$TMP/nosite.sqlite" --to "$PG_URL" --quiet
check nosite_nothing 0 "^2$" -- psql_value "SELECT count(*) FROM caldaq.machines"

# The administrator moves B's machine to site A: its runs go along; engineer A sees them now.
psql_value "UPDATE caldaq.machines SET site = 'Plant A' WHERE name = 'Lathe 7'" >/dev/null
check moved 0 "^Plant A$" -- psql_value "SELECT site FROM caldaq.runs WHERE uuid = '$UUIDB'"
check a_sees_moved 0 "\($RUNS_ALL runs\)" -- "$DAQ" runs --db "$ENGA"
check b_sees_none 0 "\(0 runs\)" -- "$DAQ" runs --db "$(as eng_b)"

# A server of central schema 6 (before sites), with its runs and approvals, migrated in place by
# the administrator's next sync; an engineer's login cannot migrate it. B's run named no site in
# its configuration (here: settings that are not even JSON) and so its machine is 'unassigned'.
pg_undo_central_8
pg_undo_central_7
psql_value "UPDATE caldaq.runs SET settings_json = 'not json' WHERE uuid = '$UUIDB'" >/dev/null
check v6 0 "^6 2 $RUNS_ALL$" -- psql_value \
  "SELECT version || ' ' || (SELECT count(*) FROM caldaq.approvals) || ' ' || (SELECT count(*) FROM caldaq.runs) FROM caldaq.schema_version"
check v6_refused_by_readers 2 "central schema version 6 is older than this daq reads \(13\)" -- "$DAQ" runs --db "$ENGA"
check engineer_cannot_migrate 2 "create or migrate the central schema: .*(must be owner|permission denied)" -- \
  "$DAQ" sync --db "$DB" --to "$ENGA" --quiet
check migrate 0 "$RUNS_A runs synced .*central schema 13.*: 0 new; 0 chunks sent" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check migrated_sites 0 "^Lathe 7 unassigned unassigned\|SIMULATED VMC caldaq built-in simulated shop caldaq built-in simulated shop$" -- psql_value \
  "SELECT string_agg(x, '|' ORDER BY x) FROM (SELECT DISTINCT m.name || ' ' || m.site || ' ' || r.site AS x FROM caldaq.machines m JOIN caldaq.runs r ON r.machine_id = m.id) AS d"
check migrated_kept 0 "^13 2 $RUNS_ALL 0$" -- psql_value \
  "SELECT version || ' ' || (SELECT count(*) FROM caldaq.approvals) || ' ' || (SELECT count(*) FROM caldaq.runs) || ' ' || (SELECT count(*) FROM caldaq.site_grants) FROM caldaq.schema_version"
check migrated_engineer_nothing 0 "\(0 runs\)" -- "$DAQ" runs --db "$ENGA"
psql_value "INSERT INTO caldaq.site_grants VALUES ('eng_a', 'caldaq built-in simulated shop')" >/dev/null
check migrated_granted 0 "\($RUNS_A runs\)" -- "$DAQ" runs --db "$ENGA"
check migrated_rev_b_not 1 "is not of a site login rev_b may approve" -- \
  sql rev_b "SELECT * FROM caldaq.approve('$(psql_value "SELECT uuid FROM caldaq.runs WHERE id = 2")', '$(psql_value "SELECT fingerprint FROM caldaq.results WHERE run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 2) AND superseded_by IS NULL")')"

finish
