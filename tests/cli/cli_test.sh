#!/usr/bin/env bash
# End-to-end tests of the daq command line: exit codes, key numbers in the output, and the
# error messages for bad input. Usage: cli_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2

source "$(dirname "$0")/check.sh"
scratch_dir

check help 0 "analyse" -- "$DAQ" --help
check analyse_help 0 "iso230-2" -- "$DAQ" analyse --help
# NIST shop-floor equation by hand at 20 degC, 101.325 kPa, 50 %RH:
# 1 + 7.86e-4 x 101.325 / 293 - 1.5e-11 x 50 x 560 = 1.000271393 (to 9 decimals)
check env_shop_floor 0 '"n": 1\.00027139' -- "$DAQ" env -t 20 -p 1013.25 -r 50 -e shop-floor --json
check env_text 0 "ciddor +1\.0002713" -- "$DAQ" env -t 20 -p 1013.25 -r 50
check env_material 0 '"material_temperature_degc": 20\.5' -- "$DAQ" env -m 20 -m 21 -m 99 --disable-sensor 3 --json
check env_out_of_range 2 "air temperature = 150 degC is outside the valid range" -- "$DAQ" env -t 150 -e ciddor
check env_bad_sensor 2 "there are 1 material sensors" -- "$DAQ" env -m 20 --disable-sensor 2
# Hand-calculated data set: R = 9, E = 7, A = 10 (see tests/analysis/iso230_2_test.cpp)
check iso_json 0 '"R_bi": \{[^}]*"value_um": 9\.0' -- bash -c "\"$DAQ\" analyse iso230-2 --input \"$DATA/hand.csv\" --json | tr -d '\n'"
check iso_text 0 "E +7\.000 um" -- "$DAQ" analyse iso230-2 -i "$DATA/hand.csv"
check iso_vdi 0 '"P": \{[^}]*"value_um": 13\.0' -- bash -c "\"$DAQ\" analyse iso230-2 -i \"$DATA/hand.csv\" -s vdi3441 --json | tr -d '\n'"
check iso_unknown_standard 2 "unknown standard 'iso9999'" -- "$DAQ" analyse iso230-2 -i "$DATA/hand.csv" -s iso9999
check iso_bad_csv 2 "bad_direction.csv:3: column direction: 'sideways'" -- "$DAQ" analyse iso230-2 -i "$DATA/bad_direction.csv"
check iso_missing_file 2 "no_such.csv: cannot open" -- "$DAQ" analyse iso230-2 -i "$DATA/no_such.csv"
check targets 0 "121 moves" -- "$DAQ" targets --first 0 --last 1000 --interval 100 --random-fraction 0.2
check targets_json 0 '"schema": "caldaq.plan.v1"' -- "$DAQ" targets --first 0 --last 100 --count 6 --json
check targets_bad 2 "does not divide" -- "$DAQ" targets --first 0 --last 100 --interval 30
# ISO 230-2 over 2000 mm: 250 mm apart by default, one run per direction with a note.
check targets_long 0 "^13 targets \(mm\): 0\.000 250\.000 " -- "$DAQ" targets --first 0 --last 3000 --runs 1
check targets_long_note 0 "^note: axis over 2000 mm" -- "$DAQ" targets --first 0 --last 3000 --runs 1
check targets_short_default 2 "give an interval or a count" -- "$DAQ" targets --first 0 --last 1000
check uncertainty 0 "expanded uncertainty U \(k = 2\)" -- "$DAQ" uncertainty -L 1 -m 21
demo_runs "$TMP"  # `daq demo --quiet` (the ctest fixture "demo", or run here)
check demo 0 "Simulated truth vs measured" -- cat "$TMP/demo.log"
# A capture cut in half: the replay says where the damage is and stores nothing as complete.
head -c 300000 "$DEMO_CDQ" > "$TMP/cut.cdq"
check replay_damaged 2 "cut.cdq: replay stored as run [0-9]+ but incomplete: the capture is damaged at byte [0-9]+" -- "$DAQ" replay "$TMP/cut.cdq" --db "$TMP/replay.sqlite"
check replay_not_capture 2 "not a caldaq capture file" -- "$DAQ" replay "$DATA/hand.csv" --db "$TMP/replay.sqlite"
check demo_stored 0 "complete" -- "$DAQ" runs --db "$TMP/demo.sqlite"
check demo_export 0 "^time_s,utc,device,device_name,channel,quantity,status,value,time_ns$" -- "$DAQ" export 1 --db "$TMP/demo.sqlite"
# A full disk stops the export at once, naming why (the rows are written 64 KiB at a time).
check export_full_disk 2 "export: cannot write: No space left on device" -- "$DAQ" export 1 --db "$TMP/demo.sqlite" -o /dev/full
check export_json_full_disk 2 "export: cannot write: No space left on device" -- "$DAQ" export 1 --db "$TMP/demo.sqlite" --format json -o /dev/full
check demo_targets 0 "^0,1,up,-?[0-9.e-]+,1,[0-9.e-]+,20[0-9-]+T[0-9:.]+Z," -- "$DAQ" export 1 --what targets --db "$TMP/demo.sqlite"
# Exports loaded back: the targets feed `daq analyse iso230-2` and give the stored run's E; the
# circle traces feed `daq analyse circle` and give its G; a circle has no targets.
E=$("$DAQ" analyse 1 --db "$TMP/demo.sqlite" --json | "$PY" -c "import json,sys; print(format(json.load(sys.stdin)['axis']['E_bi']['value_um'], '.3f'))")
"$DAQ" export 1 --what targets -o "$TMP/deviations.csv" --db "$TMP/demo.sqlite"
check targets_feed_analyse 0 "^  E +$E um" -- "$DAQ" analyse iso230-2 --input "$TMP/deviations.csv"
G=$("$DAQ" analyse 2 --db "$TMP/demo.sqlite" --json | "$PY" -c "import json,sys; print(format(json.load(sys.stdin)['iso230_4']['G_bi_um'], '.3f'))")
"$DAQ" export 2 --what circle -o "$TMP/ballbar.csv" --db "$TMP/demo.sqlite"
opts=$(sed -nE 's/^# .*daq analyse circle --input FILE (.*)$/\1/p' "$TMP/ballbar.csv")
check circle_feed_analyse 0 "G\(b\) +$G um" -- bash -c "\"$DAQ\" analyse circle --input \"$TMP/ballbar.csv\" $opts"
# The demo's circle has its own capture beside the linear run's, and replays to the same G.
check circle_capture_replays 0 "G\(b\) +$G um" -- "$DAQ" replay "${DEMO_CDQ%.cdq}-circle.cdq" --db "$TMP/circle-replay.sqlite"
check circle_no_targets 2 "run 2 is a circle test and has no captured stops: use --what circle" -- "$DAQ" export 2 --what targets --db "$TMP/demo.sqlite"
check linear_no_circle 2 "run 1 is a linear test, not a circle" -- "$DAQ" export 1 --what circle --db "$TMP/demo.sqlite"
# Readings: one timestamp per sample (the ballbar's lines delivered together are spread by its
# 1 ms period), seconds from the start rising, UTC sub-second, device names, values that read
# back exactly (the shortest round-trip form).
"$DAQ" export 2 -o "$TMP/bar.csv" --db "$TMP/demo.sqlite"
check readings_times 0 "^ok" -- "$PY" -c "
import csv, re, sys
rows = list(csv.DictReader(open('$TMP/bar.csv')))
t = [float(r['time_s']) for r in rows if r['device_name'] == 'ballbar']
assert len(t) > 1000, len(t)
assert all(b > a for a, b in zip(t, t[1:])), 'two samples share a time, or time goes back'
gaps = sorted(b - a for a, b in zip(t, t[1:]))
assert abs(gaps[len(gaps) // 2] - 0.001) < 2e-4, gaps[len(gaps) // 2]
assert all(re.fullmatch(r'20\d\d-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{6}Z', r['utc']) for r in rows[:50])
from decimal import Decimal
digits = lambda x: len(Decimal(x).normalize().as_tuple().digits)
assert all(digits(r['value']) <= digits(repr(float(r['value']))) for r in rows[:2000]), 'not shortest'
print('ok', len(t), 'bar samples')
"
# Stored runs: another standard; recompensation with a corrected expansion coefficient. The
# demo's machine is at 21.5 degC, the last target 500 mm: 1 ppm/K more moves it by
# 500 mm x 1e-6 x 1.5 K = 0.75 um (plus a few nm: the stored environment is now interpolated
# between samples where the live run held the newest).
check analyse_stored 0 "Pa +[0-9.]+ um +position deviation" -- "$DAQ" analyse 1 --db "$TMP/demo.sqlite" -s vdi3441
check recompensate 0 "largest change 0\\.7[4-7][0-9] um" -- "$DAQ" recompensate 1 --db "$TMP/demo.sqlite" --alpha-ppm 12.5
check recompensate_circle 2 "no run 9" -- "$DAQ" recompensate 9 --db "$TMP/demo.sqlite"
check analyse_needs_run 2 "give a stored RUN number" -- "$DAQ" analyse --db "$TMP/demo.sqlite"
# Runs against configured devices: a device that cannot be reached is given up, named, and
# the run is stored as aborted. Part programs from the same configuration.
check run_refused 2 "aborted: .*closed: gave up after 2 attempts" -- "$DAQ" run linear -c "$DATA/run/refused.toml" --db "$TMP/run.sqlite" --give-up-after 2 --check-s 0
# The start-up check (issue 13): the run is refused at once, naming every device that failed.
check run_device_check_laser 2 "daq: error: device check: .*devices.laser \(tcp 127.0.0.1:1\): failed: .*Connection refused" -- "$DAQ" run linear -c "$DATA/run/refused.toml" --db "$TMP/run.sqlite" --check-s 5
check run_device_check_air 2 "daq: error: device check: .*devices.air \(serial /dev/null 4800 7E1\): failed: .*not a serial port" -- "$DAQ" run linear -c "$DATA/run/refused.toml" --db "$TMP/run.sqlite" --check-s 5
check run_stored_aborted 0 "aborted" -- "$DAQ" runs --db "$TMP/run.sqlite"
check gcode_siemens 0 "^G4 F3\\.0000$" -- "$DAQ" gcode linear -c "$DATA/run/refused.toml" -d siemens
check gcode_circle 0 "^G03 X-10\\.0000 Y0\\.0000 I-10\\.0000 J0\\.0000 F1000$" -- "$DAQ" gcode circle -c "$DATA/run/refused.toml"
# The standard set in one program: six tests (three planes at two feeds), G18 for ZX with its
# K/I words; the ZX feed-in ends at Z = -350 + 100 cos(-120) = -400, X = 250 + 100 sin(-120) =
# 163.3975 (caldaq's angles: Z first in ZX, the 220 deg arc symmetric about +Z, 10 deg overshoot).
check gcode_set_tests 0 "^6$" -- bash -c "\"$DAQ\" gcode circle -c \"$DATA/run/ballbar_set.toml\" | grep -c '^(TEST '"
check gcode_set_zx 0 "^G01 X163\\.3975 Z-400\\.0000 F500$" -- "$DAQ" gcode circle -c "$DATA/run/ballbar_set.toml"
check gcode_set_g18 0 "^G18$" -- "$DAQ" gcode circle -c "$DATA/run/ballbar_set.toml"
check gcode_set_heidenhain 0 "CC X\\+250\\.0000 Z-350\\.0000" -- "$DAQ" gcode circle -c "$DATA/run/ballbar_set.toml" -d heidenhain
check gcode_set_flag 0 "^3$" -- bash -c "\"$DAQ\" gcode circle --set -c \"$DATA/run/refused.toml\" | grep -c '^(TEST '"
check gcode_dialect 2 "dialect 'mazak'" -- "$DAQ" gcode linear -c "$DATA/run/refused.toml" -d mazak
check config_error 2 "no_such.toml: cannot open" -- "$DAQ" gcode linear -c "$DATA/run/no_such.toml"
check show_missing 2 "no run 7" -- "$DAQ" show 7 --db "$TMP/demo.sqlite"

# Device discovery: the listing works without hardware, probes name what failed.
check devices_json 0 '"schema": "caldaq.devices.v1"' -- "$DAQ" devices --json
check devices_probe_refused 0 "tcp 127.0.0.1:1: cannot connect" -- "$DAQ" devices --probe 127.0.0.1:1
check devices_probe_not_serial 0 "serial /dev/null 4800 7E1: not a serial port" -- "$DAQ" devices --probe-serial /dev/null
check devices_probe_bad_settings 2 "parity 'X'" -- "$DAQ" devices --probe-serial /dev/null@9600\ 8X1

# Import of a Renishaw dynamic capture (.rtx): a header and three little-endian float64
# samples written byte by byte (1.0, -2.5, 0.125 mm at 1 kHz); then the same cut inside the
# third sample, which is stored as an incomplete run with the two whole samples.
RTX_HEAD='HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13\r\nFile Type: Linear\r\nSample rate: 50000\r\nSample no: 3\r\nActual sample rate: 1000\r\nMachine: VMC-7\r\nSerial No: 99\r\nAxis: Y\r\nData:\r\n'
RTX_DATA='\x00\x00\x00\x00\x00\x00\xf0\x3f\x00\x00\x00\x00\x00\x00\x04\xc0\x00\x00\x00\x00\x00\x00\xc0\x3f'
{ printf "$RTX_HEAD"; printf "$RTX_DATA"; printf '\r\nEOF::\r\n'; } >"$TMP/t.rtx"
{ printf "$RTX_HEAD"; printf "$RTX_DATA" | head -c 20; } >"$TMP/cut.rtx"
check import_rtx 0 "^  range -2\.500000 \.\. 1\.000000 mm" -- "$DAQ" import rtx "$TMP/t.rtx" --db "$TMP/rtx.sqlite"
check import_rtx_export 0 "^0\.001,,0,renishaw-rtx \(CARTO-Dynamic 4\.13\),0,displacement_m,0,-0\.0025,1000000$" -- "$DAQ" export 1 --db "$TMP/rtx.sqlite"
check import_rtx_cut 0 "note: the file ends inside a sample \(4 bytes dropped\)" -- "$DAQ" import rtx "$TMP/cut.rtx" --db "$TMP/rtx.sqlite"
check import_rtx_cut_incomplete 0 "2 +2026.*dynamic +Y +incomplete +2" -- "$DAQ" runs --db "$TMP/rtx.sqlite"
# Samples that stand for 1 nm readings in mm are stored as those decimals in metres, as the
# export prints them: 100.000123 mm is 0.100000123 m (the sample x 1e-3 was 0.10000012300000001),
# -250.000001 mm is -0.250000001 m (x / 1e3 gives -0.25000000099999997), 33.333333 mm is
# 0.033333333 m (both gave 0.03333333300000001). The samples' bytes: Python's struct.pack('<d').
RTX_NM='\x8e\x3e\xe6\x03\x02\x00\x59\x40\xf4\xde\x18\x02\x00\x40\x6f\xc0\xbb\xd6\xde\xa7\xaa\xaa\x40\x40'
{ printf "$RTX_HEAD"; printf "$RTX_NM"; printf '\r\nEOF::\r\n'; } >"$TMP/nm.rtx"
check import_rtx_nm 0 "^  range -250\.000001 \.\. 100\.000123 mm" -- "$DAQ" import rtx "$TMP/nm.rtx" --db "$TMP/rtx_nm.sqlite"
check import_rtx_nm_0 0 "^0,.*,displacement_m,0,0\.100000123,0$" -- "$DAQ" export 1 --db "$TMP/rtx_nm.sqlite"
check import_rtx_nm_1 0 "^0\.001,.*,displacement_m,0,-0\.250000001,1000000$" -- "$DAQ" export 1 --db "$TMP/rtx_nm.sqlite"
check import_rtx_nm_2 0 "^0\.002,.*,displacement_m,0,0\.033333333,2000000$" -- "$DAQ" export 1 --db "$TMP/rtx_nm.sqlite"
check import_not_rtx 2 "data/run/refused.toml: byte 0: not a Renishaw .rtx file" -- "$DAQ" import rtx "$DATA/run/refused.toml" --db "$TMP/rtx.sqlite"

finish
