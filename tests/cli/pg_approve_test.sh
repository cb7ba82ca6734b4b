#!/usr/bin/env bash
# Issue 35: users, roles and sign-off, against a real PostgreSQL server started here
# (tests/cli/pg_server.sh). The central schema's migration makes the roles caldaq_engineer (sends
# runs) and caldaq_reviewer (approves); a login of neither reads and writes nothing; an engineer
# cannot approve; a reviewer's approval names the exact result (its fingerprint, the run's version)
# and the reviewer's login, and a result superseded since is refused. A report is an issued
# certificate only for an approved result, a draft otherwise; the local store approves too
# (schema 9). Names from the store are escaped in the report.
# Usage: pg_approve_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_visit  # the demo's runs, run 1 re-compensated, sent by the server's owner (migrating it)

value() {
  "$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchone()[0])" "$1" "$2"
}
# as ROLE: the test's server for that login (trust authentication: the login is the role).
as() { echo "postgresql:///caldaq?host=$PGTMP&user=$1"; }
check schema 0 "^7 2$" -- psql_value \
  "SELECT version || ' ' || (SELECT count(*) FROM pg_roles WHERE rolname IN ('caldaq_engineer', 'caldaq_reviewer')) FROM caldaq.schema_version"
check local_schema 0 "^9$" -- value "$DB" "PRAGMA user_version"
psql_value "CREATE ROLE eng LOGIN IN ROLE caldaq_engineer; CREATE ROLE rev LOGIN IN ROLE caldaq_reviewer; CREATE ROLE visitor LOGIN; CREATE ROLE \"r<i>&\" LOGIN IN ROLE caldaq_reviewer" >/dev/null
ENG=$(as eng)
REV=$(as rev)
VISITOR=$(as visitor)
OLD=$(value "$DB" "SELECT min(id) FROM results WHERE run_id = 1 AND superseded_by IS NOT NULL")
CUR=$(value "$DB" "SELECT id FROM results WHERE run_id = 1 AND superseded_by IS NULL")

# An engineer sends (and reads); a login of neither role does neither.
check engineer_sends 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$ENG" --quiet
check engineer_reads 0 "linear" -- "$DAQ" runs --db "$ENG"
check visitor_cannot_send 2 "permission denied for schema caldaq" -- "$DAQ" sync --db "$DB" --to "$VISITOR" --quiet
check visitor_cannot_read 2 "permission denied for schema caldaq" -- "$DAQ" runs --db "$VISITOR"
check visitor_cannot_insert 1 "permission denied" -- \
  "$PG_BIN/psql" -X -At "$VISITOR" -c "INSERT INTO caldaq.machines(name) VALUES ('intruder')"
check visitor_cannot_approve 2 "permission denied" -- "$DAQ" approve 1 --db "$VISITOR"
# The engineer cannot approve, nor write an approval past the function.
check engineer_cannot_approve 2 "permission denied for function approve" -- "$DAQ" approve 1 --db "$ENG"
check engineer_cannot_insert 1 "permission denied for table approvals" -- \
  "$PG_BIN/psql" -X -At "$ENG" -c "INSERT INTO caldaq.approvals SELECT run_uuid, fingerprint, 1, 'eng', 0 FROM caldaq.results LIMIT 1"
check nothing_approved 0 "^0 0$" -- psql_value \
  "SELECT (SELECT count(*) FROM caldaq.approvals) || ' ' || (SELECT count(*) FROM caldaq.machines WHERE name = 'intruder')"

# Before approval the report is a draft.
check report_draft 0 "written to" -- "$DAQ" report 1 --db "$ENG" -o "$TMP/draft.html"
check_file "$TMP/draft.html" <<END
draft_marked DRAFT — NOT APPROVED</strong>: result $CUR has not been approved
END
check draft_not_issued 1 "" -- grep -c "ISSUED CERTIFICATE" "$TMP/draft.html"

# The reviewer: the superseded result refused, the current one approved (the server names the
# login), once.
check superseded_refused 2 "result $OLD is superseded by result $CUR \(re-analysed or re-compensated since\): it cannot be approved" -- \
  "$DAQ" approve 1 --result "$OLD" --db "$REV"
check no_such_result 2 "run 1 has no result 99" -- "$DAQ" approve 1 --result 99 --db "$REV"
check no_such_run 2 "no run 77" -- "$DAQ" approve 77 --db "$REV"
check approve 0 "run 1: result $CUR approved by rev at 20[0-9-]{8}T[0-9:]{8}Z \(fingerprint [0-9a-f]{32}, version 1 of its stops\)" -- \
  "$DAQ" approve 1 --db "$REV"
