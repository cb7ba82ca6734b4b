#!/usr/bin/env bash
# The Debian package (issue 34, packaging/README.md): cpack builds it from this build tree;
# dpkg-deb shows its control fields and files; extracted into a scratch root, its daq runs, its
# manual pages render, its bash completion completes, its unit passes systemd-analyze verify,
# and the unit's ExecStart (with the configuration file it reads) serves the page as an
# unprivileged user with no new privileges, then stops on SIGTERM as systemd stops it. Its
# postinst, run against stand-ins for adduser and friends, creates the user, the groups'
# membership and the state directory. (systemd is not running here: no systemctl start.)
# Usage: deb_test.sh BUILD_DIR WITH_PYTHON(0|1: the build has the Python module)
set -u
BUILD=$(realpath "$1")
WITH_PYTHON=${2:-0}
TMP=$(mktemp -d)
chmod 755 "$TMP"
SERVE_PID=
cleanup() { [ -n "$SERVE_PID" ] && kill "$SERVE_PID" 2>/dev/null; rm -rf "$TMP"; }
trap cleanup EXIT
source "$(dirname "$0")/../cli/check.sh"

(cd "$BUILD" && cpack -G DEB -B "$TMP/packages" >"$TMP/cpack.log" 2>&1) ||
  { echo "FAIL: cpack"; cat "$TMP/cpack.log"; exit 1; }
DEB=$(ls "$TMP"/packages/caldaq_*.deb)
check deb_built 0 "caldaq_0\.1\.0_[a-z0-9]+\.deb$" -- echo "$DEB"

INFO=$(dpkg-deb -I "$DEB")
check package_name 0 "^ Package: caldaq$" -- echo "$INFO"
check depends_libs 0 "^ Depends: .*adduser.*" -- echo "$INFO"
check depends_shlibs 0 "^ Depends: .*libc6 .*libsqlite3-0" -- echo "$INFO"
# Issue 35: the central store's client library, found by dpkg-shlibdeps from daq's links.
check depends_libpqxx 0 "^ Depends: .*libpqxx-6\.4" -- echo "$INFO"
check recommends_chromium 0 "^ Recommends: chromium" -- echo "$INFO"
check maintainer_scripts 0 "postinst.*" -- echo "$INFO"
check conffile 0 "^/etc/caldaq/caldaq.conf$" -- bash -c 'dpkg-deb --ctrl-tarfile "$1" | tar -xO ./conffiles' _ "$DEB"
FILES=$(dpkg-deb -c "$DEB")
for f in ./usr/bin/daq ./lib/udev/rules.d/60-caldaq.rules ./lib/udev/rules.d/61-caldaq-plugdev.rules \
  ./lib/systemd/system/caldaq.service ./etc/caldaq/caldaq.conf ./usr/share/man/man1/daq.1.gz \
  ./usr/share/man/man1/daq-serve.1.gz ./usr/share/man/man1/daq-model-map.1.gz \
  ./usr/share/bash-completion/completions/daq ./usr/share/doc/caldaq/README.md; do
  check "has_${f##*/}" 0 " $f$" -- echo "$FILES"
done
check binary_mode 0 "^-rwxr-xr-x root/root .* \./usr/bin/daq$" -- echo "$FILES"
# The Python package, where it is built.
if [ "$WITH_PYTHON" = 1 ]; then
  PYDEB=$(ls "$TMP"/packages/python3-caldaq_*.deb)
  check python_package 0 "/dist-packages/caldaq/_caldaq.*\.so$" -- dpkg-deb -c "$PYDEB"
  check python_depends 0 "^ Depends: .*python3 \(>= 3\.11\)" -- dpkg-deb -I "$PYDEB"
fi

ROOT=$TMP/root
dpkg-deb -x "$DEB" "$ROOT"
check runs 0 "^daq 0\.1\.0$" -- "$ROOT/usr/bin/daq" --version
# Every command has its page, and the pages say what --help says.
PAGES=$(ls "$ROOT/usr/share/man/man1" | wc -l)
check man_pages_count 0 "^ok$" -- bash -c "[ $PAGES -ge 40 ] && echo ok || echo $PAGES"
check man_renders 0 "^ +daq-serve +- +Serve +the +operator's +page" -- env MANWIDTH=100 man -l "$ROOT/usr/share/man/man1/daq-serve.1.gz"
check man_options 0 "^ +--port" -- env MANWIDTH=100 man -l "$ROOT/usr/share/man/man1/daq-serve.1.gz"
# NAME says daq once and the whole first sentence (whatis reads it): it was "daq - daq -
# machine-tool calibration: laser interferometer, environment and ballbar".
check man_name_once 0 "^ +daq +- +machine-tool +calibration: .* +and +ballbar +acquisition, +compensation +and +ISO +230 +analysis\.$" -- env MANWIDTH=300 man -l "$ROOT/usr/share/man/man1/daq.1.gz"
check man_exit_status 0 "EXIT STATUS" -- env MANWIDTH=100 man -l "$ROOT/usr/share/man/man1/daq.1.gz"
check man_no_warnings 0 "^$" -- bash -c "zcat '$ROOT'/usr/share/man/man1/*.1.gz | groff -man -Tutf8 -ww -z 2>&1 | head -5"

