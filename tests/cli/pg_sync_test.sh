#!/usr/bin/env bash
# Issue 35: daq sync --to postgresql://... against a real PostgreSQL server started here
# (tests/cli/pg_server.sh): the demo's runs synced, synced again (nothing twice), a sync cut
# mid-transaction and resumed (nothing lost, nothing twice), every chunk's checksum and bytes
# compared on both sides, a damaged chunk on the server found, bad URIs and unreachable servers
# refused with the password never printed.
# Usage: pg_sync_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo

# local_value SQL: one value from the local SQLite store.
local_value() {
  "$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchone()[0])" "$DB" "$1"
}
# Every chunk as (run UUID, seq, crc, md5 of its bytes), sorted: the same text on both sides.
local_chunks() {
  "$PY" - "$DB" <<'PY'
import hashlib, sqlite3, sys
c = sqlite3.connect(sys.argv[1])
for u, seq, crc, data in c.execute(
        "SELECT r.uuid, k.seq, k.crc, k.data FROM reading_chunks k JOIN runs r ON r.id = k.run_id"):
    print(f"{u}|{seq}|{crc}|{hashlib.md5(data).hexdigest()}")
PY
}
server_chunks() {
  psql_value "SELECT run_uuid || '|' || seq || '|' || crc || '|' || md5(data) FROM caldaq.reading_chunks"
}
same_chunks() {
  local_chunks | sort >"$TMP/local.txt"
  server_chunks | sort >"$TMP/server.txt"
  if cmp -s "$TMP/local.txt" "$TMP/server.txt"; then echo "same $(wc -l <"$TMP/local.txt")"; else
    diff "$TMP/local.txt" "$TMP/server.txt" | head -5; fi
}

# Refused before anything is sent: not a PostgreSQL URI; a server not there (its password never
# printed).
check no_local_db 2 "$TMP/none.sqlite: no such database: nothing to sync" -- "$DAQ" sync --db "$TMP/none.sqlite" --to "$PG_URL"
check no_local_db_not_created 0 "^absent$" -- bash -c "[ -e '$TMP/none.sqlite' ] && echo present || echo absent"
check not_a_uri 2 "--to: '/tmp/x.sqlite' is not a PostgreSQL URI" -- "$DAQ" sync --db "$DB" --to /tmp/x.sqlite
check no_server 2 "postgresql:///caldaq\?host=$TMP/nowhere: connect: .*(No such file|could not connect)" -- \
  "$DAQ" sync --db "$DB" --to "postgresql:///caldaq?host=$TMP/nowhere"
check password_hidden 2 "postgresql://engineer:\*\*\*@127\.0\.0\.1:1/caldaq: connect" -- \
  "$DAQ" sync --db "$DB" --to "postgresql://engineer:s3cret@127.0.0.1:1/caldaq"
check password_not_printed 0 "^hidden$" -- bash -c \
  "'$DAQ' sync --db '$DB' --to 'postgresql://engineer:s3cret@127.0.0.1:1/caldaq' 2>&1 | grep -q s3cret || echo hidden"

# The demo's store migrated to schema 11 by the first writing open: every run and machine has its own UUID.
RUNS=$(local_value "SELECT count(*) FROM runs")
CHUNKS=$(local_value "SELECT count(*) FROM reading_chunks")
check local_runs 0 "^[1-9][0-9]*$" -- echo "$RUNS"

# A sync cut mid-transaction: after its 10th chunk (pages of 4: two committed, the third lost).
check cut 75 "" -- env CALDAQ_SYNC_CUT_AFTER_CHUNKS=10 "$DAQ" sync --db "$DB" --to "$PG_URL" --chunks-per-transaction 4
check local_schema 0 "^11$" -- local_value "PRAGMA user_version"
check local_uuids 0 "^$RUNS$" -- local_value "SELECT count(DISTINCT uuid) FROM runs WHERE uuid LIKE '________-____-4___-____-____________'"
CUT=$(psql_value "SELECT count(*) FROM caldaq.reading_chunks")
check cut_left_committed_pages 0 "^8$" -- echo "$CUT"
check cut_schema 0 "^13$" -- psql_value "SELECT version FROM caldaq.schema_version"

# Resumed: the chunks there are checked, the rest sent; every chunk once, the same bytes.
check resume 0 "$RUNS runs synced .* $((CHUNKS - CUT)) chunks sent .*, $CUT already there" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --chunks-per-transaction 4
check resume_runs 0 "^$RUNS$" -- psql_value "SELECT count(*) FROM caldaq.runs"
check resume_chunks 0 "^same $CHUNKS$" -- same_chunks
check resume_results 0 "^$(local_value "SELECT count(*) FROM results")$" -- psql_value "SELECT count(*) FROM caldaq.results"
check resume_stops 0 "^$(local_value "SELECT count(*) FROM captured_targets")$" -- psql_value "SELECT count(*) FROM caldaq.captured_targets"
check resume_origins 0 "^$(local_value "SELECT count(*) FROM instruments WHERE origin = 'simulated'")$" -- \
  psql_value "SELECT count(*) FROM caldaq.instruments WHERE origin = 'simulated'"
check resume_provenance 0 "^0$" -- psql_value "SELECT count(*) FROM caldaq.results WHERE provenance_json NOT LIKE '%\"how\"%'"

