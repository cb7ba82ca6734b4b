#!/usr/bin/env bash
# Bad input at the door (issue 15): every reproduction of the issue through the real `daq`
# command line now gets a clear error naming what and where, with exit status 2, and nothing
# non-finite or out of syntax is written into a part program or a controller table.
# Usage: hostile_input_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
source "$(dirname "$0")/check.sh"

# Usage errors: status 2 as docs/cli.md says (CLI11's own codes were 104-109).
check usage_unknown_option 2 "The following argument was not expected: --bogus" -- "$DAQ" runs --bogus
check usage_no_command 2 "A subcommand is required" -- "$DAQ"
check usage_missing_required 2 "--last is required" -- "$DAQ" targets --first 0
check usage_not_a_number 2 "'abc' is not a finite decimal number" -- "$DAQ" env -t abc
check help_is_success 0 "Usage:" -- "$DAQ" --help
check version_is_success 0 "daq 0.1.0" -- "$DAQ" --version
# daq bench ingest's thread placement: a CPU this process may not use is refused (exit 2, the CPU
# named) before the capture is written and a round run, and both CPUs or neither. CPU0: the
# first CPU this test may use.
CPU0=$(python3 -c 'import os; print(min(os.sched_getaffinity(0)))')
check bench_cpu_not_ours 2 "CPU 4096: not one this process may run on" -- "$DAQ" bench ingest --seconds 1 --rounds 1 --dir "$TMP" --loop-cpu "$CPU0" --storage-cpu 4096
check bench_cpu_half 2 "give both --loop-cpu and --storage-cpu" -- "$DAQ" bench ingest --seconds 1 --rounds 1 --dir "$TMP" --loop-cpu "$CPU0"
check bench_cpu_before_the_capture 0 "^refused, 0 capture lines$" -- sh -c "out=\$(\"$DAQ\" bench ingest --seconds 1 --rounds 1 --dir \"$TMP\" --loop-cpu 4096 --storage-cpu $CPU0 2>&1); test \$? -eq 2 && echo \"\$out\" | grep -q 'CPU 4096' && echo \"refused, \$(echo \"\$out\" | grep -c '^capture:') capture lines\""

# Command-line numbers: finite, plain, in range, sizes bounded.
check cli_nan 2 "--temperature: 'nan' is not a finite decimal number" -- "$DAQ" env -t nan
check cli_inf 2 "'inf' is not a finite decimal number" -- "$DAQ" env -p inf
check cli_hex 2 "'0x10' is not a finite decimal number" -- "$DAQ" env -t 0x10
check cli_int_exponent 2 "'1e9' is not a whole decimal number" -- "$DAQ" targets --first 0 --last 100 --count 1e9
check cli_count_bounded 2 "count = 1000000000 must be in 2 .. 10000" -- "$DAQ" targets --first 0 --last 100 --count 1000000000
check cli_interval_bounded 2 "more than 10000" -- "$DAQ" targets --first 0 --last 1000000 --interval 0.001
check cli_octal_count 0 "^10$" -- sh -c "\"$DAQ\" targets --first 0 --last 90 --count 010 --json | python3 -c 'import json,sys; print(len(json.load(sys.stdin)[\"targets_mm\"]))'"
check cli_int_overflow 2 "Could not convert: --runs = 4294967297" -- "$DAQ" targets --first 0 --last 100 --count 5 --runs 4294967297
check cli_int64_overflow 2 "'99999999999999999999' is out of range" -- "$DAQ" targets --first 0 --last 100 --count 5 --runs 99999999999999999999

