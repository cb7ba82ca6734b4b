#!/usr/bin/env bash
# Static checks of the udev rules in udev/, and `udevadm verify` where udevadm has it.
# Usage: check_rules.sh UDEV_DIR [CATALOG]   (CATALOG: a file or a folder; by default drivers/,
# whose drivers/<device>/device.cpp files hold the devices' USB ids)
#
# Checked for every *.rules file:
#  - the name sorts before 73-seat-late.rules (TAG+="uaccess" is applied there);
#  - every line is blank, a comment, or a rule: comma-separated KEY OP "VALUE" items with a
#    known udev key (udev(7)), an operator allowed for that key (match keys take == or !=,
#    assignment keys = += -= :=), and {attribute} where the key needs one; no continuation
#    lines;
#  - every ATTRS{idVendor} / ATTRS{idProduct} value is 4 lowercase hex digits (sysfs form);
#  - MODE is 4 octal digits; every GOTO has its LABEL.
# And across the files: uaccess and the plugdev alternative are both there, and every
# VID:PID of the catalog has a hidraw rule. The checker also checks itself on broken files:
# each must be refused, or the checker is broken.
set -u
UDEV_DIR=$1
CATALOG=${2:-$UDEV_DIR/../drivers}
export LC_ALL=C
passes=0
fails=0

match_keys=" ACTION DEVPATH KERNEL KERNELS SUBSYSTEM SUBSYSTEMS DRIVER DRIVERS ATTRS TAGS TEST RESULT CONST PROGRAM "
assign_keys=" OWNER GROUP MODE RUN LABEL GOTO IMPORT OPTIONS SECLABEL "
both_keys=" NAME SYMLINK TAG ENV ATTR SYSCTL "
brace_keys=" ATTR ATTRS ENV TEST IMPORT RUN SYSCTL CONST SECLABEL "
item_re='^[[:space:]]*([A-Z_]+)(\{([^}]*)\})?[[:space:]]*(==|!=|\+=|-=|:=|=)[[:space:]]*"([^"]*)"[[:space:]]*(,(.*))?$'

