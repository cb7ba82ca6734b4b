#!/usr/bin/env bash
# Issue 35: machine models in both stores (local schema 11, central schema 10; the server here is at 13), against a real
# PostgreSQL server started here (tests/cli/pg_server.sh). Laptop A's store, taken back to schema
# 10, is migrated in place by `daq model build --store`, which keeps the model with the runs it was
# built from (their UUIDs), who and when; `daq model store FILE` keeps a file. Both are synced up
# (sent twice, stored once), brought to laptop B by `daq sync --from` (brought twice, kept once)
# and sent back (nothing new); `daq model map`, `show --json` and `compare` give byte-identical
# output from the file, laptop A's store, laptop B's and the central store. A server of central
# schema 9 with runs is migrated in place by the next sync. Sites: engineer B neither reads site
# A's models (model list, model map --db, SQL) nor writes one for A's machine; B's own model is
# kept under B and A does not see it; nobody updates a stored model.
# Usage: pg_models_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
pg_with_demo  # DB: laptop A (the demo's runs); the server, empty

MACHINE=$(value "$DB" "SELECT name FROM machines ORDER BY id")
LAPTOP_B=$TMP/b.sqlite

# Laptop A's store as an older daq left it (schema 10, no models table): migrated in place.
"$PY" -c "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); c.executescript('DROP TABLE models; PRAGMA user_version = 10;')" "$DB"
RUNS_BEFORE=$(value "$DB" "SELECT group_concat(uuid) FROM (SELECT uuid FROM runs ORDER BY id)")
check schema_10 0 "^10$" -- value "$DB" "PRAGMA user_version"
check list_schema_10 0 "0 models" -- "$DAQ" model list --db "$DB"
check build_store 0 "Kept in .*demo.sqlite as model 1, [0-9a-f-]{36}" -- \
  "$DAQ" model build --machine "$MACHINE" --topology FXYZ --allow-missing --store -o "$TMP/a-model.json" --db "$DB"
check migrated 0 "^11$" -- value "$DB" "PRAGMA user_version"
check runs_kept 0 "^$RUNS_BEFORE$" -- value "$DB" "SELECT group_concat(uuid) FROM (SELECT uuid FROM runs ORDER BY id)"
UUID=$(value "$DB" "SELECT uuid FROM models WHERE id = 1")
# Its provenance: every run it was built from by UUID (those of the store), who stored it.
check provenance 0 "^ok [1-9][0-9]* runs$" -- "$PY" - "$DAQ" "$DB" "${USER:-$(id -un)}" <<'PY'
import json, sqlite3, subprocess, sys
daq, db, user = sys.argv[1:]
listed = json.loads(subprocess.run([daq, "model", "list", "--json", "--db", db], capture_output=True, text=True, check=True).stdout)
m = listed["models"][0]
runs = {u: (i, k) for i, u, k in sqlite3.connect(db).execute("SELECT id, uuid, kind FROM runs")}
p = m["provenance"]
assert p["schema"] == "caldaq.model-provenance.v1" and p["how"] == "daq model build", p
assert m["stored_by"] == user and m["stored_from"], m
assert p["runs"], p
for r in p["runs"]:
    assert r["uuid"] in runs and runs[r["uuid"]] == (r["id"], r["kind"]), r
    assert r["version"] is None and r["errors"], r  # a local store keeps one version of a run
print("ok", len(p["runs"]), "runs")
PY
# The same model file kept again by daq model store: another model, the file named.
cp "$TMP/a-model.json" "$TMP/copy.json"
check store_file 0 "Kept in .* as model 2, [0-9a-f-]{36}" -- "$DAQ" model store "$TMP/copy.json" --db "$DB"
check store_no_machine 2 "no machine 'Nowhere'" -- "$DAQ" model store "$TMP/copy.json" --machine Nowhere --db "$DB"
check list_two 0 "2 models" -- "$DAQ" model list --db "$DB"
check build_store_central 2 "--store keeps the model in the local store" -- \
  "$DAQ" model build --machine "$MACHINE" --allow-missing --store --db "$PG_URL"

