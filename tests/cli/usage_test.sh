#!/usr/bin/env bash
# A command that helps (issue 34): a mistyped command or option gets "did you mean"; every
# usage error is status 2 with one "daq: error:" line (a busy port too); nothing is printed
# after an error as if the command had started; `daq export -o` says what it wrote and shows
# its progress on a terminal only; `daq run`'s progress shows no number before the device gave
# one, the stop k of N, the time so far and left, and JSON lines with --json.
# Usage: usage_test.sh DAQ_BINARY
set -u
DAQ=$(realpath "$1")
source "$(dirname "$0")/check.sh"
scratch_dir HOLD_PID

# "Did you mean": commands, nested commands, aliases, long and short options.
check mistyped_command 2 "^daq: error: unknown command 'analys' of daq; did you mean 'analyse'\?$" -- "$DAQ" analys 1
check mistyped_subcommand 2 "^daq: error: unknown command 'mapp' of daq model; did you mean 'map'\?$" -- "$DAQ" model mapp x.json
check mistyped_option 2 "^daq: error: unknown option '--fromat' of daq report; did you mean '--format'\?$" -- "$DAQ" report 1 --fromat pdf
check mistyped_option_short_word 2 "^daq: error: unknown option '--wht' of daq export; did you mean '--what'\?$" -- "$DAQ" export --wht targets
check mistyped_option_with_value 2 "did you mean '--db'\?$" -- "$DAQ" runs --dbb=x.sqlite
check unknown_command_no_guess 2 "^daq: error: unknown command 'frobnicate' of daq \(see daq --help\)$" -- "$DAQ" frobnicate
check unknown_option_no_guess 2 "^daq: error: unknown option '--zzzzzz' of daq runs \(see daq runs --help\)$" -- "$DAQ" runs --zzzzzz
# Right words are left alone: values of options (negative numbers, several values), aliases,
# "--" and an option's value that looks like a command.
check alias_is_known 0 "Usage: .*analyze|Usage: .*analyse" -- "$DAQ" analyze --help
check negative_values 0 "^3 targets \(mm\): -100.000 -50.000 0.000$" -- "$DAQ" targets --first -100 --last 0 --interval 50
check several_values 0 "." -- "$DAQ" analyse squareness --method diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8
check value_like_a_command 2 "no such database" -- "$DAQ" runs --db report
# CLI11's own errors: one prefix, where to look, status 2 (they were "RUN: ...", then "Run with
# --help for more information.", status 2 only by main's mapping).
check cli11_error_one_line 0 "^1 lines, 1 prefixed, status 2$" -- bash -c 'out=$("$1" env -t abc 2>&1); rc=$?; echo "$(wc -l <<<"$out") lines, $(grep -c "^daq: error: --temperature: .abc. is not a finite decimal number (see daq env --help)$" <<<"$out") prefixed, status $rc"' _ "$DAQ"
check no_doubled_prefix 2 "^daq: error: daq serve needs a set-up: give -c FILE" -- "$DAQ" serve
check no_doubled_prefix_only 0 "^ok$" -- bash -c '"$1" serve 2>&1 | grep -qE "error: daq [a-z]+:" && echo doubled || echo ok' _ "$DAQ"

# A busy port is the user's to change: status 2 naming it (it was status 1).
PORT=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -c 'import socket, sys, time
s = socket.socket(); s.bind(("127.0.0.1", int(sys.argv[1]))); s.listen(); print("held", flush=True); time.sleep(120)' "$PORT" >"$TMP/hold.log" &
HOLD_PID=$!
for _ in $(seq 50); do grep -q held "$TMP/hold.log" && break; sleep 0.1; done
check busy_port 2 "^daq: error: cannot listen on 127\.0\.0\.1:$PORT: Address already in use \(--address, --port\)$" -- "$DAQ" serve --simulate --port "$PORT" --db "$TMP/serve.sqlite"
kill "$HOLD_PID"; HOLD_PID=

