#!/usr/bin/env bash
# Bad input at the door (issue 15): every reproduction of the issue through the real `daq`
# command line now gets a clear error naming what and where, with exit status 2, and nothing
# non-finite or out of syntax is written into a part program or a controller table.
# Usage: hostile_input_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$(realpath "$1")  # absolute: the numeric options are tried from $TMP
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir

# Usage errors: status 2 as docs/cli.md says (CLI11's own codes were 104-109).
check usage_unknown_option 2 "^daq: error: unknown option .--bogus. of daq runs" -- "$DAQ" runs --bogus
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
# daq bench export's generated values and the build it compares with: a clear refusal, nothing run.
check bench_export_values 2 "^daq: error: --values: nonsense not in \{quantised,unquantised,both\}" -- "$DAQ" bench export --minutes 1 --steps 1 --dir "$TMP" --values nonsense
check bench_export_peer_missing 2 "^daq: error: --peer-daq: File does not exist: $TMP/no-daq" -- "$DAQ" bench export --minutes 1 --steps 1 --dir "$TMP" --peer-daq "$TMP/no-daq"
check bench_export_repeat_zero 2 "^daq: error: --repeat: '0' is not a whole number in \[1, 1000\]" -- "$DAQ" bench export --minutes 1 --steps 1 --dir "$TMP" --repeat 0
# A simulated vibration the ballbar would sample as an alias (at or above 0.45 of its rate, where
# the analysis stops looking) is refused, as is half of the pair, before anything is recorded.
check sim_vibration_alias 2 "--vibration-y-hz 876.6 Hz: at or above 450 Hz \\(0.45 x --ballbar-rate-hz 1000\\)" -- "$DAQ" sim --acquire --test circle --db "$TMP/vib.sqlite" --vibration-y-um 1 --vibration-y-hz 876.6
check bench_replay_vibration_alias 2 "--circle-vibration-hz 500 Hz: at or above 450 Hz" -- "$DAQ" bench replay --kinds ballbar --dir "$TMP" --circle-vibration-um 1 --circle-vibration-hz 500
check bench_replay_vibration_half 2 "--circle-vibration-um and --circle-vibration-hz go together" -- "$DAQ" bench replay --kinds ballbar --dir "$TMP" --circle-vibration-um 1
check bench_replay_vibration_no_circle 2 "none of --kinds is replayed from: add ballbar" -- "$DAQ" bench replay --kinds ids3010 --dir "$TMP" --circle-vibration-um 1 --circle-vibration-hz 100

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

# Issue 27: every numeric option is finite, plain and in range whatever its validator (18 of
# them took nan and hex because CLI11's range check replaced the finite-number check: `replay
# --speed nan` exited 0, `serve --request-timeout-s nan` started a server that answered
# nothing). One row per option: the command before it, the option, a value out of its range
# (and what follows). Each is tried with nan, inf, hex and that value; `timeout` keeps a
# command that wrongly starts from hanging the test.
printf 'direction,angle_deg,deviation_um\nccw,0,1\nccw,90,2\nccw,180,1\nccw,270,0\n' >"$TMP/circ.csv"
printf '{}' >"$TMP/model.json"
NUMERIC_OPTIONS=(
  "sim|--speed|1000"
  "sim|--start-after-s|-1"
  "sim|--runs|11"
  "sim|--targets|12"
  "sim|--feed-mm-per-min|5"
  "sim|--ballbar-rate-hz|50"
  "sim|--vibration-y-um|-1"
  "sim|--vibration-y-hz|-1"
  "bench replay|--circle-feed-mm-per-min|5"
  "bench replay|--circle-vibration-um|-1"
  "bench replay|--circle-vibration-hz|-1"
  "demo|--speed|300"
  "replay $TMP/none.cdq|--speed|-1"
  "run linear -c $TMP/none.toml|--check-s|-1"
  "run circle -c $TMP/none.toml|--check-s|-1"
  "serve|--speed|0.5"
  "serve|--max-connections|3"
  "serve|--request-timeout-s|0"
  "serve|--check-s|-1"
  "bench ingest|--loop-cpu|-2"
  "bench ingest|--storage-cpu|-2"
  "analyse circle -i $TMP/circ.csv|--radius-mm|0"
  "analyse circle -i $TMP/circ.csv -R 100|--feed-mm-min|0"
  "analyse circle -i $TMP/circ.csv -R 100|--calibrated-radius-mm|0"
  "analyse 1|--calibrated-radius-mm|0"
  "analyse 1|--cyclic-period-mm|0"
  "ballbar calibrate --bar B --calibrator-mm 100 --reading-mm 0|--nominal-mm|0"
  "ballbar calibrate --bar B --nominal-mm 100 --reading-mm 0|--calibrator-mm|0"
  "model map $TMP/model.json|--min-mm|1e6|0 0 --max-mm 1 1 1"
  "model testpiece $TMP/model.json --tool-radius-mm 5|--origin-mm|1e6|0 0"
  "model testpiece $TMP/model.json --origin-mm 0 0 0|--tool-radius-mm|-1"
)
cd "$TMP" || exit 1  # where a command that wrongly starts writes its files
for row in "${NUMERIC_OPTIONS[@]}"; do
  IFS='|' read -r before option out_of_range after <<<"$row"
  for value in nan inf 0x10 "$out_of_range"; do
    # shellcheck disable=SC2086 # word splitting of the row's parts is the point
    check "numeric ${before%% *} $option $value" 2 "$option: '$value' is not a" -- \
      env CALDAQ_DB="$TMP/numeric.sqlite" timeout 10 "$DAQ" $before "$option" "$value" $after
  done
