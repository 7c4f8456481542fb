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
h="$tmp/h.wrl" f="$tmp/h.fdp"
expect_error "no arguments" 2 "usage: afm-build" - -- "$bin"
expect_error "unknown muscle" 2 "no muscle 'smile'" - -- "$bin" "$h" "$f" --contract smile=50
expect_error "percent out of range" 2 "within -100..100" - -- "$bin" "$h" "$f" --contract orbicularis_oris=150
expect_error "bad contract" 2 "MUSCLE=PERCENT" - -- "$bin" "$h" "$f" --contract orbicularis_oris
expect_error "bad solver" 2 "newton, newton-rest, implicit-euler" - -- "$bin" "$h" "$f" --solver magic
expect_error "bad thread count" 2 "use a count" - -- "$bin" "$h" "$f" --threads 0
expect_error "pose without calibration" 2 "needs calibrated" "$tmp/bad.png" -- \
  "$bin" "$h" "$f" --no-calibrate --jaw 50 --pose "$tmp/bad.png"

# Bad input: exit 1 naming the file; nothing written.
expect_error "missing mesh" 1 "missing.wrl" "$tmp/bad.png" -- \
  "$bin" "$tmp/missing.wrl" "$f" --no-calibrate --muscle-map "$tmp/bad.png"
finish