# Compensation tables: no nan, inf or foreign characters reach a controller.
COMP="$DAQ compensate --input $DATA/compensate/meas.csv --interval-mm 50 --points 5"
check comp_start_nan 2 "--start-mm: 'nan' is not a finite decimal number" -- $COMP --start-mm nan
check comp_resolution 2 "resolution 1e-320 must be 0 \(none\) or within 1e-9 .. 1" -- $COMP --start-mm 0 --resolution 1e-320 -f siemens
check comp_points_exponent 2 "'2e9' is not a whole decimal number" -- "$DAQ" compensate --input "$DATA/compensate/meas.csv" --start-mm 0 --interval-mm 50 --points 2e9
check comp_points_bounded 2 "2000000000 points, expected 2 .. 100000" -- "$DAQ" compensate --input "$DATA/compensate/meas.csv" --start-mm 0 --interval-mm 50 --points 2000000000
check comp_axis_newline 2 "axis name 'X" -- $COMP --start-mm 0 -f siemens --axis $'X\nM30'
check comp_axis_ok 0 "LEC for axis X2 " -- $COMP --start-mm 0 -f siemens --axis X2
check comp_dev_zero 2 "/dev/zero: over the 256 MiB limit of a measurement file" -- "$DAQ" compensate -i /dev/zero --start-mm 0 --interval-mm 50 --points 5
printf 'position_mm,deviation_um\n0,0\n100,1.5abc\n200,4\n' >"$TMP/garbage.csv"
check comp_straightness_sscanf 2 "garbage.csv:3: column deviation_um: '1.5abc' is not a number" -- "$DAQ" compensate --straightness "$TMP/garbage.csv" --output-axis Y --start-mm 0 --interval-mm 100 --points 3

# CSV readers: extra cells (a decimal-comma file), hex, NUL; decimal commas only when asked.
printf 'position_mm,deviation_um\n0,0,000\n100,4,000\n200,0,000\n' >"$TMP/comma.csv"
printf 'position_mm;deviation_um\n0;0,000\n100;4,000\n200;0,000\n' >"$TMP/semicolon.csv"
printf 'position_mm,deviation_um\n0,0\n100,0x4\n200,0\n' >"$TMP/hex.csv"
printf 'position_mm,deviation_um\n0,0\n100,4\0003\n200,0\n' >"$TMP/nul.csv"
check csv_decimal_comma 2 "comma.csv:2: 3 cells, the header \(line 1\) has 2 columns \(a decimal comma\?" -- "$DAQ" analyse straightness -i "$TMP/comma.csv"
check csv_decimal_comma_asked 0 "straightness +4.000 um" -- "$DAQ" analyse straightness -i "$TMP/semicolon.csv" --decimal-comma -r endpoint
check csv_hex 2 "hex.csv:3: column deviation_um: '0x4' is not a number" -- "$DAQ" analyse straightness -i "$TMP/hex.csv"
check csv_nul 2 "nul.csv:3: column deviation_um: '4\\\\x003' is not a number" -- "$DAQ" analyse straightness -i "$TMP/nul.csv"
printf 'direction,angle_deg,deviation_um\nccw,0,1,5\nccw,90,2\n' >"$TMP/circle.csv"
check csv_circle_extra_cell 2 "circle.csv:2: 4 cells, the header \(line 1\) has 3 columns" -- "$DAQ" analyse circle -i "$TMP/circle.csv" -R 100
printf 'target_mm,run,direction,deviation_um\n0,1,up,1,5\n' >"$TMP/iso.csv"
check csv_iso_extra_cell 2 "iso.csv:2: 5 cells" -- "$DAQ" analyse iso230-2 -i "$TMP/iso.csv"

# Configurations: every value checked at load, with file:line:column.
cat >"$TMP/base.toml" <<'EOF'
[machine]
name = "hostile"
EOF
conf() { { cat "$TMP/base.toml"; printf '%s\n' "$@"; } >"$TMP/c.toml"; echo "$TMP/c.toml"; }
check conf_radius_inf 2 "c.toml:4:13: key 'test.circle.radius_mm': inf is not a finite number" -- "$DAQ" gcode circle -c "$(conf '[test.circle]' 'radius_mm = inf')"
check conf_centre_nan 2 "c.toml:4:13: key 'test.circle.centre_mm': nan is not a finite number" -- "$DAQ" gcode circle -c "$(conf '[test.circle]' 'centre_mm = [nan, 0, 0]')"
check conf_overrun 2 "key 'test.linear.overrun_mm': 1000000000 must be within 0 .. 1000 mm" -- "$DAQ" gcode linear -c "$(conf '[test.linear]' 'count = 5' 'overrun_mm = 1e9')"
check conf_runs_overflow 2 "key 'test.linear.runs': 4294967297 is out of range" -- "$DAQ" gcode linear -c "$(conf '[test.linear]' 'count = 5' 'runs = 4294967297')"
check conf_standard 2 "key 'test.linear.standard': .*iso230-2:2041" -- "$DAQ" gcode linear -c "$(conf '[test.linear]' 'count = 5' 'standard = "iso230-2:2041"')"
check conf_plane_used 0 "^G18 |G21 G90 G18 G94" -- "$DAQ" gcode circle -c "$(conf '[test.circle]' 'plane = "ZX"' 'radius_mm = 50')"
check conf_ok_no_nan 0 "G03 " -- "$DAQ" gcode circle -c "$(conf '[test.circle]' 'radius_mm = 50')"