done
cd - >/dev/null || exit 1

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

# --- Issue 27 -----------------------------------------------------------------------------------
# An end marker after a partial sample was read as a sample of 4.95e27 m: now the marker, with
# the 3 bytes before it dropped and noted.
rtx "$TMP/odd.rtx" Linear 1000 2 '\x01\x02\x03\r\nEOF::\r\n'
check rtx_odd_tail_marker 0 "2 linear samples" -- "$DAQ" import rtx "$TMP/odd.rtx" --db "$TMP/odd.sqlite"
check rtx_odd_tail_range 0 "range -2\.500000 .. 1\.000000 mm" -- "$DAQ" import rtx "$TMP/odd.rtx" --db "$TMP/odd.sqlite"
check rtx_odd_tail_noted 0 "ends inside a sample \(3 bytes dropped\)" -- "$DAQ" import rtx "$TMP/odd.rtx" --db "$TMP/odd.sqlite"
# "By: Müller" in Windows-1252 gave exit 1 and a raw JSON library error: refused with the line
# and byte, or read as Windows-1252 when asked.
{ printf 'HEADER::\r\nOwner: CARTO-Dynamic\r\nFile Type: Linear\r\nActual sample rate: 1000\r\nBy: M\xfcller\r\nData:\r\n'
  printf '\x00\x00\x00\x00\x00\x00\xf0\x3f\r\nEOF::\r\n'; } >"$TMP/cp1252.rtx"
check rtx_not_utf8 2 "cp1252.rtx: line 5, byte 82: the header is not UTF-8 text \(byte 0xFC\).*--header-encoding windows-1252" -- "$DAQ" import rtx "$TMP/cp1252.rtx" --db "$TMP/enc.sqlite"
check rtx_windows_1252 0 "imported .* into run 1" -- "$DAQ" import rtx "$TMP/cp1252.rtx" --db "$TMP/enc.sqlite" --header-encoding windows-1252
check rtx_windows_1252_stored 0 '"By": "Müller"' -- "$DAQ" show 1 --db "$TMP/enc.sqlite" --json
{ printf 'HEADER::\r\nFile Type: Linear\r\nActual sample rate: 1000\r\nMachine: VMC\x1b]0;owned\x07\r\nData:\r\n'
  printf '\x00\x00\x00\x00\x00\x00\xf0\x3f\r\nEOF::\r\n'; } >"$TMP/esc.rtx"