check approval_row 0 "^rev $CUR 1 true$" -- psql_value \
  "SELECT a.approved_by || ' ' || s.source_result_id || ' ' || a.run_version || ' ' || (s.fingerprint = a.result_fingerprint) FROM caldaq.approvals a JOIN caldaq.results s ON s.run_uuid = a.run_uuid AND s.fingerprint = a.result_fingerprint"
check approve_twice 2 "result $CUR is approved already \(by rev" -- "$DAQ" approve 1 --db "$REV"
check show_approval 0 "approved by rev at" -- "$DAQ" show 1 --db "$ENG"
check show_json_approval 0 "\"approved_by\": \"rev\"" -- "$DAQ" show 1 --db "$ENG" --json
check report_issued 0 "written to" -- "$DAQ" report 1 --db "$ENG" -o "$TMP/issued.html"
check_file "$TMP/issued.html" <<END
issued_marked ISSUED CERTIFICATE</strong>: result $CUR approved by <span class="approver">rev</span> on 20
issued_provenance <td>Approved</td><td>by rev on 20
END
check issued_not_draft 1 "" -- grep -c "NOT APPROVED" "$TMP/issued.html"

# Re-compensated again on the laptop and sent: the new result is current and not approved (the
# approval names the exact one), so the report is a draft again, and the old one is refused.
check recompensate_again 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 11.0 --db "$DB"
NEW=$(value "$DB" "SELECT id FROM results WHERE run_id = 1 AND superseded_by IS NULL")
check engineer_sends_new 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$ENG" --quiet
check approved_refused_now 2 "result $CUR is superseded by result $NEW" -- "$DAQ" approve 1 --result "$CUR" --db "$REV"
check report_draft_again 0 "written to" -- "$DAQ" report 1 --db "$ENG" -o "$TMP/again.html"
check_file "$TMP/again.html" <<END
draft_again DRAFT — NOT APPROVED</strong>: result $NEW has not been approved
END
check old_approval_in_show 0 "approved by rev" -- "$DAQ" show 1 --db "$ENG"
# A reviewer's login of awkward characters: escaped in the report's HTML.
check approve_escaped 0 "result $NEW approved by r<i>& at .*, version 2 of its stops" -- "$DAQ" approve 1 --db "$(as 'r%3Ci%3E%26')"
check report_escaped 0 "written to" -- "$DAQ" report 1 --db "$ENG" -o "$TMP/escaped.html"
check_file "$TMP/escaped.html" <<'END'
approver_escaped <span class="approver">r&lt;i&gt;&amp;</span>
END
check approver_not_raw 1 "" -- grep -c 'r<i>&' "$TMP/escaped.html"

# The local store (schema 9): the approver is the account (no accounts of its own).
RUN2=$(value "$DB" "SELECT id FROM results WHERE run_id = 2 AND superseded_by IS NULL")
check local_draft 0 "written to" -- "$DAQ" report 2 --db "$DB" -o "$TMP/local-draft.html"
check_file "$TMP/local-draft.html" <<END
local_draft_marked DRAFT — NOT APPROVED</strong>: result $RUN2 has not been approved
END
check local_superseded_refused 2 "result $CUR of run 1 is superseded by result $NEW" -- \
  "$DAQ" approve 1 --result "$CUR" --db "$DB"
check local_approve 0 "run 2: result $RUN2 approved by a<b>&c at 20" -- env USER='a<b>&c' "$DAQ" approve 2 --db "$DB"
check local_approve_twice 2 "approved already \(by a<b>&c" -- "$DAQ" approve 2 --db "$DB" --json
check local_report 0 "written to" -- "$DAQ" report 2 --db "$DB" -o "$TMP/local.html"
check_file "$TMP/local.html" <<END
local_issued ISSUED CERTIFICATE</strong>: result $RUN2 approved by <span class="approver">a&lt;b&gt;&amp;c</span> on 20
END
check local_show 0 "approved by a<b>&c at" -- "$DAQ" show 2 --db "$DB"
# Local approvals stay local: the server's are made there, by a reviewer's login.
check local_not_sent 0 "^2$" -- bash -c "'$DAQ' sync --db '$DB' --to '$ENG' --quiet >/dev/null && '$PG_BIN/psql' -X -At '$PG_URL' -c 'SELECT count(*) FROM caldaq.approvals'"

finish