# The readers: a file, or with --db a stored model by UUID or number; the same output.
GRID=(--min-mm 0 0 0 --max-mm 400 300 200 --count 3 3 3)
"$DAQ" model map "$TMP/a-model.json" "${GRID[@]}" >"$TMP/map-file.txt" 2>&1
"$DAQ" model map "$TMP/a-model.json" "${GRID[@]}" --json >"$TMP/map-file.json" 2>&1
"$DAQ" model show "$TMP/a-model.json" --json >"$TMP/show-file.json" 2>&1
check map_file_not_empty 0 "largest \|e\| +[0-9.]+ um" -- cat "$TMP/map-file.txt"
# map_same NAME ARGS...: model map/show of the stored model (ARGS: where) as of the file: the text
# and show --json byte-identical, the map's JSON but for "model" (the file's name, or "model UUID").
map_same() {
  local name=$1
  shift
  "$DAQ" model map "$@" "${GRID[@]}" >"$TMP/map.txt" 2>&1
  "$DAQ" model map "$@" "${GRID[@]}" --json >"$TMP/map.json" 2>&1
  "$DAQ" model show "$@" --json >"$TMP/show.json" 2>&1
  check "${name}_map" 0 "^same$" -- bash -c "diff '$TMP/map-file.txt' '$TMP/map.txt' && echo same"
  check "${name}_show" 0 "^same$" -- bash -c "diff '$TMP/show-file.json' '$TMP/show.json' && echo same"
  check "${name}_json" 0 "^same 27 points, model $UUID$" -- "$PY" -c "
import json
a, b = json.load(open('$TMP/map-file.json')), json.load(open('$TMP/map.json'))
a.pop('model')
label = b.pop('model')
print('same' if a == b else 'differ', len(a['points']), 'points,', label)"
}
map_same local_uuid "$UUID" --db "$DB"
map_same local_number 1 --db "$DB"
check no_model 2 "no model 0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b \(daq model list" -- \
  "$DAQ" model map 0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b --db "$DB"
check uuid_without_db 2 "$UUID: no such file; a model kept in a store is read with --db" -- \
  "$DAQ" model map "$UUID"
check bad_ref 2 "a stored model is named by its UUID or its number" -- "$DAQ" model map mill --db "$DB"
"$DAQ" model compare "$TMP/a-model.json" "$TMP/copy.json" 2>&1 | sed "s#$TMP/a-model.json#A#; s#$TMP/copy.json#B#" >"$TMP/compare-file.txt"
"$DAQ" model compare 1 2 --db "$DB" 2>&1 | sed "s#model $UUID#A#; s#model [0-9a-f-]\{36\}#B#" >"$TMP/compare-stored.txt"
check compare_stored 0 "^same [1-9]" -- bash -c "diff '$TMP/compare-file.txt' '$TMP/compare-stored.txt' && echo same \$(wc -l <'$TMP/compare-file.txt')"

# Up: the administrator's sync names the site; sent twice, stored once.
check sync_up 0 "runs synced .*central schema 13.*; 2 models synced, 2 new$" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --site "Plant A" --quiet
check sync_up_again 0 "; 2 models synced, 0 new$" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check central_two 0 "^2 2$" -- psql_value "SELECT count(*) || ' ' || count(DISTINCT uuid) FROM caldaq.models"
map_same central "$UUID" --db "$PG_URL"
check central_list 0 "$UUID" -- "$DAQ" model list --db "$PG_URL" --machine "$MACHINE"

# A server of central schema 9 with these runs (the models table dropped): refused by the readers,
# migrated in place by the next sync, which sends the models again.
pg_undo_central_10
RUNS_CENTRAL=$(psql_value "SELECT count(*) FROM caldaq.runs")
check central_9_refused 2 "central schema version 9 is older than this daq reads \(13\)" -- \
  "$DAQ" model list --db "$PG_URL"
check central_migrated 0 "central schema 13\): 0 new; .*; 2 models synced, 2 new$" -- \
  "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check central_runs_kept 0 "^$RUNS_CENTRAL 2$" -- psql_value "SELECT (SELECT count(*) FROM caldaq.runs) || ' ' || (SELECT count(*) FROM caldaq.models)"

# Down to laptop B (a new store), twice: kept once, as stored on A (provenance, who, when).
check pull 0 "brought from .*; 2 models new$" -- "$DAQ" sync --db "$LAPTOP_B" --from "$PG_URL" --machine "$MACHINE"
check pull_again 0 "; 0 models new$" -- "$DAQ" sync --db "$LAPTOP_B" --from "$PG_URL" --machine "$MACHINE"
check laptop_b_two 0 "^2$" -- value "$LAPTOP_B" "SELECT count(*) FROM models"
check same_records 0 "^same 2$" -- "$PY" -c "
import json, subprocess, sys
def listed(db):
    out = json.loads(subprocess.run([sys.argv[1], 'model', 'list', '--json', '--db', db], capture_output=True, text=True, check=True).stdout)['models']
    for m in out: m.pop('id')
    return sorted(out, key=lambda m: m['uuid'])
