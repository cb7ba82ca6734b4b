#!/usr/bin/env bash
# Commands that only read (runs, show, export, report, analyse RUN) never create or change a
# database: a missing file is an error naming the path, another program's SQLite file is
# refused, a database of the schema-1 code is read as it is (byte for byte unchanged, its
# crashed run shown as interrupted), and they work on a read-only medium and a full disk.
# Usage: readonly_db_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2

source "$(dirname "$0")/check.sh"
scratch_dir

# A mistyped path: an error naming it, and nothing created.
check missing_runs 2 "$TMP/typo/site.sqlite: no such database" -- "$DAQ" runs --db "$TMP/typo/site.sqlite"
check missing_export 2 "no such database" -- "$DAQ" export 1 --db "$TMP/typo/site.sqlite"
check missing_report 2 "no such database" -- "$DAQ" report 1 --db "$TMP/typo/site.sqlite" -o "$TMP/r.html"
check missing_analyse 2 "no such database" -- "$DAQ" analyse 1 --db "$TMP/typo/site.sqlite"
check missing_nothing_created 0 "^absent$" -- bash -c "[ -e '$TMP/typo' ] && echo present || echo absent"
CALDAQ_DB= XDG_DATA_HOME="$TMP/xdg" check missing_default 2 "xdg/caldaq/site.sqlite: no such database" -- "$DAQ" runs
check missing_default_not_created 0 "^absent$" -- bash -c "[ -e '$TMP/xdg' ] && echo present || echo absent"

# Another program's SQLite file: refused by readers and writers alike, and left as it was.
python3 -c "
import sqlite3; c = sqlite3.connect('$TMP/photos.db')
c.execute('CREATE TABLE albums(id INTEGER, name TEXT)'); c.commit(); c.close()"
cp "$TMP/photos.db" "$TMP/photos.orig"
check foreign_runs 2 "photos.db: not a caldaq database: an SQLite database with other tables \(albums\)" -- "$DAQ" runs --db "$TMP/photos.db"
check foreign_analyse_store 2 "not a caldaq database" -- "$DAQ" analyse 1 --store --db "$TMP/photos.db"
check foreign_unchanged 0 "^same$" -- bash -c "cmp -s '$TMP/photos.db' '$TMP/photos.orig' && echo same"

# A database written by the schema-1 code (tests/data/storage/make_schema1.cpp).
cp "$DATA/storage/schema1.sqlite" "$TMP/old.sqlite"
cp "$DATA/storage/schema1.sqlite" "$TMP/old.orig"
check old_runs 0 "2 .*linear +Y +incomplete" -- "$DAQ" runs --db "$TMP/old.sqlite"
check old_show 0 "opened read-only" -- "$DAQ" show 2 --db "$TMP/old.sqlite"
check old_export 0 "^12019$" -- bash -c "'$DAQ' export 1 --db '$TMP/old.sqlite' | wc -l"
check old_export_first 0 "^0,,0,gauge,0,length_m,0,0\.1,0$" -- bash -c "'$DAQ' export 1 --db '$TMP/old.sqlite' | sed -n 2p"
# The JSON export streams its readings into the document: it must still parse, every row there.
check old_export_json 0 "^12018 \[0, '', 0, 'gauge', 0, 'length_m', 0, 0\.1, 0\] 1$" -- bash -c "'$DAQ' export 1 --format json --db '$TMP/old.sqlite' | python3 -c 'import json, sys; j = json.load(sys.stdin); print(len(j[\"readings\"]), j[\"readings\"][0], len(j[\"targets\"]))'"
check old_unchanged 0 "^same$" -- bash -c "cmp -s '$TMP/old.sqlite' '$TMP/old.orig' && echo same"

# A read-only medium and a full disk: a tmpfs in a private mount namespace (unshare -rm: root
# in a user namespace, so no privileges are needed where user namespaces are allowed).
if unshare -rm true 2>/dev/null; then
  cat >"$TMP/medium.sh" <<EOF
set -u
M="$TMP/mnt"
mkdir -p "\$M"
mount -t tmpfs -o size=2m tmpfs "\$M" || exit 90
cp "$DATA/storage/schema1.sqlite" "\$M/site.sqlite"
mount -o remount,ro "\$M" || exit 91
"$DAQ" runs --db "\$M/site.sqlite" || exit 1
"$DAQ" export 1 --db "\$M/site.sqlite" -o /dev/null || exit 2
"$DAQ" show 1 --json --db "\$M/site.sqlite" | grep -q '"readings": 12018' || exit 3
mount -o remount,rw "\$M"
dd if=/dev/zero of="\$M/fill" bs=64k 2>/dev/null
[ "\$(df --output=avail "\$M" | tail -1)" -eq 0 ] || exit 92
"$DAQ" runs --db "\$M/site.sqlite" || exit 4
"$DAQ" export 1 --db "\$M/site.sqlite" -o /dev/null || exit 5
"$DAQ" report 1 --db "\$M/site.sqlite" -o "$TMP/full-disk-report.html" || exit 6
cmp -s "\$M/site.sqlite" "$DATA/storage/schema1.sqlite" || exit 7
echo medium-ok
EOF
  check readonly_medium_and_full_disk 0 "^medium-ok$" -- unshare -rm bash "$TMP/medium.sh"
else
  echo "SKIP readonly_medium_and_full_disk: unshare -rm is not allowed here (no user namespaces); the in-process test ReadOnly.ACleanDatabaseOpensWithoutItsWalIndexAsOnAReadOnlyMedium covers the fallback"
fi

finish
