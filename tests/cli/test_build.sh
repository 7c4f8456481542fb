#!/bin/sh
# afm-build: the model summary, the pictures (muscle map, influence, jaw,
# pose), and its errors (bad usage exits 2, bad input exits 1 naming the
# file, nothing written).
test_name=test_build.sh
. "$(dirname "$0")/lib/common.sh"
gen="$bin/afm-headgen"
bin="$bin/afm-build"

"$bin" --help | grep -q -- "--muscle-map" || fail "--help does not list --muscle-map"
"$bin" --list-muscles | grep -q "^orbicularis_oris .*sphincter" || fail "--list-muscles lacks orbicularis_oris"
[ "$("$bin" --list-muscles | grep -c '^[a-z]')" -eq 26 ] || fail "--list-muscles does not list 25 muscles"

"$gen" --vertices 1000 -o "$tmp/h.wrl" >/dev/null 2>&1 || fail "afm-headgen failed"

# Placement only: the summary and three pictures.
"$bin" "$tmp/h.wrl" "$tmp/h.fdp" --no-calibrate -q --muscle-map "$tmp/map.png" \
  --influence zygomaticus_major_left "$tmp/zyg.png" --jaw-map "$tmp/jaw.png" >"$tmp/out.txt" 2>&1 ||
  fail "a placement run failed: $(cat "$tmp/out.txt")"
grep -q "^skin: part 'skin', [0-9]* vertices" "$tmp/out.txt" || fail "no skin summary"
grep -q "^orbicularis_oris " "$tmp/out.txt" || fail "no muscle table"
grep -q "^jaw: .* skin vertices" "$tmp/out.txt" || fail "no jaw summary"
for p in map zyg jaw; do
  sig=$(od -An -tx1 -N8 "$tmp/$p.png" 2>/dev/null | tr -d ' \n')
  [ "$sig" = "89504e470d0a1a0a" ] || fail "$p.png is not a PNG"
done

# Bad usage: exit 2 with a message, nothing written.
check_usage() {
  name=$1 pattern=$2
  shift 2
  "$bin" "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
  got=$?
  [ "$got" -eq 2 ] || fail "$name: exit $got, expected 2"
  grep -Eq -- "$pattern" "$tmp/err.txt" || fail "$name: message '$(cat "$tmp/err.txt")'"
  [ -e "$tmp/bad.png" ] && fail "$name: wrote bad.png"
}
check_usage "no arguments" "usage: afm-build"
check_usage "unknown muscle" "no muscle 'smile'" "$tmp/h.wrl" "$tmp/h.fdp" --contract smile=50
check_usage "percent out of range" "within -100..100" "$tmp/h.wrl" "$tmp/h.fdp" --contract orbicularis_oris=150
check_usage "bad contract" "MUSCLE=PERCENT" "$tmp/h.wrl" "$tmp/h.fdp" --contract orbicularis_oris
check_usage "bad solver" "newton, implicit-euler" "$tmp/h.wrl" "$tmp/h.fdp" --solver magic
check_usage "pose without calibration" "needs calibrated" "$tmp/h.wrl" "$tmp/h.fdp" --no-calibrate --jaw 50 --pose "$tmp/bad.png"

# Bad input: exit 1 naming the file; nothing written.
"$bin" "$tmp/missing.wrl" "$tmp/h.fdp" --no-calibrate --muscle-map "$tmp/bad.png" >"$tmp/out.txt" 2>"$tmp/err.txt"
[ $? -eq 1 ] || fail "a missing mesh does not exit 1"
grep -q "missing.wrl" "$tmp/err.txt" || fail "the error does not name the mesh: $(cat "$tmp/err.txt")"
[ -e "$tmp/bad.png" ] && fail "a failed run wrote bad.png"
finish