check rtx_control_character 2 "esc.rtx: line 4, byte .*: a control character \(0x1B\) in the header" -- "$DAQ" import rtx "$TMP/esc.rtx" --db "$TMP/enc.sqlite"
# `daq decode temper --json` of bytes that are not UTF-8: valid JSON, the bytes as U+FFFD.
check decode_json_not_utf8 0 "TEMPer\\?ufffdGold|TEMPer.Gold" -- bash -c "printf 'firmware: TEMPer\xfcGold_V9.9\n80 80 09 2e 00 00 00 00\n' | '$DAQ' decode temper - --json | python3 -c 'import json,sys; [print(json.loads(l).get(\"reason\", \"\")) for l in sys.stdin]'"
# Control characters in stored text and device ids never reach the terminal as they are.
check decode_text_escaped 0 'TEMPer\\x1B\[2JGold' -- bash -c "printf 'firmware: TEMPer\x1b[2JGold_V9.9\n80 80 09 2e 00 00 00 00\n' | '$DAQ' decode temper -"
check stored_axis_import 0 "into run 2" -- "$DAQ" import rtx "$TMP/real.rtx" --db "$TMP/enc.sqlite" --axis $'X\e[2J\e]52;c;aGk=\a'
check stored_axis_runs_escaped 0 'X\\x1B\[2J\\x1B\]52;c;aGk=\\x07' -- "$DAQ" runs --db "$TMP/enc.sqlite"
check stored_axis_show_escaped 0 'dynamic X\\x1B\[2J' -- "$DAQ" show 2 --db "$TMP/enc.sqlite"
check stored_no_raw_escape 0 "^no ESC$" -- bash -c "('$DAQ' runs --db '$TMP/enc.sqlite'; '$DAQ' show 2 --db '$TMP/enc.sqlite') | grep -q \$'\\e' || echo 'no ESC'"
check device_id_control 2 'c.toml:5:1: table \[devices\]: device id .la\\x1B\[2Jser.: use 1 to 64 letters' -- "$DAQ" gcode linear -c "$(conf '[test.linear]' 'count = 5' '[devices."la\u001b[2Jser"]' 'driver = "ptu300"' 'transport = "serial /dev/null 4800 7E1"')"
check device_serial_control 2 "key 'devices.air.serial_number': control characters are not allowed" -- "$DAQ" gcode linear -c "$(conf '[test.linear]' 'count = 5' '[devices.air]' 'driver = "ptu300"' 'transport = "serial /dev/null 4800 7E1"' 'serial_number = "A\u001b[2J"')"

# JSON nested 100 000 deep in a model's provenance or a component's source crashed all four
# `daq model` commands (a recursive dump): refused with the file and the byte.
python3 -c "
import json
deep = '[' * 100000 + ']' * 100000
print('{\"schema\": \"caldaq.model.v1\", \"units\": {\"position\": \"mm\", \"translation\": \"um\", \"angle\": \"urad\"}, \"topology\": \"FXYZ\", \"provenance\": ' + deep + '}')" >"$TMP/deep.json"
python3 -c "
deep = '{\"a\":' * 100000 + '1' + '}' * 100000
print('{\"schema\": \"caldaq.model.v1\", \"units\": {\"position\": \"mm\", \"translation\": \"um\", \"angle\": \"urad\"}, \"topology\": \"FXYZ\", \"components\": {\"E_XX\": {\"polynomial\": [0, 1], \"source\": ' + deep + '}}}')" >"$TMP/deep_source.json"
for m in deep deep_source; do
  check "model_${m}_show" 2 "$m.json: line 1, byte [0-9]+: JSON nested deeper than 64 levels" -- "$DAQ" model show "$TMP/$m.json"
  check "model_${m}_map" 2 "$m.json: line 1, byte [0-9]+: JSON nested deeper than 64 levels" -- "$DAQ" model map "$TMP/$m.json" --min-mm 0 0 0 --max-mm 1 1 1
  check "model_${m}_compensate" 2 "$m.json: line 1, byte [0-9]+: JSON nested deeper than 64 levels" -- "$DAQ" model compensate "$TMP/$m.json" -f csv --interval-mm 50 50 50
  check "model_${m}_testpiece" 2 "$m.json: line 1, byte [0-9]+: JSON nested deeper than 64 levels" -- "$DAQ" model testpiece "$TMP/$m.json" --origin-mm 0 0 0 --tool-radius-mm 5
done
# Absurd model values made map and testpiece print inf and -nan with exit 0.
M='"schema": "caldaq.model.v1", "units": {"position": "mm", "translation": "um", "angle": "urad"}, "topology": "FXYZ"'
printf '{%s, "components": {"E_XX": {"table": {"position_mm": [0, 100], "value": [0, 1e300]}}}}' "$M" >"$TMP/huge_table.json"
check model_huge_value 2 "huge_table.json: components.E_XX.table.value\[1\]: 1e\+300 um is beyond 1e\+08 um" -- "$DAQ" model show "$TMP/huge_table.json"
printf '{%s, "tool_offset_mm": [0, 0, 1e9]}' "$M" >"$TMP/far.json"
check model_far_offset 2 "far.json: tool_offset_mm\[2\]: 1000000000 mm is beyond 100000 mm" -- "$DAQ" model show "$TMP/far.json"
printf '{%s, "travel_mm": {"X": [0, 1000], "Y": [0, 1000], "Z": [-500, 0]}, "components": {"E_XX": {"polynomial": [0, 0, 0, 1e300]}}}' "$M" >"$TMP/steep.json"
check model_polynomial_over_travel 2 "steep.json: components.E_XX.polynomial: .* um at .* mm of the X travel, beyond" -- "$DAQ" model show "$TMP/steep.json"
printf '{%s, "components": {"E_XX": {"polynomial": [0, 0, 0, 1e300]}}}' "$M" >"$TMP/overflow.json"
check model_map_not_finite 2 "the volumetric error over the grid: -?inf is not a finite number" -- "$DAQ" model map "$TMP/overflow.json" --min-mm 0 0 0 --max-mm 1000 1000 1000
check model_points_not_finite 2 "p1.csv:2: the error at .*: -?inf is not a finite number" -- sh -c "printf 'x_mm,y_mm,z_mm\n1000,0,0\n' >'$TMP/p1.csv'; '$DAQ' model map '$TMP/overflow.json' --points '$TMP/p1.csv'"
check model_testpiece_not_finite 2 "is not a finite number" -- "$DAQ" model testpiece "$TMP/overflow.json" --origin-mm 900 0 0 --tool-radius-mm 5
# CMM points: a header alone, and bore points on a straight line, were accepted.
printf 'feature,x_mm,y_mm\n' >"$TMP/cmm_empty.csv"
check cmm_header_only 2 "cmm_empty.csv:1: a header and no rows of data" -- "$DAQ" model testpiece "$DATA/model/square50.json" --origin-mm 100 100 -50 --tool-radius-mm 5 --cmm "$TMP/cmm_empty.csv"
printf 'feature,x_mm,y_mm\nbore1,38,26\nbore1,38,30\nbore1,38,34\n' >"$TMP/cmm_line.csv"
check cmm_collinear_bore 2 "cmm_line.csv: bore1: the points lie within half of the bore" -- "$DAQ" model testpiece "$DATA/model/square50.json" --origin-mm 100 100 -50 --tool-radius-mm 5 --cmm "$TMP/cmm_line.csv"
# ballbar calibrate stored 1e300 mm, -300 degC and the year 26.
BB=("$DAQ" ballbar calibrate --db "$TMP/bb.sqlite" --bar B --reading-mm 0)
check bar_length_absurd 2 "--nominal-mm 1e\+300 mm: a bar is longer than 0 and at most 100 m" -- "${BB[@]}" --nominal-mm 1e300 --calibrator-mm 1e300
check bar_temperature_absurd 2 "--temperature-degc -300: outside -50 .. 100 degC" -- "${BB[@]}" --nominal-mm 100 --calibrator-mm 100 --temperature-degc -300
check bar_year_26 2 "--date '0026-01-05': before 1990 or in the future" -- "${BB[@]}" --nominal-mm 100 --calibrator-mm 100 --date 0026-01-05
check bar_future 2 "--date '2999-01-05': before 1990 or in the future" -- "${BB[@]}" --nominal-mm 100 --calibrator-mm 100 --date 2999-01-05
check bar_nothing_stored 2 "bb.sqlite: no such database" -- "$DAQ" ballbar calibrations --db "$TMP/bb.sqlite"
# Capture headers of the wrong shape gave a raw JSON error: the file and the key named.
W="$(dirname "$0")/write_capture.py"
python3 "$W" "$TMP/shape1.cdq" '{"format": "caldaq.capture-header.v1", "config": {"machine": 5}, "instruments": []}'
check capture_header_machine 2 "shape1.cdq: capture header: config: key 'machine': expected a string, found number" -- "$DAQ" replay "$TMP/shape1.cdq" --db "$TMP/shape.sqlite"
python3 "$W" "$TMP/shape2.cdq" '{"format": "caldaq.capture-header.v1", "config": {}, "instruments": [{"device": "0", "driver": "ids3010"}]}'
check capture_header_device 2 "shape2.cdq: capture header: instruments\[\]: key 'device': expected a whole number, found string" -- "$DAQ" replay "$TMP/shape2.cdq" --db "$TMP/shape.sqlite"
python3 "$W" "$TMP/shape3.cdq" '{"format": "caldaq.capture-header.v1", "config": {}, "instruments": {}}'
check capture_header_instruments 2 "shape3.cdq: capture header: key 'instruments': expected an array" -- "$DAQ" replay "$TMP/shape3.cdq" --db "$TMP/shape.sqlite"
python3 "$W" "$TMP/shape4.cdq" "{\"format\": \"caldaq.capture-header.v1\", \"config\": $(python3 -c "print('[' * 5000 + ']' * 5000)")}"
check capture_header_deep 2 "shape4.cdq: capture header: line 1, byte [0-9]+: JSON nested deeper than 64 levels" -- "$DAQ" replay "$TMP/shape4.cdq" --db "$TMP/shape.sqlite"
finish