# A busy serial port too: two readers would each get part of its bytes. Another program holds
# the simulated barometer's pty with an exclusive flock (as picocom, pyserial's exclusive mode
# and a second daq do): daq run refuses with status 2, naming the port and the holder.
(cd "$TMP" && exec "$DAQ" sim --test linear -o "$TMP/busy.toml" --db "$TMP/busy.sqlite" >"$TMP/busy-sim.log" 2>&1) &
SIM_PID=$!
for _ in $(seq 100); do grep -q "^transport = \"serial" "$TMP/busy.toml" 2>/dev/null && break; sleep 0.1; done
AIR=$(grep -oE '"serial /dev/pts/[0-9]+ 4800' "$TMP/busy.toml" | cut -d' ' -f2)
python3 -c 'import fcntl, os, sys, time
fd = os.open(sys.argv[1], os.O_RDWR | os.O_NOCTTY); fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
print("held", flush=True); time.sleep(120)' "$AIR" >"$TMP/hold-serial.log" &
HOLD_PID=$!
for _ in $(seq 50); do grep -q held "$TMP/hold-serial.log" && break; sleep 0.1; done
check busy_serial_port 2 "^daq: error: device check: devices\.air \(serial $AIR 4800 7E1\): failed: serial $AIR 4800 7E1: busy: pid $HOLD_PID \(python3\) has the port open; close it first" -- "$DAQ" run linear -c "$TMP/busy.toml" --db "$TMP/busy.sqlite"
kill "$HOLD_PID" "$SIM_PID"; HOLD_PID=; SIM_PID=

# A database that cannot be opened: the error only, no demo banner after (or before) it.
check demo_bad_db 0 "^refused, 0 banner lines$" -- bash -c 'out=$(cd "$2" && "$1" demo --db /nonexistent/dir/x.sqlite 2>&1); rc=$?; [ $rc -eq 2 ] && echo "refused, $(grep -c "daq demo: ISO 230-2" <<<"$out") banner lines"' _ "$DAQ" "$TMP"

# daq export -o FILE says what it wrote; piped, its stderr carries no progress.
demo_runs "$TMP"
DB=$TMP/demo.sqlite
check export_says_what 0 "^readings of run 1 written to $TMP/r1.csv \([0-9]+ bytes\)$" -- "$DAQ" export 1 --db "$DB" -o "$TMP/r1.csv"
check export_targets_says 0 "^CSV of the targets of run 1 written to $TMP/t1.csv \([0-9]+ bytes\)$" -- "$DAQ" export 1 --what targets --db "$DB" -o "$TMP/t1.csv"
check export_size_true 0 "^same$" -- bash -c '[ "$(stat -c %s "$2")" = "$("$1" export 1 --db "$3" -o "$2.again" | sed -E "s/.*\(([0-9]+) bytes\)$/\1/")" ] && echo same' _ "$DAQ" "$TMP/r1.csv" "$DB"
check export_piped_silent 0 "^0$" -- bash -c '"$1" export 1 --db "$2" -o "$3" 2>&1 >/dev/null | grep -c "%"; true' _ "$DAQ" "$DB" "$TMP/r2.csv"
# On a terminal (script(1) gives it one) the export shows how far it is, then clears the line.
check export_progress_tty 0 "export run 1: +[0-9]+ % \([0-9]+ of [0-9]+ readings\)" -- script -qec "'$DAQ' export 1 --db '$DB' -o '$TMP/r3.csv'" /dev/null
cmp -s "$TMP/r1.csv" "$TMP/r3.csv" && passes=$((passes + 1)) || { echo "FAIL export_same_on_tty"; fails=$((fails + 1)); }

# daq report shows its progress on a terminal too: the readings a long run's plots read (a run
# of another kind, here an imported dynamic capture of 3 samples), then the time Chromium has
# taken printing; piped, nothing.
printf 'HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13\r\nFile Type: Linear\r\nSample rate: 50000\r\nSample no: 3\r\nActual sample rate: 1000\r\nMachine: VMC-7\r\nSerial No: 99\r\nAxis: Y\r\nData:\r\n\x00\x00\x00\x00\x00\x00\xf0\x3f\x00\x00\x00\x00\x00\x00\x04\xc0\x00\x00\x00\x00\x00\x00\xc0\x3f\r\nEOF::\r\n' >"$TMP/t.rtx"
"$DAQ" import rtx "$TMP/t.rtx" --db "$TMP/rtx.sqlite" >/dev/null
check report_progress_tty 0 "report of run 1: +[0-9]+ % \([0-9] of 3 readings\)" -- script -qec "'$DAQ' report 1 --db '$TMP/rtx.sqlite' -o '$TMP/rtx.html'" /dev/null
check report_pdf_progress_tty 0 "report of run 1: printing the PDF with Chromium, 0:[0-9]{2} elapsed" -- script -qec "'$DAQ' report 1 --db '$DB' --format pdf -o '$TMP/r1.pdf'" /dev/null
check report_pdf_written 0 "^%PDF" -- head -c 4 "$TMP/r1.pdf"
check report_piped_silent 0 "^0$" -- bash -c '"$1" report 1 --db "$2" --format pdf -o "$3" 2>&1 >/dev/null | grep -c "elapsed"; true' _ "$DAQ" "$DB" "$TMP/r2.pdf"

