#!/usr/bin/env bash
# Issue 35: users, roles and sign-off, against a real PostgreSQL server started here
# (tests/cli/pg_server.sh). The central schema's migration makes the roles caldaq_engineer (sends
# runs) and caldaq_reviewer (approves); a login of neither reads and writes nothing; an engineer
# cannot approve; a reviewer's approval names the exact result (its fingerprint, the run's version)
# and the reviewer's login, and a result superseded since is refused. A report is an issued
# certificate only for an approved result, a draft otherwise; the local store approves too
# (schema 9). Names from the store are escaped in the report. A laptop that brings the machine's
# history (daq sync --from) brings the server's approvals, read-only (local schema 10): its report
# is issued as the server's, naming the reviewer "on the central server".
# Usage: pg_approve_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_visit  # the demo's runs, run 1 re-compensated, sent by the server's owner (migrating it)

check schema 0 "^13 2$" -- psql_value \
  "SELECT version || ' ' || (SELECT count(*) FROM pg_roles WHERE rolname IN ('caldaq_engineer', 'caldaq_reviewer')) FROM caldaq.schema_version"
check local_schema 0 "^11$" -- value "$DB" "PRAGMA user_version"
psql_value "CREATE ROLE eng LOGIN IN ROLE caldaq_engineer; CREATE ROLE rev LOGIN IN ROLE caldaq_reviewer; CREATE ROLE visitor LOGIN; CREATE ROLE \"r<i>&\" LOGIN IN ROLE caldaq_reviewer" >/dev/null
# Each login granted the demo's site (central schema 7: the [customer] site of the configuration
# its runs were measured with, docs/storage.md "Sites"); the visitor none.
SITE=$(psql_value "SELECT site FROM caldaq.machines")
check demo_site 0 "^caldaq built-in simulated shop$" -- echo "$SITE"
psql_value "INSERT INTO caldaq.site_grants VALUES ('eng', '$SITE'), ('rev', '$SITE'), ('\"r<i>&\"', '$SITE')" >/dev/null
ENG=$(as eng)
REV=$(as rev)
VISITOR=$(as visitor)
OLD=$(value "$DB" "SELECT min(id) FROM results WHERE run_id = 1 AND superseded_by IS NOT NULL")
CUR=$(value "$DB" "SELECT id FROM results WHERE run_id = 1 AND superseded_by IS NULL")

# An engineer sends (and reads); a login of neither role does neither.
check engineer_sends 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$ENG" --quiet
check engineer_reads 0 "linear" -- "$DAQ" runs --db "$ENG"
check visitor_cannot_send 2 "permission denied for schema caldaq" -- "$DAQ" sync --db "$DB" --to "$VISITOR" --quiet
# The server's SQLSTATE in the message: libpqxx 6.4 gives none with its insufficient_privilege
# exception (central_schema.hpp, sqlstate()): 42501 is PostgreSQL's insufficient_privilege.
check visitor_cannot_read 2 "permission denied for schema caldaq \(SQLSTATE 42501\)" -- "$DAQ" runs --db "$VISITOR"
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

# A laptop brings the machine's history before a visit (as the engineer): the server's approvals
# come with it, read-only. Run 1's current result ($NEW, approved on the server by r<i>&) is
# issued on the laptop, naming the reviewer on the central server; run 2's, not approved there,
# is a draft (its local approval stays in the store that made it).
MACHINE=$(value "$DB" "SELECT name FROM machines")
LAPTOP=$TMP/laptop.sqlite
check pull_approvals 0 ", 2 approvals new; 0 runs' operator actions refreshed" -- \
  "$DAQ" sync --db "$LAPTOP" --from "$ENG" --machine "$MACHINE"
UUID1=$(value "$DB" "SELECT uuid FROM runs WHERE id = 1")
L1=$(value "$LAPTOP" "SELECT id FROM runs WHERE uuid = '$UUID1'")
LNEW=$(value "$LAPTOP" "SELECT id FROM results WHERE run_id = $L1 AND superseded_by IS NULL")
check laptop_approval_row 0 "^r<i>& 2 [0-9a-f]{32}$" -- value "$LAPTOP" \
  "SELECT approved_by || ' ' || run_version || ' ' || result_fingerprint FROM central_approvals WHERE result_id = $LNEW"
check laptop_show 0 "approved by r<i>& at 20[0-9-]{8}T[0-9:]{8}Z on the central server" -- "$DAQ" show "$L1" --db "$LAPTOP"
check laptop_show_json 0 "^r<i>& True 2$" -- bash -c \
  "'$DAQ' show $L1 --json --db '$LAPTOP' | '$PY' -c 'import json, sys; a = [r[\"approval\"] for r in json.load(sys.stdin)[\"results\"] if r[\"current\"]][0]; print(a[\"approved_by\"], a[\"central_server\"].startswith(\"postgresql://\"), a[\"run_version\"])'"
check laptop_report 0 "written to" -- "$DAQ" report "$L1" --db "$LAPTOP" -o "$TMP/laptop.html"
check_file "$TMP/laptop.html" <<END
laptop_issued ISSUED CERTIFICATE</strong>: result $LNEW approved by <span class="approver">r&lt;i&gt;&amp;</span> on 20[0-9: -]+ UTC, on the central server \(result fingerprint [0-9a-f]{32}, version 2 of the run's stops\)
laptop_provenance <td>Approved</td><td>by r&lt;i&gt;&amp; on 20[0-9: -]+ UTC, on the central server</td>
END
check laptop_not_draft 1 "" -- grep -c "NOT APPROVED" "$TMP/laptop.html"
# Read-only here: the laptop's account cannot approve what the server approved.
check laptop_approved_already 2 "result $LNEW of run $L1 is approved already \(by r<i>&, unix ms [0-9]+, on the central server\)" -- \
  "$DAQ" approve "$L1" --db "$LAPTOP"
UUID2=$(value "$DB" "SELECT uuid FROM runs WHERE id = 2")
L2=$(value "$LAPTOP" "SELECT id FROM runs WHERE uuid = '$UUID2'")
check laptop_report_draft 0 "written to" -- "$DAQ" report "$L2" --db "$LAPTOP" -o "$TMP/laptop-draft.html"
check laptop_draft 0 "DRAFT — NOT APPROVED" -- cat "$TMP/laptop-draft.html"
# Brought again: nothing twice. Approved on the server since (run 2, by rev): the next pull
# brings it, and the laptop's report of run 2 is issued.
check pull_again 0 ", 0 approvals new" -- "$DAQ" sync --db "$LAPTOP" --from "$ENG" --machine "$MACHINE"
check approve_run2 0 "approved by rev" -- "$DAQ" approve 2 --db "$REV"
check pull_new_approval 0 ", 1 approvals new" -- "$DAQ" sync --db "$LAPTOP" --from "$ENG" --machine "$MACHINE"
check laptop_report_now 0 "written to" -- "$DAQ" report "$L2" --db "$LAPTOP" -o "$TMP/laptop-now.html"
check laptop_now_issued 0 "approved by <span class=\"approver\">rev</span> on 20[0-9: -]+ UTC, on the central server" -- cat "$TMP/laptop-now.html"
check laptop_central_count 0 "^3$" -- value "$LAPTOP" "SELECT count(*) FROM central_approvals"

finish