# Renishaw .rtx: the real end marker, the file type, nonsense header values.
rtx() {  # rtx FILE TYPE RATE COUNT TAIL
  { printf 'HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13\r\nFile Type: %s\r\nSample rate: 50000\r\nSample no: %s\r\nActual sample rate: %s\r\nAxis: X\r\nData:\r\n' "$2" "$4" "$3"
    printf '\x00\x00\x00\x00\x00\x00\xf0\x3f\x00\x00\x00\x00\x00\x00\x04\xc0'
    printf "$5"; } >"$1"
}
rtx "$TMP/real.rtx" Linear 1000 2 '\r\nEOF::\r\n'
check rtx_real_marker 0 "imported .*real.rtx into run 1: 2 linear samples at 1000 Hz" -- "$DAQ" import rtx "$TMP/real.rtx" --db "$TMP/rtx.sqlite"
check rtx_no_false_note 0 "^ +1 +.* dynamic +X +complete +2" -- "$DAQ" runs --db "$TMP/rtx.sqlite"
check rtx_no_note_json 0 "\"notes\": \[\]" -- "$DAQ" import rtx "$TMP/real.rtx" --db "$TMP/rtx.sqlite" --json
rtx "$TMP/angular.rtx" Angular 1000 2 '\r\nEOF::\r\n'
check rtx_angular_needs_unit 2 "angular.rtx: an Angular capture: give --unit arcsec" -- "$DAQ" import rtx "$TMP/angular.rtx" --db "$TMP/bad.sqlite"
check rtx_angular_not_mm 2 "'mm' is not an angle unit" -- "$DAQ" import rtx "$TMP/angular.rtx" --db "$TMP/bad.sqlite" --unit mm
check rtx_angular_imported 0 "into run 3: 2 angular samples .* unit arcsec \(from --unit\)" -- "$DAQ" import rtx "$TMP/angular.rtx" --db "$TMP/rtx.sqlite" --unit arcsec
# 1 arcsec = pi / 648000 rad = 4.8481368110953598e-06 rad
check rtx_angular_stored_as_angle 0 ",angle_rad,0,4\.848136811095" -- "$DAQ" export 3 --db "$TMP/rtx.sqlite"
rtx "$TMP/straight.rtx" Straightness 1000 2 '\r\nEOF::\r\n'
check rtx_type_refused 2 "straight.rtx: header: File Type 'Straightness' is not supported" -- "$DAQ" import rtx "$TMP/straight.rtx" --db "$TMP/bad.sqlite"
rtx "$TMP/inf.rtx" Linear inf 2 '\r\nEOF::\r\n'
check rtx_rate_inf 2 "inf.rtx: header: Actual sample rate 'inf' is not a rate within" -- "$DAQ" import rtx "$TMP/inf.rtx" --db "$TMP/bad.sqlite"
rtx "$TMP/tiny.rtx" Linear 1e-300 2 '\r\nEOF::\r\n'
check rtx_rate_tiny 2 "Actual sample rate '1e-300' is not a rate within" -- "$DAQ" import rtx "$TMP/tiny.rtx" --db "$TMP/bad.sqlite"
rtx "$TMP/huge.rtx" Linear 1000 1e300 '\r\nEOF::\r\n'
check rtx_count_huge 2 "Sample no '1e300' is not a whole number of samples" -- "$DAQ" import rtx "$TMP/huge.rtx" --db "$TMP/bad.sqlite"
# Nothing stored on refusal: not even a database was created (daq runs only reads, so a
# missing database is an error naming it).
check rtx_nothing_stored_on_refusal 2 "bad.sqlite: no such database" -- "$DAQ" runs --db "$TMP/bad.sqlite"
finish