# check_line FILE LINENO TEXT: prints each problem; the number of problems is its exit status.
check_line() {
  local file=$1 n=$2 rest=$3 problems=0
  if [[ $rest =~ \\[[:space:]]*$ ]]; then
    echo "$file:$n: continuation lines are not allowed"; return 1
  fi
  while [[ -n ${rest//[[:space:]]/} ]]; do
    if ! [[ $rest =~ $item_re ]]; then
      echo "$file:$n: not KEY OP \"VALUE\": ${rest}"; return $((problems + 1))
    fi
    local key=${BASH_REMATCH[1]} attr=${BASH_REMATCH[3]} braces=${BASH_REMATCH[2]}
    local op=${BASH_REMATCH[4]} value=${BASH_REMATCH[5]}
    rest=${BASH_REMATCH[7]}
    if [[ -n ${BASH_REMATCH[6]} && -z ${rest//[[:space:]]/} ]]; then
      echo "$file:$n: trailing comma"; problems=$((problems + 1))
    fi
    if [[ $match_keys != *" $key "* && $assign_keys != *" $key "* && $both_keys != *" $key "* ]]; then
      echo "$file:$n: unknown key $key"; problems=$((problems + 1)); continue
    fi
    if [[ $brace_keys == *" $key "* && -z $braces ]]; then
      echo "$file:$n: $key needs {attribute}"; problems=$((problems + 1))
    elif [[ $brace_keys != *" $key "* && -n $braces ]]; then
      echo "$file:$n: $key takes no {attribute}"; problems=$((problems + 1))
    fi
    if [[ $match_keys == *" $key "* && $op != "==" && $op != "!=" ]]; then
      echo "$file:$n: $key is a match key: $op must be == or !="; problems=$((problems + 1))
    fi
    if [[ $assign_keys == *" $key "* && ($op == "==" || $op == "!=") ]]; then
      echo "$file:$n: $key is an assignment key: $op is a match"; problems=$((problems + 1))
    fi
    if [[ $key == ATTRS && ($attr == idVendor || $attr == idProduct) && ! $value =~ ^[0-9a-f]{4}$ ]]; then
      echo "$file:$n: ATTRS{$attr}==\"$value\" is not 4 lowercase hex digits"
      problems=$((problems + 1))
    fi
    if [[ $key == MODE && ! $value =~ ^0[0-7]{3}$ ]]; then
      echo "$file:$n: MODE=\"$value\" is not 4 octal digits"; problems=$((problems + 1))
    fi
  done
  return $problems
}

# catalog_text CATALOG: the catalog file, or every drivers/<device>/device.cpp below a folder.
catalog_text() {
  if [ -d "$1" ]; then find "$1" -name device.cpp -exec cat {} +; else cat "$1"; fi
}

# check_dir DIR CATALOG: prints each problem; succeeds when there is none.
check_dir() {
  local dir=$1 catalog=$2 problems=0 file name n line
  shopt -s nullglob
  local files=("$dir"/*.rules)
  if [ ${#files[@]} -eq 0 ]; then echo "$dir: no .rules files"; return 1; fi
  for file in "${files[@]}"; do
    name=$(basename "$file")
    if ! [[ $name < "73-seat-late.rules" ]]; then
      echo "$name: sorts after 73-seat-late.rules, so TAG+=\"uaccess\" would not apply"
      problems=$((problems + 1))
    fi
    n=0
    while IFS= read -r line || [ -n "$line" ]; do
      n=$((n + 1))
      [[ $line =~ ^[[:space:]]*(#.*)?$ ]] && continue
      check_line "$name" "$n" "$line" || problems=$((problems + $?))
    done <"$file"
    local label
    for label in $(grep -o 'GOTO="[^"]*"' "$file" | cut -d'"' -f2); do
      grep -q "LABEL=\"$label\"" "$file" || { echo "$name: GOTO=\"$label\" has no LABEL"; problems=$((problems + 1)); }
    done
  done
  grep -hq 'TAG+="uaccess"' "${files[@]}" || { echo "$dir: no TAG+=\"uaccess\" rule"; problems=$((problems + 1)); }
  grep -h 'GROUP="plugdev"' "${files[@]}" | grep -q 'MODE="0660"' ||
    { echo "$dir: no plugdev alternative (MODE=\"0660\", GROUP=\"plugdev\")"; problems=$((problems + 1)); }
  if [ ! -r "$catalog" ]; then echo "$catalog: cannot read the device catalog"; return 1; fi
  local vid pid found=0
  while read -r vid pid; do
    found=$((found + 1))
    vid=${vid,,} pid=${pid,,}
    grep -h 'SUBSYSTEM=="hidraw"' "${files[@]}" | grep "ATTRS{idVendor}==\"$vid\"" | grep -q "ATTRS{idProduct}==\"$pid\"" ||
      { echo "$dir: the catalog's $vid:$pid has no hidraw rule"; problems=$((problems + 1)); }
  done < <(catalog_text "$catalog" | grep -oE '\{0x[0-9a-fA-F]{4}, *0x[0-9a-fA-F]{4}, *"' |
           sed -E 's/.*0x([0-9a-fA-F]{4}), *0x([0-9a-fA-F]{4}).*/\1 \2/')
  if [ "$found" -eq 0 ]; then echo "$catalog: no KnownDevice entries found"; problems=$((problems + 1)); fi
  [ "$problems" -eq 0 ]
}

expect() {  # expect NAME WANT(pass|fail) DIR CATALOG
  local name=$1 want=$2 out rc
  out=$(check_dir "$3" "$4" 2>&1)
  rc=$?
  if { [ "$want" = pass ] && [ $rc -eq 0 ]; } || { [ "$want" = fail ] && [ $rc -ne 0 ]; }; then
    passes=$((passes + 1))
  else
    echo "FAIL $name: expected the checker to $want"; echo "$out" | head -20; fails=$((fails + 1))
  fi
}

# The real rules.
expect rules pass "$UDEV_DIR" "$CATALOG"
check_dir "$UDEV_DIR" "$CATALOG" >/dev/null || check_dir "$UDEV_DIR" "$CATALOG"

# The checker on broken copies: each must be refused.
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
good_catalog=$TMP/catalog.cpp
echo 'KnownDevice{0x0c45, 0x7401, "temper", "x", "hid"},' >"$good_catalog"
good='SUBSYSTEM=="hidraw", ATTRS{idVendor}=="0c45", ATTRS{idProduct}=="7401", TAG+="uaccess"
ENV{ID_CALDAQ}=="1", MODE="0660", GROUP="plugdev"'
case_dir() {  # case_dir NAME FILE_NAME CONTENT -> the directory
  mkdir -p "$TMP/$1" && printf '%s\n' "$3" >"$TMP/$1/$2" && echo "$TMP/$1"
}
expect self_good pass "$(case_dir good 60-x.rules "$good")" "$good_catalog"
expect self_late_name fail "$(case_dir late 80-x.rules "$good")" "$good_catalog"
expect self_short_hex fail "$(case_dir hex 60-x.rules "${good/0c45/c45}")" "$good_catalog"
expect self_upper_hex fail "$(case_dir upper 60-x.rules "${good/7401/740A}")" "$good_catalog"
expect self_unknown_key fail "$(case_dir key 60-x.rules "$good
SUBSYSTEM==\"tty\", FROB=\"1\"")" "$good_catalog"
expect self_match_assign fail "$(case_dir op 60-x.rules "${good/SUBSYSTEM==/SUBSYSTEM=}")" "$good_catalog"
expect self_unquoted fail "$(case_dir quote 60-x.rules "${good/\"hidraw\"/hidraw}")" "$good_catalog"
expect self_bad_mode fail "$(case_dir mode 60-x.rules "${good/0660/660}")" "$good_catalog"
expect self_no_uaccess fail "$(case_dir uaccess 60-x.rules "${good/TAG+=\"uaccess\"/TAG+=\"other\"}")" "$good_catalog"
expect self_goto fail "$(case_dir goto 60-x.rules "$good
ACTION==\"remove\", GOTO=\"nowhere\"")" "$good_catalog"
expect self_continuation fail "$(case_dir cont 60-x.rules "$good
SUBSYSTEM==\"tty\", \\
  TAG+=\"uaccess\"")" "$good_catalog"
missing_catalog=$TMP/catalog2.cpp
printf '%s\n' 'KnownDevice{0x0c45, 0x7401, "temper", "x", "hid"},' \
  'KnownDevice{0x3553, 0xa001, "temper", "y", "hid"},' >"$missing_catalog"
expect self_missing_device fail "$TMP/good" "$missing_catalog"

# udevadm verify (systemd >= 253) where it exists.
if command -v udevadm >/dev/null && udevadm verify --help >/dev/null 2>&1; then
  if udevadm verify --resolve-names=never "$UDEV_DIR"/*.rules; then
    passes=$((passes + 1))
  else
    echo "FAIL udevadm verify"; fails=$((fails + 1))
  fi
else
  echo "note: udevadm verify is not available here (systemd < 253); static checks only"
fi

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
