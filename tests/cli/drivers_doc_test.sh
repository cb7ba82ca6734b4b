#!/usr/bin/env bash
# docs/drivers.md carries the output of `daq devices --options --markdown` between its
# BEGIN/END markers: this fails when the documented options and the drivers' option tables
# disagree (regenerate with scripts/update-driver-docs). Usage: drivers_doc_test.sh DAQ DOC
set -u
DAQ=$1
DOC=$2
want=$(mktemp)
have=$(mktemp)
trap 'rm -f "$want" "$have"' EXIT
"$DAQ" devices --options --markdown >"$want" || { echo "daq devices --options --markdown failed"; exit 1; }
awk '/<!-- BEGIN generated: daq devices --options --markdown -->/{on=1; next}
     /<!-- END generated: daq devices --options --markdown -->/{on=0}
     on' "$DOC" >"$have"
if ! grep -q . "$have"; then echo "$DOC: no generated options between the markers"; exit 1; fi
if ! diff -u "$have" "$want"; then
  echo "$DOC: the options above differ from the drivers' tables: run scripts/update-driver-docs"
  exit 1
fi
echo "docs/drivers.md matches the option tables of $(grep -c '^### ' "$want") drivers"
