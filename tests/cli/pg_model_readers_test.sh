#!/usr/bin/env bash
# Issue 35: the commands that read a machine model take a stored one as `daq model map` does (its
# UUID or number with --db FILE|postgresql://...; with --model-db where --db is where the command
# writes its run): model probe, probe-check, probe-sim, probe-poses, probe-poses-sim, ballbar5x,
# ballbar5x-sim, ballbar5x-program, ballbar5x-run and `daq sim --compensate`. Each command's
# output is the same from the model file, laptop A's store (by UUID and by number) and the
# central server (PostgreSQL started here, tests/cli/pg_server.sh), with the model's name (the
# file's path, or "model UUID") the only difference. A UUID not in the store is named in the
# error; another site's engineer is refused the model (no such model there for them).
# Usage: pg_model_readers_test.sh DAQ_BINARY DATA_DIR (tests/data/model)
set -u
DAQ=$(realpath "$1") # absolute: two commands below run in their own directories
DATA=$(realpath "$2")

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo # DB: laptop A (the demo's runs); the server, empty

MACHINE=$(value "$DB" "SELECT name FROM machines ORDER BY id")
TRUTH=$DATA/trunnion_truth.json
NOM=$DATA/trunnion_nominal.json
VOL=$TMP/volumetric.json
WRONG=0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b
"$DAQ" sim --truth-out "$VOL" --topology YFXZ >/dev/null

# The three models kept in laptop A's store (numbers 1, 2, 3), then sent to the server.
check store_truth 0 "as model 1, " -- "$DAQ" model store "$TRUTH" --machine "$MACHINE" --db "$DB"
check store_nominal 0 "as model 2, " -- "$DAQ" model store "$NOM" --machine "$MACHINE" --db "$DB"
check store_volumetric 0 "as model 3, " -- "$DAQ" model store "$VOL" --machine "$MACHINE" --db "$DB"
UT=$(value "$DB" "SELECT uuid FROM models WHERE id = 1")
UN=$(value "$DB" "SELECT uuid FROM models WHERE id = 2")
UV=$(value "$DB" "SELECT uuid FROM models WHERE id = 3")
check sync_up 0 "; 3 models synced, 3 new$" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --site "Plant A" --quiet
psql_value "CREATE ROLE eng_a LOGIN IN ROLE caldaq_engineer; CREATE ROLE eng_b LOGIN IN ROLE caldaq_engineer;
  INSERT INTO caldaq.site_grants VALUES ('eng_a', 'Plant A'), ('eng_b', 'Plant B')" >/dev/null

# The inputs, made once from the files: probed centres (C at 12 angles, A at 7), poses turning C
# and A together, ballbar readings (C radial, tangential, axial; A radial, axial).
S="150 100 -250"
BALL="150 0 -250"
"$DAQ" model probe-sim "$TRUTH" --axis C --sphere-mm $S --noise-um 1 --seed 1 \
  --angles-deg 0 30 60 90 120 150 180 210 240 270 300 330 >"$TMP/c.csv" 2>/dev/null
"$DAQ" model probe-sim "$TRUTH" --axis A --sphere-mm $S --noise-um 1 --seed 2 \
  --angles-deg -90 -60 -30 0 30 60 90 2>/dev/null | grep -v '^axis\|^#' >"$TMP/a.csv"
cat "$TMP/c.csv" "$TMP/a.csv" >"$TMP/centres.csv"
printf 'c_deg,a_deg\n0,0\n90,0\n180,0\n270,0\n0,30\n90,-30\n180,45\n270,60\n45,-60\n135,90\n' >"$TMP/poses.csv"
"$DAQ" model probe-poses-sim "$TRUTH" --poses "$TMP/poses.csv" --sphere-mm $S --noise-um 1 \
  -o "$TMP/pose-centres.csv" 2>/dev/null
: >"$TMP/readings.csv"
n=0
for t in "C radial" "C tangential" "C axial" "A radial" "A axial"; do
  set -- $t
  angles="0 45 90 135 180 225 270 315"
  [ "$1" = A ] && angles="-90 -45 0 45 90"
  "$DAQ" model ballbar5x-sim "$TRUTH" --control "$NOM" --axis "$1" --setup "$2" --ball-mm $BALL \
    --angles-deg $angles --noise-um 0.5 --seed $((n + 1)) -o "$TMP/one.csv" 2>/dev/null
  if [ $n -eq 0 ]; then cat "$TMP/one.csv"; else grep -v '^#\|^test,' "$TMP/one.csv"; fi >>"$TMP/readings.csv"
  n=$((n + 1))
done
check inputs 0 "^ok 19 10 34$" -- bash -c "echo ok \$(grep -c '^[CA],' '$TMP/centres.csv') \
  \$(grep -c '^[0-9-]' '$TMP/pose-centres.csv') \$(grep -c '^[CA]-' '$TMP/readings.csv')"

