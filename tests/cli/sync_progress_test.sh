#!/usr/bin/env bash
# Issue 34: the progress of `daq sync` against a real PostgreSQL server started here
# (tests/cli/pg_server.sh): on a terminal (a pseudo-terminal by `script`) a line of chunks done
# of the total on stderr, cleared before each run's line and before the summary; nothing on
# stderr when piped; with --json a caldaq.sync-progress.v1 line per run on stderr and the
# caldaq.sync.v1 summary on stdout, counting the chunks a cut sync left on the server.
# Usage: sync_progress_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo
"$PG_BIN/psql" -q -X "postgresql:///postgres?host=$PGTMP&user=caldaq" -c "CREATE DATABASE second" ||
  { echo "FAIL: CREATE DATABASE second"; exit 1; }
SECOND="postgresql:///second?host=$PGTMP&user=caldaq"

local_value() {
  "$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchone()[0])" "$DB" "$1"
}
# The first writing open migrates the demo's store (each run its UUID): before counting.
"$DAQ" sync --db "$DB" --to "postgresql:///caldaq?host=$TMP/nowhere" >/dev/null 2>&1
RUNS=$(local_value "SELECT count(*) FROM runs")
CHUNKS=$(local_value "SELECT count(*) FROM reading_chunks")
check local_counts 0 "^[1-9][0-9]* [1-9][0-9]*$" -- echo "$RUNS $CHUNKS"

# On a terminal: the progress line from the start (0 of every chunk), each run's line and the
# summary written where the progress line was (erased first: ESC [K), never after its text.
script -qec "'$DAQ' sync --db '$DB' --to '$PG_URL'" /dev/null >"$TMP/tty.txt"
check tty_exit 0 "^0$" -- echo $?
check tty_progress 0 "sync to postgresql:///caldaq\?host=$PGTMP&user=caldaq: +0 % \(0 of $CHUNKS chunks\), 0:00 elapsed" -- cat "$TMP/tty.txt"
# The screen as a terminal leaves it (carriage return, erase to the end of the line, newline):
# the lines left are the runs' and the summary, whole, and the progress line is gone at the end.
check tty_lines_clean 0 "^clean $((RUNS + 1))$" -- "$PY" - "$TMP/tty.txt" <<'PY'
import re, sys
line, col, lines = [], 0, []
for t in re.findall(r"\x1b\[K|\r|\n|.", open(sys.argv[1], "rb").read().decode(), re.S):
    if t == "\r":
        col = 0
    elif t == "\x1b[K":
        del line[col:]
    elif t == "\n":
        lines.append("".join(line))
        line, col = [], 0
    else:
        line[col:col + 1] = [t]
        col += 1
ok = [l for l in lines if re.fullmatch(r"run +\d+  \S+ +\d+ chunks sent, +\d+ already there \(checked\)", l)
      or re.search(r": \d+ runs synced to .*already there$", l)]
print("clean", len(ok) if len(ok) == len(lines) and not line else (lines, "".join(line)))
PY
check tty_summary 0 "$RUNS runs synced to .*: $RUNS new; $CHUNKS chunks sent" -- cat "$TMP/tty.txt"

# Piped: nothing on stderr; the run lines and the summary on stdout.
"$DAQ" sync --db "$DB" --to "$PG_URL" >"$TMP/out.txt" 2>"$TMP/err.txt"
check piped_exit 0 "^0$" -- echo $?
check piped_stderr_empty 0 "^0$" -- stat -c %s "$TMP/err.txt"
check piped_runs 0 "^$RUNS$" -- grep -cE "^run +[0-9]+  " "$TMP/out.txt"
# --quiet on a terminal: the summary alone, no progress either.
check tty_quiet 0 "^quiet$" -- bash -c "script -qec \"'$DAQ' sync --quiet --db '$DB' --to '$PG_URL'\" /dev/null | grep -q 'sync to\|^run ' || echo quiet"

# --json, after a cut sync (10 chunks sent, pages of 4: 8 committed): a line per run on stderr
# whose counts add up to every chunk, sent now or already there; the summary on stdout.
env CALDAQ_SYNC_CUT_AFTER_CHUNKS=10 "$DAQ" sync --db "$DB" --to "$SECOND" --chunks-per-transaction 4 >/dev/null 2>&1
check cut 0 "^75$" -- echo $?
script -qec "'$DAQ' sync --json --db '$DB' --to '$SECOND' 2>'$TMP/json_err.txt' >'$TMP/json_out.txt'" /dev/null >/dev/null
check json_exit 0 "^0$" -- echo $?
check json_lines 0 "^ok$" -- "$PY" - "$TMP/json_err.txt" "$TMP/json_out.txt" "$RUNS" "$CHUNKS" <<'PY'
import json, sys
err, out, runs, chunks = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
lines = [json.loads(l) for l in open(err)]  # every stderr line is JSON: no terminal progress
assert len(lines) == runs, lines
assert all(l["schema"] == "caldaq.sync-progress.v1" and l["runs"] == runs and l["chunks"] == chunks
           for l in lines), lines
assert [l["runs_done"] for l in lines] == list(range(1, runs + 1)), lines
assert lines[-1]["chunks_done"] == chunks, lines
assert sum(l["chunks_already"] for l in lines) == 8, lines  # what the cut committed
summary = json.load(open(out))
assert summary["schema"] == "caldaq.sync.v1", summary
assert (summary["runs"], summary["chunks_sent"], summary["chunks_already"]) == (runs, chunks - 8, 8), summary
assert summary["chunks_sent"] == sum(l["chunks_sent"] for l in lines), summary
print("ok")
PY
check json_password_hidden 2 "postgresql://engineer:\*\*\*@127\.0\.0\.1:1/caldaq: connect" -- \
  "$DAQ" sync --json --db "$DB" --to "postgresql://engineer:s3cret@127.0.0.1:1/caldaq"
finish
