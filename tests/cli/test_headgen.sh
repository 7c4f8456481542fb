#!/bin/sh
# afm-headgen: the files it writes (VRML or OBJ by extension, the FDP file
# beside it, a PNG picture), and its errors (bad usage exits 2 with a clear
# message and writes nothing; an unwritable place exits 1).
test_name=test_headgen.sh
. "$(dirname "$0")/lib/common.sh"
bin="$bin/afm-headgen"

# Default format and FDP name: OUT.wrl and OUT.fdp.
"$bin" --vertices 1000 -o "$tmp/a.wrl" >"$tmp/out.txt" 2>&1 || fail "a plain run failed"
head -c 15 "$tmp/a.wrl" 2>/dev/null | grep -q "#VRML V2.0" || fail "a.wrl is not VRML97"
grep -q "^2.2 skin " "$tmp/a.fdp" 2>/dev/null || fail "a.fdp has no 2.2 on the skin"
grep -q "^fapu " "$tmp/a.fdp" 2>/dev/null || fail "a.fdp has no fapu line"
grep -q "FAPU (m): ES0 0.06300" "$tmp/out.txt" || fail "the FAP units are not printed"
[ "$(grep -c '^[0-9]' "$tmp/a.fdp")" -eq 84 ] || fail "a.fdp does not hold 84 FDPs"

# OBJ by extension, FDP file named explicitly, and a picture.
"$bin" --vertices 1200 -o "$tmp/b.OBJ" --fdp "$tmp/b-points.fdp" --render "$tmp/b.png" \
  --size 120x150 --fdp-dots --views 0,40:5,90 >/dev/null 2>&1 || fail "an OBJ run failed"
grep -q "^o skin" "$tmp/b.OBJ" 2>/dev/null || fail "b.OBJ has no skin object"
[ -s "$tmp/b-points.fdp" ] || fail "--fdp was not written"
# PNG signature, and 3 views of 120 px side by side: IHDR width 360, height 150.
sig=$(od -An -tx1 -N8 "$tmp/b.png" 2>/dev/null | tr -d ' \n')
[ "$sig" = "89504e470d0a1a0a" ] || fail "b.png is not a PNG"
ihdr=$(od -An -tx1 -j16 -N8 "$tmp/b.png" 2>/dev/null | tr -d ' \n')
[ "$ihdr" = "0000016800000096" ] || fail "b.png is not 360x150 (IHDR $ihdr)"

# The renderer (libOSMesa, which brings libLLVM) is a shared object loaded
# for the first picture (ports/osmesa/src/osmesa_plugin.h). The loader's own
# trace (LD_DEBUG=files lists every object it maps, dlopen'ed or not) shows
# it mapped for a run with a picture, and not for a run without one.
LD_DEBUG=files "$bin" --vertices 1000 -o "$tmp/p.wrl" --render "$tmp/p.png" --size 40x40 \
  >/dev/null 2>"$tmp/ld.txt" || fail "a run with a picture failed under LD_DEBUG"
grep -q "file=libafm_osmesa.so\|file=.*/libafm_osmesa.so" "$tmp/ld.txt" ||
  fail "LD_DEBUG=files does not show the renderer loaded for a picture"
grep -q "file=libOSMesa" "$tmp/ld.txt" || fail "LD_DEBUG=files does not show libOSMesa for a picture"
LD_DEBUG=files "$bin" --vertices 1000 -o "$tmp/q.wrl" >/dev/null 2>"$tmp/ld.txt" ||
  fail "a run without a picture failed under LD_DEBUG"
grep -q "libOSMesa\|libafm_osmesa\|libLLVM" "$tmp/ld.txt" &&
  fail "a run without a picture loaded $(grep -o 'file=[^ ]*\(OSMesa\|osmesa\|LLVM\)[^ ]*' "$tmp/ld.txt" | sort -u | tr '\n' ' ')"
# A renderer that cannot be loaded: exit 1, its path and why, no picture.
AFM_OSMESA_PLUGIN="$tmp/no-renderer.so" "$bin" --vertices 1000 -o "$tmp/r.wrl" \
  --render "$tmp/r.png" >/dev/null 2>"$tmp/err.txt"
[ $? -eq 1 ] || fail "a missing renderer does not exit 1"
grep -q "cannot load the OSMesa renderer: .*no-renderer.so" "$tmp/err.txt" ||
  fail "a missing renderer: '$(cat "$tmp/err.txt")'"
[ -e "$tmp/r.png" ] && fail "a missing renderer left a picture"
# A shared object that is not the renderer (libpng, which the tool maps anyway).
png_so=$(ldd "$bin" | awk '/libpng/ { print $3; exit }')
[ -n "$png_so" ] || fail "ldd finds no libpng in $bin"
AFM_OSMESA_PLUGIN="$png_so" "$bin" --vertices 1000 -o "$tmp/r.wrl" --render "$tmp/r.png" \
  >/dev/null 2>"$tmp/err.txt"
[ $? -eq 1 ] || fail "a foreign shared object as the renderer does not exit 1"
grep -q "is not the AFM OSMesa renderer (it has no afm_osmesa_plugin_get)" "$tmp/err.txt" ||
  fail "a foreign renderer: '$(cat "$tmp/err.txt")'"
[ -e "$tmp/r.png" ] && fail "a foreign renderer left a picture"

# Bad usage: exit 2, a message that says what is wrong, nothing written.
check_usage() {
  name=$1 pattern=$2
  shift 2
  "$bin" "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
  got=$?
  [ "$got" -eq 2 ] || fail "$name: exit $got, expected 2"
  grep -Eq -- "$pattern" "$tmp/err.txt" || fail "$name: message '$(cat "$tmp/err.txt")'"
  [ -e "$tmp/bad.wrl" ] && fail "$name: wrote bad.wrl"
  [ -e "$tmp/bad.fdp" ] && fail "$name: wrote bad.fdp"
  rm -f "$tmp/bad.wrl" "$tmp/bad.fdp"
}
check_usage "too few vertices" "1000..100000, got '999'" --vertices 999 -o "$tmp/bad.wrl"
check_usage "not a number" "1000..100000, got '10k'" --vertices 10k -o "$tmp/bad.wrl"
check_usage "missing value" "--vertices needs a number" --vertices
check_usage "unknown format" "must end in .wrl, .vrml or .obj" -o "$tmp/bad.ply"
check_usage "picture not PNG" "must end in .png" -o "$tmp/bad.wrl" --render "$tmp/x.jpg"
check_usage "bad size" "WxH" -o "$tmp/bad.wrl" --render "$tmp/x.png" --size 10x
check_usage "bad views" "YAW or YAW:PITCH" -o "$tmp/bad.wrl" --render "$tmp/x.png" --views 0,up

# Unwritable output: exit 1 naming the path, no temporary left behind.
"$bin" --vertices 1000 -o "$tmp/no/such/dir/c.wrl" >/dev/null 2>"$tmp/err.txt"
[ $? -eq 1 ] || fail "unwritable output does not exit 1"
grep -q "no/such/dir/c.wrl" "$tmp/err.txt" || fail "unwritable output: '$(cat "$tmp/err.txt")'"
ls "$tmp"/*.tmp* >/dev/null 2>&1 && fail "left a temporary file"

finish