# run_as WHERE FLAG ARGS...: daq ARGS with @T@, @N@, @V@ (the trunnion's truth, its nominal
# model, the volumetric truth) the files (WHERE file), or the stored models by UUID in laptop A's
# store (uuid), by number there (number), by UUID on the server (central), with FLAG STORE added.
# Standard output in $TMP/out.WHERE, standard error in $TMP/err.WHERE, the status in $TMP/rc.WHERE.
run_as() {
  local where=$1 flag=$2 a t n v store
  shift 2
  case $where in
  file) t=$TRUTH n=$NOM v=$VOL store= ;;
  uuid) t=$UT n=$UN v=$UV store=$DB ;;
  number) t=1 n=2 v=3 store=$DB ;;
  central) t=$UT n=$UN v=$UV store=$PG_URL ;;
  esac
  local args=()
  for a in "$@"; do
    a=${a//@T@/$t}
    a=${a//@N@/$n}
    args+=("${a//@V@/$v}")
  done
  [ -n "$store" ] && args+=("$flag" "$store")
  if [ -n "${RUN_DIR:-}" ]; then cd "$RUN_DIR" && rm -f run.sqlite* m.toml; fi
  "$DAQ" "${args[@]}" >"$TMP/out.$where" 2>"$TMP/err.$where"
  echo $? >"$TMP/rc.$where"
  # The model's name as printed: the file's path or "model UUID" (terminal_safe, as is).
  sed -i "s#$TRUTH#TRUTH#g; s#model $UT#TRUTH#g; s#$NOM#NOMINAL#g; s#model $UN#NOMINAL#g;
    s#$VOL#VOLUMETRIC#g; s#model $UV#VOLUMETRIC#g" "$TMP/out.$where"
}
# same NAME FLAG PATTERN ARGS...: the file's output (status 0, matching PATTERN) and the same
# bytes from laptop A's store by UUID and by number and from the server. A command that ignored
# FLAG would read "UUID" or "2" as a file and fail.
same() {
  local name=$1 flag=$2 pattern=$3 where
  shift 3
  run_as file "$flag" "$@"
  check "${name}_file" 0 "$pattern" -- bash -c "cat '$TMP/err.file'; cat '$TMP/out.file'; exit \$(cat '$TMP/rc.file')"
  cp "$TMP/out.file" "$TMP/$name.file"
  for where in uuid number central; do
    run_as $where "$flag" "$@"
    check "${name}_$where" 0 "^same$" -- bash -c "cat '$TMP/err.$where'; [ \$(cat '$TMP/rc.$where') = 0 ] &&
      cmp '$TMP/$name.file' '$TMP/out.$where' && echo same"
  done
}

same probe --db "E_X0C +\+2[3-6]\.[0-9]+ um" model probe "$TMP/centres.csv" --model @N@
same probe_json --db '"schema": "caldaq.axis-line-fit.v1"' model probe "$TMP/centres.csv" --model @N@ --json
same probe_check --db "largest deviation [0-9.]+ um" model probe-check "$TMP/centres.csv" --model @N@
same probe_sim --db "^C,90,[0-9.-]+,[0-9.-]+,-?[0-9.]+$" \
  model probe-sim @T@ --control @N@ --axis C --sphere-mm $S --noise-um 1 --angles-deg 0 90 180
same probe_poses --db '"schema": "caldaq.location-fit.v1"' model probe-poses "$TMP/pose-centres.csv" --model @N@ --json
same probe_poses_sim --db "^135,90,[0-9.-]+,[0-9.-]+,-?[0-9.]+$" \
  model probe-poses-sim @T@ --control @N@ --poses "$TMP/poses.csv" --sphere-mm $S --noise-um 1
same ballbar5x --db "E_X0C +\+2[3-7]\.[0-9]+ um" model ballbar5x "$TMP/readings.csv" --model @N@
same ballbar5x_json --db '"model": "NOMINAL"' model ballbar5x "$TMP/readings.csv" --model @N@ --json
same ballbar5x_sim --db "^C-radial,C,radial,150,0,-250,100,90,[0-9.-]+$" \
  model ballbar5x-sim @T@ --control @N@ --axis C --ball-mm $BALL --angles-deg 0 90 180 --noise-um 0.5
same ballbar5x_program --db "^G01 X[0-9.-]+ Y[0-9.-]+ Z[0-9.-]+ C90\.0000 F500$" \
  model ballbar5x-program --model @N@ --axis C --ball-mm $BALL --angles-deg 0 90 180
# The commands that write a run (each into a new store, here in its own directory so that the
# paths they print are the same) read the models from --model-db.
BB5X=(model ballbar5x-run @T@ --control @N@ --ball-mm $BALL --c-angles-deg 0 90 180 270
  --a-angles-deg -90 -45 0 45 90 --noise-um 0.5 --json)
same_run() { # same_run NAME PATTERN ARGS...: same, each run into a new store run.sqlite in TMP/NAME
  local name=$1 pattern=$2
  shift 2
  RUN_DIR=$TMP/$name
  mkdir -p "$RUN_DIR"
  same "$name" --model-db "$pattern" "$@"
  RUN_DIR=
  cd "$TMP"
}
same_run ballbar5x_run '"schema": "caldaq.ballbar5x.v1"' "${BB5X[@]}" --db run.sqlite
same_run sim_compensate '"schema": "caldaq.profile.v1"' sim --measure E_YX --topology YFXZ --acquire \
  --compensate @V@ -o m.toml --db run.sqlite --json
# The correction was applied: the straightness E_YX (about the least-squares line) and the range of
# the means are smaller than the same run's without it (0.44 and 1.44 um; with it 0.14 and 0.60).
"$DAQ" sim --measure E_YX --topology YFXZ --acquire -o "$TMP/plain.toml" --db "$TMP/plain.sqlite" \
  --json >"$TMP/plain.json" 2>/dev/null
check sim_compensated 0 "^smaller [0-9.]+ < [0-9.]+, [0-9.]+ < [0-9.]+$" -- "$PY" -c "
import json
c, p = (json.load(open(f)) for f in ('$TMP/sim_compensate.file', '$TMP/plain.json'))
a, b = (c['straightness_um'], c['range']), (p['straightness_um'], p['range'])
ok = a[0] < b[0] - 0.1 and a[1] < b[1] - 0.3
print('smaller' if ok else 'not smaller', '%.3f < %.3f, %.3f < %.3f' % (a[0], b[0], a[1], b[1]))"

# --model-db left out: the models come from the command's own --db (a copy of laptop A's store).
cp "$DB" "$TMP/visit.sqlite"
check sim_models_from_db 0 "E_YX" -- "$DAQ" sim --measure E_YX --topology YFXZ --acquire \
  --compensate "$UV" -o "$TMP/visit.toml" --db "$TMP/visit.sqlite"
check run_to_central_refused 2 "--db postgresql:.*: this command writes the local store" -- \
  "$DAQ" "${BB5X[@]/@[TN]@/$UT}" --db "$PG_URL"
check demo_to_central_refused 2 "--db postgresql:.*: this command writes the local store" -- \
  bash -c "cd '$TMP' && '$DAQ' demo --quiet --db '$PG_URL'"

# A UUID not in the store: named in the error, for each kind of option.
for where in "$DB" "$PG_URL"; do
  tag=local
  [ "$where" = "$PG_URL" ] && tag=central
  check wrong_model_$tag 2 "no model $WRONG \(daq model list" -- \
    "$DAQ" model probe "$TMP/centres.csv" --model $WRONG --db "$where"
  check wrong_truth_$tag 2 "no model $WRONG" -- \
    "$DAQ" model ballbar5x-sim $WRONG --control "$UN" --axis C --ball-mm $BALL --angles-deg 0 90 --db "$where"
  check wrong_control_$tag 2 "no model $WRONG" -- \
    "$DAQ" model probe-poses-sim "$UT" --control $WRONG --poses "$TMP/poses.csv" --sphere-mm $S --db "$where"
  check wrong_compensate_$tag 2 "no model $WRONG" -- \
    "$DAQ" sim --measure E_YX --acquire --compensate $WRONG -o "$TMP/w.toml" --db "$TMP/w.sqlite" --model-db "$where"
done
check uuid_without_db 2 "$UN: no such file; a model kept in a store is read with --db" -- \
  "$DAQ" model ballbar5x-program --model "$UN" --axis C --ball-mm $BALL --angles-deg 0 90

# Sites: site A's engineer reads the models as the administrator does; site B's is refused them.
run_as file --db model ballbar5x "$TMP/readings.csv" --model @N@ --json
cp "$TMP/out.file" "$TMP/fit.file"
"$DAQ" model ballbar5x "$TMP/readings.csv" --model "$UN" --json --db "$(as eng_a)" 2>&1 |
  sed "s#model $UN#NOMINAL#g" >"$TMP/fit.eng_a"
check eng_a_reads 0 "^same$" -- bash -c "cmp '$TMP/fit.file' '$TMP/fit.eng_a' && echo same"
check eng_b_probe 2 "no model $UN \(daq model list" -- \
  "$DAQ" model probe "$TMP/centres.csv" --model "$UN" --db "$(as eng_b)"
check eng_b_truth 2 "no model $UT" -- \
  "$DAQ" model ballbar5x-sim "$UT" --control "$UN" --axis C --ball-mm $BALL --angles-deg 0 90 --db "$(as eng_b)"
check eng_b_compensate 2 "no model $UV" -- \
  "$DAQ" sim --measure E_YX --acquire --compensate "$UV" -o "$TMP/b.toml" --db "$TMP/b.sqlite" --model-db "$(as eng_b)"

finish