# Sent again: nothing twice.
check again 0 "$RUNS runs synced .*: 0 new; 0 chunks sent \(0 bytes\), $CHUNKS already there" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL"
check again_runs 0 "^$RUNS$" -- psql_value "SELECT count(*) FROM caldaq.runs"
check again_chunks 0 "^same $CHUNKS$" -- same_chunks

# daq runs reads the central store through the same interface: the same listing (the server
# numbers the runs in the order it first saw them: here the local order) but for its first line.
check runs_central 0 "^postgresql:///caldaq\?host=.* \($RUNS runs\)$" -- bash -c "'$DAQ' runs --db '$PG_URL' | head -1"
check runs_same 0 "^same$" -- bash -c "diff <('$DAQ' runs --db '$PG_URL' | tail -n +2) <('$DAQ' runs --db '$DB' | tail -n +2) && echo same"
check runs_json_uuids 0 "^same$" -- bash -c "diff <('$DAQ' runs --json --db '$PG_URL' | grep '\"uuid\"') <('$DAQ' runs --json --db '$DB' | grep '\"uuid\"') && echo same"
check runs_json_has_uuids 0 "^$RUNS$" -- bash -c "'$DAQ' runs --json --db '$PG_URL' | grep -cE '\"uuid\": \"[0-9a-f-]{36}\"'"
check write_central_refused 2 "--db postgresql:///caldaq\?host=.*: this command writes the local store" -- \
  "$DAQ" recompensate 1 --alpha-ppm 12 --db "$PG_URL"
check runs_no_central 2 "no caldaq central store in this database \(daq sync --to creates it\)" -- \
  "$DAQ" runs --db "postgresql:///postgres?host=$PG_DIR&user=caldaq"

# A new result of a run (re-analysis) is added once; its run is not duplicated.
check reanalyse 0 "" -- "$DAQ" analyse 1 --store --db "$DB"
check new_result 0 "1 runs synced .*: 0 new" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --run 1 --quiet
check new_result_count 0 "^$(local_value "SELECT count(*) FROM results")$" -- psql_value "SELECT count(*) FROM caldaq.results"
check new_result_superseded 0 "^$(local_value "SELECT count(*) FROM results WHERE superseded_by IS NOT NULL")$" -- \
  psql_value "SELECT count(*) FROM caldaq.results WHERE superseded_by IS NOT NULL"

# daq bench sync: a generated run sent and measured beside the server's own binary COPY of the
# same chunk rows; its run and its scratch table deleted again (the server's runs as before).
SERVER_RUNS=$(psql_value "SELECT count(*) FROM caldaq.runs")
check bench_sync 0 "median: daq sync [0-9]+ readings/s, COPY ceiling [0-9]+ readings/s: sync at [0-9]+ % of the ceiling" -- \
  "$DAQ" bench sync --to "$PG_URL" --minutes 1 --rounds 1 --dir "$TMP"
# 60 s of 10 kHz readings and 60 air samples of three quantities each: 600,000 + 180.
check bench_sync_readings 0 "^ +1 +600180 " -- bash -c "'$DAQ' bench sync --to '$PG_URL' --minutes 1 --rounds 1 --dir '$TMP' | sed -n 3p"
# A store of several runs (--runs), all sent by one sync and all deleted again: 3 x 600,180.
check bench_sync_runs 0 "^3 runs of 1 min .*: 1800540 readings.* +1 +1800540 " -- bash -c \
  "'$DAQ' bench sync --to '$PG_URL' --minutes 1 --runs 3 --rounds 1 --dir '$TMP' | sed -n '1p;3p' | tr '\n' ' '"
check bench_sync_runs_gone 0 "^$SERVER_RUNS$" -- psql_value "SELECT count(*) FROM caldaq.runs"
check bench_sync_table_gone 0 "^t$" -- psql_value "SELECT to_regclass('public.caldaq_bench_reading_chunks') IS NULL"
check bench_sync_not_a_uri 2 "bench sync: --to: '/tmp/x.sqlite' is not a PostgreSQL URI" -- "$DAQ" bench sync --to /tmp/x.sqlite

# Every chunk read back and its checksum recomputed over the server's bytes.
check verify 0 "$CHUNKS chunks read back and their checksums verified" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --verify --quiet

# Damage on the server is found, not overwritten: a changed byte (by --verify), a changed checksum.
psql_value "UPDATE caldaq.reading_chunks SET data = set_byte(data, 3, (get_byte(data, 3) + 1) % 256) WHERE seq = 2 AND run_uuid = (SELECT uuid FROM caldaq.runs WHERE source_run_id = 1)" >/dev/null
check damaged_bytes 2 "run 1 \(.*\): the server's reading chunk 2 differs from the local one \(its bytes on the server do not match its checksum\)" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --verify --run 1
psql_value "UPDATE caldaq.reading_chunks SET crc = crc # 1 WHERE seq = 0 AND run_uuid = (SELECT uuid FROM caldaq.runs WHERE source_run_id = 1)" >/dev/null
check damaged_crc 2 "the server's reading chunk 0 differs from the local one \(checksum .* there, .* here\); nothing of it was overwritten" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --run 1

# A server of a newer central schema is refused.
psql_value "UPDATE caldaq.schema_version SET version = 99" >/dev/null
check newer_schema 2 "central schema version 99 is newer than this daq understands \(13\)" -- "$DAQ" sync --db "$DB" --to "$PG_URL"

finish
