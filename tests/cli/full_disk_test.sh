#!/usr/bin/env bash
# A real full disk (issue 15): `daq demo` with its store, then its capture, on a small tmpfs
# mounted in a private mount namespace. The run must end as aborted with the reason naming
# the file, exit status 2, keep what was written, and the cut capture must replay as damaged
# with its byte offset. Where mounting is not allowed (no root, no user namespaces), the test
# is skipped (status 77) and says why; tests/e2e/faults_test.cpp covers the same paths through
# injected write failures everywhere.
# Usage: full_disk_test.sh DAQ_BINARY
set -u
DAQ=$1
if [ "${2:-}" != --inside ]; then
  if ! unshare -m --propagation private true 2>/dev/null; then
    echo "SKIP: cannot create a mount namespace here (unshare -m needs root or user namespaces)"
    exit 77
  fi
  exec unshare -m --propagation private "$0" "$DAQ" --inside
fi
TMP=$(mktemp -d)
MNT="$TMP/full"
mkdir "$MNT"
cleanup() {
  umount "$MNT" 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT
source "$(dirname "$0")/check.sh"

mount_tmpfs() {  # mount_tmpfs SIZE
  umount "$MNT" 2>/dev/null
  if ! mount -t tmpfs -o "size=$1" tmpfs "$MNT" 2>"$TMP/mount.err"; then
    echo "SKIP: cannot mount a tmpfs here: $(cat "$TMP/mount.err")"
    exit 77
  fi
}

# 1. The store on a full disk: room for the schema and a little more, not for the run.
mount_tmpfs 384k
check store_full_exit 2 "daq: error: run 1 aborted: storage failed: $MNT/d.sqlite: .*(full|No space)" -- \
  "$DAQ" demo --quiet --db "$MNT/d.sqlite" --capture "$TMP/d.cdq"
# What was committed stays readable (read from a copy: opening the store still writes). The
# run is "aborted" if the abort itself could still be written, else "incomplete" (a run left
# running, as after a kill): the reason is then only in daq's message.
cp "$MNT"/d.sqlite* "$TMP/"
check store_full_kept 0 "^ +1 +.* linear +X +(aborted|incomplete) +[1-9][0-9]*" -- "$DAQ" runs --db "$TMP/d.sqlite"

# 2. The capture on a full disk: the run ends, the store says why, the capture replays up to
#    the failure and is reported as damaged there.
mount_tmpfs 64k
check capture_full_exit 2 "daq: error: run 1 aborted: capture failed: $MNT/c.cdq: write failed at byte [0-9]+: No space left on device" -- \
  "$DAQ" demo --quiet --db "$TMP/c.sqlite" --capture "$MNT/c.cdq"
check capture_full_stored 0 "run 1: linear X \(aborted\).* - capture failed: $MNT/c.cdq: write failed" -- \
  "$DAQ" show 1 --db "$TMP/c.sqlite"
check capture_full_replay 2 "c.cdq: the capture is damaged at byte [0-9]+ \(block [0-9]+\): no end block|c.cdq: replay stored as run 1 but incomplete: the capture is damaged at byte [0-9]+" -- \
  "$DAQ" replay "$MNT/c.cdq" --db "$TMP/replay.sqlite"
finish
