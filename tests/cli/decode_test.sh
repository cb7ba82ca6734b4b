#!/usr/bin/env bash
# daq decode end to end: the real recordings of ../shared/realdata (their README's counts), a
# TEMPer dump with its firmware line on stdin, an IDS3010 transcript, and the errors.
# Usage: decode_test.sh DAQ_BINARY REALDATA_DIR
set -u
DAQ=$1
REAL=$2
source "$(dirname "$0")/check.sh"
[ -d "$REAL" ] || { echo "FAIL: $REAL: the real recordings are expected in ../shared/realdata beside the checkout"; exit 1; }

# MTConnect SHDR from an Okuma OSP-P300: 3,989 frames of X1actw, YI1actw, Z1actw, no error.
check okuma 0 '"errors":0,"frames":3989,"gaps":0,"readings":4905,"schema":"caldaq.decode.v1","type":"summary"' -- \
  bash -c "'$DAQ' decode shdr '$REAL/shdr_okuma_osp_p300.txt' --set keys=X1actw,YI1actw,Z1actw --json | tail -1"
check okuma_first 0 '"device_time":"2022-08-08T13:51:34.716714600Z".*"quantity":"machine_position_m"' -- \
  bash -c "'$DAQ' decode shdr '$REAL/shdr_okuma_osp_p300.txt' --set keys=X1actw,YI1actw,Z1actw --json | grep -m1 reading"
# The default keys (Xact, Yact, Zact) on the Okuma recording: no frame, and a hint naming the
# numeric data item keys seen (its X1actw, YI1actw, Z1actw among them) and --set keys=.
check okuma_default_hint 0 "note: no position: none of the keys Xact, Yact, Zact is in the input; data item keys with numeric values seen: .*X1actw.*YI1actw.*; choose yours with --set keys=KEY_X,KEY_Y,KEY_Z" -- \
  "$DAQ" decode shdr "$REAL/shdr_okuma_osp_p300.txt"
check okuma_default_hint_z 0 "numeric values seen: .*Z1actw" -- "$DAQ" decode shdr "$REAL/shdr_okuma_osp_p300.txt"
check okuma_no_hint 1 "^$" -- \
  bash -c "'$DAQ' decode shdr '$REAL/shdr_okuma_osp_p300.txt' --set keys=X1actw,YI1actw,Z1actw | grep 'no position'"
# halsampler: tagged with -t (--set tagged=true), untagged by default like halsampler itself.
# Tagged readings carry halsampler's sample number (0..799 in limit3), in text and in --json;
# untagged ones have none.
check hal_sample_first 0 "^ +0  sample 0 +ch 0  machine_position_m" -- \
  "$DAQ" decode halsampler "$REAL/halsampler_tagged_limit3.txt" --set tagged=true
check hal_sample_last 0 "  sample 799 +ch 0  machine_position_m +0\.16 m +ok" -- \
  "$DAQ" decode halsampler "$REAL/halsampler_tagged_limit3.txt" --set tagged=true
check hal_sample_json 0 '"quantity":"machine_position_m","sample":799,' -- \
  bash -c "'$DAQ' decode halsampler '$REAL/halsampler_tagged_limit3.txt' --set tagged=true --json | grep -v summary | tail -1"
check hal_untagged_no_sample 1 "^$" -- \
  bash -c "'$DAQ' decode halsampler '$REAL/halsampler_untagged_near0.txt' --set column=3 --json | grep -v summary | grep sample"
check hal_tagged 0 "^halsampler: 12097 bytes, 800 frames, 800 readings, 0 errors, 0 gaps$" -- \
  "$DAQ" decode halsampler "$REAL/halsampler_tagged_limit3.txt" --set tagged=true
check hal_untagged 0 "^halsampler: 3050 bytes, 122 frames, 122 readings, 0 errors, 0 gaps$" -- \
  "$DAQ" decode halsampler "$REAL/halsampler_untagged_near0.txt" --set column=3
check hal_bit_pin 0 "ch 0  machine_position_m +0\.001 m +ok" -- \
  "$DAQ" decode halsampler "$REAL/halsampler_untagged_biquad.txt"
check hal_overrun 0 "gap: overrun: samples lost" -- \
  bash -c "printf '1.0 \noverrun\n2.0 \n' | '$DAQ' decode halsampler -"
# TEMPer: the firmware line names the model (TEMPer2_V3.7: gold, two sensors): 0x092E = 23.50
# degC on channel 0 (the stick), 0x079E = 19.50 degC on channel 1 (the probe).
TEMPER=$'firmware: TEMPer2_V3.7\n80 80 09 2e 00 00 00 00\n80 01 07 9e 00 00 00 00\n'
check temper_stick 0 "ch 0  material_temperature_degc +23\.5 degC" -- bash -c "printf '%s' '$TEMPER' | '$DAQ' decode temper -"
check temper_probe 0 "ch 1  material_temperature_degc +19\.5 degC" -- bash -c "printf '%s' '$TEMPER' | '$DAQ' decode temper -"
check temper_unknown 0 "error \(malformed\): TEMPer firmware 'TEMPerGold_V9.9' is not in the detection table" -- \
  bash -c "printf 'firmware: TEMPerGold_V9.9\n80 80 09 2e 00 00 00 00\n' | '$DAQ' decode temper -"
# ugold.c's DS75 catch-all (0c45:7401 only) is not applied: an undocumented TEMPer1F is refused,
# naming the string and --set family, and its data report gives no reading (no phantom sensor).
check temper_1f_unknown 0 "error \(malformed\): TEMPer firmware 'TEMPer1F_V9.9' is not in the detection table.*--set family" -- \
  bash -c "printf 'firmware: TEMPer1F_V9.9\n80 04 09 2e 07 9e 00 00\n' | '$DAQ' decode temper -"
check temper_1f_no_reading 0 "^temper: 0 bytes, 0 frames, 0 readings, 2 errors" -- \
  bash -c "printf 'firmware: TEMPer1F_V9.9\n80 04 09 2e 07 9e 00 00\n' | '$DAQ' decode temper -"
# IDS3010: a transcript (request, answer); 1e11 pm = 0.1 m; a warning number is a note.
IDS='{"jsonrpc":"2.0","method":"com.attocube.sen.displacement.getAxesDisplacement","params":[],"id":7,"api":2}
{"jsonrpc":"2.0","result":[0,100000000000,0,0],"id":7}
{"jsonrpc":"2.0","method":"com.attocube.sen.displacement.getAxesDisplacement","params":[],"id":8,"api":2}
{"jsonrpc":"2.0","result":[2,100000000000,0,0],"id":8}'
check ids_reading 0 "ch 0  displacement_m +0\.1 m +ok" -- bash -c "printf '%s\n' '$IDS' | '$DAQ' decode ids3010 -"
check ids_warning 0 "note: com.attocube.sen.displacement.getAxesDisplacement: warning 2" -- bash -c "printf '%s\n' '$IDS' | '$DAQ' decode ids3010 -"
# Errors name what is wrong.
check unknown_driver 2 "unknown driver 'xl80' \(expected one of: ids3010, ptu300, gauge" -- "$DAQ" decode xl80 -
check unknown_option 2 "driver 'halsampler' has no option 'tag' \(its options: tagged, column, unit\)" -- \
  "$DAQ" decode halsampler - --set tag=true
check bad_value 2 "option 'tagged': 'yes': expected true or false" -- "$DAQ" decode halsampler - --set tagged=yes
check no_file 2 "/nonexistent: cannot open" -- "$DAQ" decode ptu300 /nonexistent
finish