# daq run's progress, piped (a line per stop): the plan's place, no number before a reading,
# the position while moving, the time so far and left.
(cd "$TMP" && "$DAQ" sim --test linear --acquire --runs 2 --targets 2 --db "$TMP/run.sqlite" -o "$TMP/sim.toml" >"$TMP/run.log" 2>&1)
check run_completes 0 "all stops captured" -- cat "$TMP/run.log"
check run_first_line_no_number 0 "^run 1 of 2 up  target 1 of 2  stop 1 of 8  waiting for the laser's first reading$" -- cat "$TMP/run.log"
absent() { grep -qE -- "$1" "$2" && echo "present: $(grep -m1 -E -- "$1" "$2")" || echo absent; }
check run_no_zero_air 0 "^absent$" -- absent "air 0\.00 degC" "$TMP/run.log"
check run_no_distance_to_target 0 "^absent$" -- absent "[-+][0-9]{4,}\.[0-9]+ um" "$TMP/run.log"
check run_stop_k_of_n 0 "^run 2 of 2 down  target 1 of 2  stop 8 of 8  " -- cat "$TMP/run.log"
check run_air_when_sampled 0 "air [12][0-9]\.[0-9]{2} degC  material [12][0-9]\.[0-9]{2} degC  [0-9]+:[0-9]{2} elapsed" -- cat "$TMP/run.log"
check run_time_left 0 "stop [2-8] of 8  .* elapsed, about [0-9]+:[0-9]{2} left$" -- cat "$TMP/run.log"
# daq sim --tolerances: only tolerance tables, only with --measure; refused before anything runs.
printf '[tolerances.X]\nstraightness_um = 1\n[machine]\nname = "x"\n' >"$TMP/tol-bad.toml"
check sim_tolerances_only 2 "tol-bad.toml:3:1: 'machine': only \[tolerances.AXIS\] and \[tolerances.PLANE\] tables" -- "$DAQ" sim --measure E_YX --acquire --tolerances "$TMP/tol-bad.toml" --db "$TMP/tol.sqlite" -o "$TMP/tol.toml"
check sim_tolerances_measure 2 "--tolerances applies to --measure" -- "$DAQ" sim --test linear --acquire --tolerances "$TMP/tol-bad.toml" --db "$TMP/tol.sqlite" -o "$TMP/tol.toml"
# --json: the result alone on stdout, the progress as JSON lines on stderr.
(cd "$TMP" && "$DAQ" sim --test linear --acquire --json --runs 2 --targets 2 --db "$TMP/run.sqlite" -o "$TMP/sim2.toml" >"$TMP/run.json" 2>"$TMP/run.err")
check run_json_result 0 "^linear complete 0$" -- python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print("linear", d["status"], len(d["missed_stops"]))' "$TMP/run.json"
check run_json_lines 0 "^live [1-9][0-9]* event [1-9][0-9]* other 0 first-display None$" -- python3 -c '
import json, sys
n = {"caldaq.live.v1": 0, "caldaq.event.v1": 0}; other = 0; first = "unset"
for line in open(sys.argv[1]):
    if not line.startswith("{"): continue  # the device check before the run is text
    d = json.loads(line)
    if d.get("schema") in n: n[d["schema"]] += 1
    else: other += 1
    if d.get("schema") == "caldaq.live.v1" and first == "unset": first = d["display"]
print("live", n["caldaq.live.v1"], "event", n["caldaq.event.v1"], "other", other, "first-display", first)' "$TMP/run.err"

finish
