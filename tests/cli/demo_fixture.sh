#!/usr/bin/env bash
# The ctest fixture "demo": one `daq demo` (the SIMULATED shop on simulated time, about 2.5 s)
# whose runs and capture several CLI tests read; each copies them before changing anything.
# Usage: demo_fixture.sh DAQ_BINARY DIR
set -eu
rm -rf "$2"
mkdir -p "$2"
cd "$2"
"$1" demo --quiet --db demo.sqlite --capture demo.cdq >demo.log 2>&1 || { cat demo.log; exit 1; }
tail -3 demo.log