a, b, c = listed(sys.argv[2]), listed(sys.argv[3]), listed(sys.argv[4])
print('same' if a == b == c else 'differ %r %r' % (a, b), len(a))" "$DAQ" "$DB" "$LAPTOP_B" "$PG_URL"
check same_text 0 "^same$" -- "$PY" -c "
import sqlite3, sys
q = 'SELECT json, provenance_json, stored_unix_ms FROM models WHERE uuid = ?'
a, b = (sqlite3.connect(f).execute(q, ('$UUID',)).fetchone() for f in ('$DB', '$LAPTOP_B'))
print('same' if a == b and a[0] else 'differ')"
map_same laptop_b "$UUID" --db "$LAPTOP_B"
# Back up from B: nothing new.
check sync_back 0 "; 2 models synced, 0 new$" -- "$DAQ" sync --db "$LAPTOP_B" --to "$PG_URL" --quiet
check central_still_two 0 "^2$" -- psql_value "SELECT count(*) FROM caldaq.models"

# Sites: engineer A (Plant A) and engineer B (Plant B), and B's laptop with a machine of its own.
psql_value "CREATE ROLE eng_a LOGIN IN ROLE caldaq_engineer; CREATE ROLE eng_b LOGIN IN ROLE caldaq_engineer;
  CREATE ROLE rev_b LOGIN IN ROLE caldaq_reviewer;
  INSERT INTO caldaq.site_grants VALUES ('eng_a', 'Plant A'), ('eng_b', 'Plant B'), ('rev_b', 'Plant B')" >/dev/null
SITEB=$TMP/siteb.sqlite
check siteb_run 0 "" -- "$DAQ" replay "$DEMO_CDQ" --db "$SITEB"
"$PY" -c "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); c.execute(\"UPDATE machines SET name = 'Lathe 7'\"); c.commit()" "$SITEB"
check siteb_store 0 "Kept in .* as model 1" -- "$DAQ" model store "$TMP/a-model.json" --machine "Lathe 7" --db "$SITEB"
UUIDB=$(value "$SITEB" "SELECT uuid FROM models")
check b_sends 0 "1 runs synced .*; 1 models synced, 1 new$" -- "$DAQ" sync --db "$SITEB" --to "$(as eng_b)" --quiet
check b_model_site 0 "^Plant B$" -- psql_value "SELECT m.site FROM caldaq.models d JOIN caldaq.machines m ON m.id = d.machine_id WHERE d.uuid = '$UUIDB'"
check a_list 0 "2 models" -- "$DAQ" model list --db "$(as eng_a)"
check a_not_b_list 0 "^ok$" -- bash -c "'$DAQ' model list --db '$(as eng_a)' | grep -q '$UUIDB' && echo seen || echo ok"
check a_not_b_map 2 "no model $UUIDB" -- "$DAQ" model map "$UUIDB" --db "$(as eng_a)" "${GRID[@]}"
check b_not_a_list 0 "1 model$" -- "$DAQ" model list --db "$(as eng_b)"
check b_not_a_map 2 "no model $UUID" -- "$DAQ" model map "$UUID" --db "$(as eng_b)" "${GRID[@]}"
check rev_b_not_a 0 "^0 1$" -- sql rev_b "SELECT (SELECT count(*) FROM caldaq.models WHERE uuid = '$UUID') || ' ' || (SELECT count(*) FROM caldaq.models WHERE uuid = '$UUIDB')"
check b_sql_not_a 0 "^0$" -- sql eng_b "SELECT count(*) FROM caldaq.models WHERE uuid <> '$UUIDB'"
check b_pull_a 2 "no machine '$MACHINE' in the central store" -- \
  "$DAQ" sync --db "$TMP/b-visit.sqlite" --from "$(as eng_b)" --machine "$MACHINE"
MACHINE_A_ID=$(psql_value "SELECT machine_id FROM caldaq.models WHERE uuid = '$UUID'")
check b_insert_for_a 1 "new row violates row-level security policy for table \"models\"" -- \
  sql eng_b "INSERT INTO caldaq.models(uuid, machine_id, name, json, provenance_json, stored_by, stored_from, stored_unix_ms, synced_unix_ms) VALUES (gen_random_uuid(), $MACHINE_A_ID, 'x', '{}', '{}', 'b', 'b', 0, 0)"
check nobody_updates 1 "permission denied for table models" -- \
  sql eng_a "UPDATE caldaq.models SET json = '{}' WHERE uuid = '$UUID'"
check nobody_deletes 1 "permission denied for table models" -- \
  sql eng_a "DELETE FROM caldaq.models WHERE uuid = '$UUID'"
map_same eng_a "$UUID" --db "$(as eng_a)"
check central_three 0 "^3$" -- psql_value "SELECT count(*) FROM caldaq.models"

finish