complete_words() {  # the completions of the words typed so far (the last one being completed)
  bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _daq; echo "${COMPREPLY[*]}"' _ \
    "$ROOT/usr/share/bash-completion/completions/daq" "$@"
}
check complete_command 0 "^analyse analyze$" -- complete_words daq anal
check complete_option 0 "^--format$" -- complete_words daq report 1 --form
check complete_nested 0 "^map$" -- complete_words daq model ma
check complete_alias_path 0 "^iso230-2$" -- complete_words daq analyze iso
check complete_after_value 0 "^--capture --check-s --config" -- complete_words daq run linear -c sim.toml --c

UNIT=$ROOT/lib/systemd/system/caldaq.service
for key in "User=caldaq" "NoNewPrivileges=yes" "PrivateTmp=yes" "ProtectSystem=strict" \
  "ReadWritePaths=/var/lib/caldaq" "StateDirectory=caldaq" "SupplementaryGroups=plugdev dialout" \
  "EnvironmentFile=/etc/caldaq/caldaq.conf"; do
  check "unit_${key%%=*}" 0 "^${key}$" -- cat "$UNIT"
done
if command -v systemd-analyze >/dev/null; then
  # verify wants the executable where the unit says: the unit with the scratch root's daq (a
  # --root lacks the system's targets). --man=no: the manual page is not installed here.
  sed "s#/usr/bin/daq#$ROOT/usr/bin/daq#" "$UNIT" >"$TMP/caldaq.service"
  check unit_verifies 0 "^verified$" -- bash -c "systemd-analyze verify --man=no '$TMP/caldaq.service' && echo verified"
fi

# The unit's ExecStart, as systemd would run it: the options of the configuration file, the
# paths of the package moved into the scratch root, any free port (a port in use here must not
# fail the test), as an unprivileged user with no new privileges when this runs as root.
STATE=$TMP/state
mkdir -p "$STATE"
EXEC=$(sed -n 's/^ExecStart=//p' "$UNIT")
set -a
source "$ROOT/etc/caldaq/caldaq.conf"
set +a
EXEC=$(eval echo "$EXEC" | sed -e "s#/usr/bin/daq#$ROOT/usr/bin/daq#" -e "s#/var/lib/caldaq#$STATE#g")
RUNNER=(setpriv --no-new-privs)
if [ "$(id -u)" -eq 0 ]; then
  chown nobody:nogroup "$STATE"
  RUNNER+=(--reuid=nobody --regid=nogroup --clear-groups)
fi
(cd "$STATE" && HOME=$STATE exec "${RUNNER[@]}" $EXEC --port 0) >"$TMP/serve.log" 2>&1 &
SERVE_PID=$!
URL=
for _ in $(seq 300); do
  URL=$(sed -nE 's#^daq serve: (http://[0-9.]+:[0-9]+/).*#\1#p' "$TMP/serve.log")
  [ -n "$URL" ] && break
  kill -0 "$SERVE_PID" 2>/dev/null || break
  sleep 0.1
done
check service_serves 0 "^200 .*\"schema\":\"caldaq.status.v1\"" -- python3 -c 'import sys, urllib.request
r = urllib.request.urlopen(sys.argv[1] + "api/status", timeout=10); print(r.status, r.read().decode()[:200])' "$URL"
check service_page 0 "^200$" -- python3 -c 'import sys, urllib.request
print(urllib.request.urlopen(sys.argv[1], timeout=10).status)' "$URL"
check service_capture_dir 0 "^captures$" -- ls "$STATE"
kill -TERM "$SERVE_PID"
STOPPED=no
for _ in $(seq 100); do kill -0 "$SERVE_PID" 2>/dev/null || { STOPPED=yes; break; }; sleep 0.1; done
wait "$SERVE_PID"
RC=$?
SERVE_PID=
check service_stops_on_sigterm 0 "^yes 0$" -- echo "$STOPPED $RC"

# postinst against stand-ins: what it would do on a Debian system.
dpkg-deb -e "$DEB" "$TMP/control"
STUBS=$TMP/stubs
mkdir -p "$STUBS"
for cmd in adduser addgroup install udevadm systemctl; do
  printf '#!/bin/sh\necho "%s $*" >>"%s/calls"\n' "$cmd" "$TMP" >"$STUBS/$cmd"
done
# getent: the groups exist, the user caldaq not yet.
printf '#!/bin/sh\n[ "$1" = group ] && exit 0\nexit 2\n' >"$STUBS/getent"
chmod +x "$STUBS"/*
check postinst_runs 0 "" -- env PATH="$STUBS:$PATH" sh -e "$TMP/control/postinst" configure
CALLS=$(cat "$TMP/calls" 2>/dev/null)
check postinst_user 0 "^adduser --system --group --home /var/lib/caldaq .* caldaq$" -- echo "$CALLS"
check postinst_plugdev 0 "^adduser caldaq plugdev$" -- echo "$CALLS"
check postinst_dialout 0 "^adduser caldaq dialout$" -- echo "$CALLS"
check postinst_state_dir 0 "^install -d -o caldaq -g caldaq -m 0750 /var/lib/caldaq /var/lib/caldaq/captures$" -- echo "$CALLS"
check scripts_parse 0 "^ok$" -- bash -c "for s in postinst prerm postrm; do sh -n '$TMP/control/'\$s || exit 1; done; echo ok"

finish
