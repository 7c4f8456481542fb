#!/bin/sh
# Command-line behaviour of the tools: --help, bad input (a clear message that
# names the file and line, part or FDP; exit 1; no output file, and an
# existing output left untouched), and the raw <-> draco round trip.
test_name=test_tools.sh
. "$(dirname "$0")/lib/common.sh"

for t in afm-headgen afm-import afm-info afm-pack; do
  "$bin/$t" --help >"$tmp/help.txt" 2>&1 || fail "$t --help exits non-zero"
  grep -q "usage: $t" "$tmp/help.txt" || fail "$t --help prints no usage line"
  "$bin/$t" --no-such-option >/dev/null 2>&1
  [ $? -eq 2 ] || fail "$t: an unknown option does not exit 2"
done

# A small valid head to spoil.
"$bin/afm-headgen" --vertices 1500 -o "$tmp/head.obj" --fdp "$tmp/head.fdp" >/dev/null ||
  fail "afm-headgen failed"
"$bin/afm-import" "$tmp/head.obj" "$tmp/head.fdp" -o "$tmp/head.afm" >/dev/null ||
  fail "afm-import of the generated head failed"

# --- missing file, unknown format
expect_error "missing mesh" 1 "nope\.obj" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/nope.obj" "$tmp/head.fdp" -o "$tmp/a.afm"
printf 'solid\n' >"$tmp/mesh.xyz"
expect_error "unknown mesh format" 1 "mesh\.xyz" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/mesh.xyz" "$tmp/head.fdp" -o "$tmp/a.afm"
expect_error "missing FDP file" 1 "nope\.fdp" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/head.obj" "$tmp/nope.fdp" -o "$tmp/a.afm"

# --- unknown FDP name, FDP on a vertex that does not exist, FDPs missing for FAPU
line=$(grep -n '^2\.10[[:space:]]' "$tmp/head.fdp" | head -1 | cut -d: -f1)
sed "${line}s/^2\.10/2.99/" "$tmp/head.fdp" >"$tmp/bad-name.fdp"
expect_error "unknown FDP name" 1 "bad-name\.fdp:$line:.*2\.99" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/head.obj" "$tmp/bad-name.fdp" -o "$tmp/a.afm"
line=$(grep -n '^9\.3[[:space:]]' "$tmp/head.fdp" | head -1 | cut -d: -f1)
awk -v n="$line" 'NR == n { $3 = 9999999 } { print }' "$tmp/head.fdp" >"$tmp/bad-vertex.fdp"
expect_error "FDP on a missing vertex" 1 "bad-vertex\.fdp:$line:.*9\.3.*9999999" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/head.obj" "$tmp/bad-vertex.fdp" -o "$tmp/a.afm"
grep -v '^3\.6[[:space:]]' "$tmp/head.fdp" >"$tmp/no-36.fdp"
expect_error "FDP missing for FAPU" 1 "ES0.*3\.6" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/head.obj" "$tmp/no-36.fdp" -o "$tmp/a.afm"

# --- FDPs as coordinates (formats/fdp.md, free points): each lands on the
# vertex the part + vertex file names, and a chin off the mesh is refused
# with its line and distance.
awk 'NR == FNR { if ($1 == "o") { part = $2; n = 0 } else if ($1 == "v") { xyz[part, n++] = $2 " " $3 " " $4 }; next }
     /^[0-9]+\.[0-9]+[[:space:]]/ && NF == 3 { print $1, xyz[$2, $3]; next } { print }' \
  "$tmp/head.obj" "$tmp/head.fdp" | sed 's/+//g' >"$tmp/coords.fdp"
grep -q '^2\.1 [-0-9.e]* [-0-9.e]* [-0-9.e]*$' "$tmp/coords.fdp" || fail "coords.fdp: no coordinates: $(head -6 "$tmp/coords.fdp")"
"$bin/afm-import" "$tmp/head.obj" "$tmp/coords.fdp" -o "$tmp/coords.afm" >"$tmp/coords.txt" 2>&1 ||
  fail "afm-import with FDP coordinates failed: $(cat "$tmp/coords.txt")"
grep -q "FDPs: 83 free points attached.*; free, off the mesh: 7\.1$" "$tmp/coords.txt" || fail "no attachment line: $(cat "$tmp/coords.txt")"
"$bin/afm-info" --fdps "$tmp/head.afm" | grep 'vertex [0-9]' >"$tmp/fdps_vertex.txt"
"$bin/afm-info" --fdps "$tmp/coords.afm" | grep 'vertex [0-9]' >"$tmp/fdps_coords.txt"
[ "$(wc -l <"$tmp/fdps_vertex.txt")" -eq 83 ] || fail "the generated head's AFM lists $(wc -l <"$tmp/fdps_vertex.txt") FDPs"
cmp -s "$tmp/fdps_vertex.txt" "$tmp/fdps_coords.txt" ||
  fail "FDP coordinates land elsewhere than their vertices: $(diff "$tmp/fdps_vertex.txt" "$tmp/fdps_coords.txt" | head -5)"
# One object for the whole head (eyes, teeth and tongue inside the skin's
# group): split into its pieces, each found by its FDPs, the FDPs where they were.
grep -v '^o ' "$tmp/head.obj" >"$tmp/merged.obj"
"$bin/afm-import" "$tmp/merged.obj" "$tmp/coords.fdp" -o "$tmp/merged.afm" >"$tmp/merged.txt" 2>&1 ||
  fail "afm-import of a one-object head failed: $(cat "$tmp/merged.txt")"
grep -q "split into its 6 separate pieces" "$tmp/merged.txt" || fail "no split: $(head -4 "$tmp/merged.txt")"
for k in eye_left eye_right teeth_upper teeth_lower tongue; do
  grep -Eq "^  merged_$k +$k " "$tmp/merged.txt" || fail "no $k piece: $(cat "$tmp/merged.txt")"
done
"$bin/afm-info" --fdps "$tmp/merged.afm" | grep 'vertex [0-9]' | sed 's/vertex [0-9]*//' | tr -s ' ' >"$tmp/fdps_merged.txt"
sed 's/vertex [0-9]*//' "$tmp/fdps_vertex.txt" | tr -s ' ' >"$tmp/fdps_places.txt"
cmp -s "$tmp/fdps_places.txt" "$tmp/fdps_merged.txt" ||
  fail "the one-object head's FDPs moved: $(diff "$tmp/fdps_places.txt" "$tmp/fdps_merged.txt" | head -5)"
# The same head as STL (loose triangles, welded at equal positions): the
# touching teeth rows come apart again, each its own piece, and the FDPs
# land where they were.
awk '$1 == "v" { v[++n] = $2 " " $3 " " $4; next }
     $1 == "f" { print "facet normal 0 0 0\n outer loop"
                 for (k = 2; k <= 4; ++k) { split($k, c, "/"); print "  vertex " v[c[1]] }
                 print " endloop\nendfacet" }
     BEGIN { print "solid head" } END { print "endsolid head" }' "$tmp/head.obj" >"$tmp/head.stl"
"$bin/afm-import" "$tmp/head.stl" "$tmp/coords.fdp" -o "$tmp/stl.afm" >"$tmp/stl.txt" 2>&1 ||
  fail "afm-import of the head as STL failed: $(cat "$tmp/stl.txt")"
grep -q "head\.stl: [0-9]* vertices join closed surfaces that touch" "$tmp/stl.txt" || fail "no STL split note: $(head -3 "$tmp/stl.txt")"
grep -q "split into its 6 separate pieces" "$tmp/stl.txt" || fail "STL head: no split into 6 pieces: $(head -4 "$tmp/stl.txt")"
for k in teeth_upper teeth_lower; do
  want=$(grep -E "^  merged_$k +$k " "$tmp/merged.txt" | awk '{ print $2, $3, $4 }')
  got=$(grep -E "^  head_$k +$k " "$tmp/stl.txt" | awk '{ print $2, $3, $4 }')
  [ -n "$want" ] && [ "$got" = "$want" ] || fail "STL head: $k piece '$got', the one-object OBJ's '$want'"
done
"$bin/afm-info" --fdps "$tmp/stl.afm" | grep 'vertex [0-9]' | sed 's/vertex [0-9]*//' | tr -s ' ' >"$tmp/fdps_stl.txt"
cmp -s "$tmp/fdps_places.txt" "$tmp/fdps_stl.txt" ||
  fail "the STL head's FDPs moved: $(diff "$tmp/fdps_places.txt" "$tmp/fdps_stl.txt" | head -5)"
# One object with a material per piece: each piece keeps its own texture.
awk 'NR == 1 { print "mtllib parts.mtl" } /^o / { print "usemtl " $2; next } { print }' "$tmp/head.obj" >"$tmp/merged-mtl.obj"
for m in skin eye_left eye_right teeth_upper teeth_lower tongue; do printf 'newmtl %s\nKd 1 1 1\nmap_Kd %s.png\n' $m $m; done >"$tmp/parts.mtl"
"$bin/afm-import" "$tmp/merged-mtl.obj" "$tmp/coords.fdp" -o "$tmp/merged-mtl.afm" >"$tmp/merged-mtl.txt" 2>&1 ||
  fail "afm-import of a one-object head with materials failed: $(cat "$tmp/merged-mtl.txt")"
for k in :skin _eye_left:eye_left _eye_right:eye_right _teeth_upper:teeth_upper _teeth_lower:teeth_lower _tongue:tongue; do
  grep -Eq "^  merged-mtl${k%%:*} +[a-z_]+ +[0-9]+ +[0-9]+ +${k##*:}\.png$" "$tmp/merged-mtl.txt" ||
    fail "piece merged-mtl${k%%:*} lacks its texture ${k##*:}.png: $(grep -A8 '  part  ' "$tmp/merged-mtl.txt")"
done
# Without FDPs on the teeth and tongue (Song's file names none), the pieces
# in the mouth still move with their bone: above the lip line the skull's,
# below it the jaw's.
grep -v '^9\.\(8\|9\|10\|11\) \|^6\.' "$tmp/coords.fdp" >"$tmp/no-teeth.fdp"
"$bin/afm-import" "$tmp/merged.obj" "$tmp/no-teeth.fdp" -o "$tmp/merged2.afm" --analytic >"$tmp/merged2.txt" 2>&1 ||
  fail "afm-import of a one-object head without teeth FDPs failed: $(cat "$tmp/merged2.txt")"
for k in teeth_upper:teeth_upper teeth_lower:teeth_lower teeth_lower_2:teeth_lower; do
  grep -Eq "^  merged_${k%%:*} +${k##*:} " "$tmp/merged2.txt" || fail "no ${k%%:*} piece without FDPs: $(grep -A8 '  part  ' "$tmp/merged2.txt")"
done
"$bin/afm-info" "$tmp/merged2.afm" | grep -q "^  jaw .* moves merged_teeth_lower merged_teeth_lower_2;" ||
  fail "the jaw does not carry both pieces below the lip line: $("$bin/afm-info" "$tmp/merged2.afm" | grep '^  jaw')"
# (In a mesh whose parts' names say nothing, only the FDPs find the skin.)
sed 's/^o skin$/o surface/' "$tmp/head.obj" >"$tmp/unnamed.obj"
"$bin/afm-import" "$tmp/unnamed.obj" "$tmp/coords.fdp" -o "$tmp/unnamed.afm" >"$tmp/unnamed.txt" 2>&1 ||
  fail "afm-import of a mesh with an unnamed skin and FDP coordinates failed: $(cat "$tmp/unnamed.txt")"
line=$(grep -n '^2\.1 ' "$tmp/coords.fdp" | cut -d: -f1)
awk -v n="$line" 'NR == n { $4 = $4 + 0.05 } { print }' "$tmp/coords.fdp" >"$tmp/chin-off.fdp"
expect_error "free chin off the mesh" 1 "chin-off\.fdp:$line: FDP 2\.1 \(chin\) is a free point 0\.0[0-9]* model units from the nearest vertex" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/unnamed.obj" "$tmp/chin-off.fdp" -o "$tmp/a.afm"

# --- OBJ materials: the skin's map_Kd becomes its texture in the AFM.
awk '/^o skin$/ { print "mtllib head.mtl"; print; print "usemtl face"; next } { print }' "$tmp/head.obj" >"$tmp/textured.obj"
printf 'newmtl face\nKd 0.9 0.7 0.6\nmap_Kd -s 1 1 1 face.png\n' >"$tmp/head.mtl"
"$bin/afm-import" "$tmp/textured.obj" "$tmp/head.fdp" -o "$tmp/textured.afm" >"$tmp/textured.txt" 2>&1 ||
  fail "afm-import of an OBJ with a material failed: $(cat "$tmp/textured.txt")"
"$bin/afm-info" "$tmp/textured.afm" | grep -Eq '^  skin +skin +[0-9]+ +[0-9]+ +face\.png$' ||
  fail "the skin's map_Kd is not its texture: $("$bin/afm-info" "$tmp/textured.afm" | grep -A3 '  part  ')"
rm "$tmp/head.mtl"
"$bin/afm-import" "$tmp/textured.obj" "$tmp/head.fdp" -o "$tmp/textured.afm" >"$tmp/textured.txt" 2>&1 ||
  fail "afm-import of an OBJ without its material library failed: $(cat "$tmp/textured.txt")"
grep -q "^note: .*textured\.obj:[0-9]*: material library 'head\.mtl' not found" "$tmp/textured.txt" ||
  fail "no note of the missing material library: $(head -n 3 "$tmp/textured.txt")"

# --- wrong orientation: named, with the fix
awk '/^v / { print "v", $2, -$4, $3; next } { print }' "$tmp/head.obj" >"$tmp/zup.obj"
expect_error "z-up mesh" 1 "--orient" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/zup.obj" "$tmp/head.fdp" -o "$tmp/a.afm"
"$bin/afm-import" "$tmp/zup.obj" "$tmp/head.fdp" -o "$tmp/zup.afm" --orient auto >/dev/null ||
  fail "--orient auto does not fix a z-up mesh"

# --- non-manifold and degenerate skin: a fourth triangle on a skin edge, and a
# triangle with two equal corners, appended inside the skin group.
skin_first=$(awk '/^o skin/ { s = 1 } s && /^f / { print; exit }' "$tmp/head.obj")
set -- $skin_first
a=${2%%/*} b=${3%%/*} c=${4%%/*}
awk -v tri="f $a $b $c" '/^o skin/ { s = 1 } s && /^f / && !done { print tri; print tri; done = 1 } { print }' \
  "$tmp/head.obj" >"$tmp/nonmanifold.obj"
expect_error "non-manifold skin" 1 "skin.*(edge|manifold)" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/nonmanifold.obj" "$tmp/head.fdp" -o "$tmp/a.afm"
awk -v tri="f $a $a $b" '/^o skin/ { s = 1 } s && /^f / && !done { print tri; done = 1 } { print }' \
  "$tmp/head.obj" >"$tmp/repeated.obj"
expect_error "repeated corner" 1 "repeated\.obj:[0-9]+:.*twice" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/repeated.obj" "$tmp/head.fdp" -o "$tmp/a.afm"
# A zero-area triangle in the skin: a skin vertex and two new ones in line
# with it. (On new vertices alone it would be a piece of its own, which the
# import splits off the skin.)
nv=$(grep -c '^v ' "$tmp/head.obj")
at=$(awk -v a="$a" '/^v / && ++n == a { print $2, $3, $4 }' "$tmp/head.obj")
awk -v n="$nv" -v a="$a" -v at="$at" '/^o skin/ { s = 1 }
  s && /^f / && !done { print "f", a, n + 1, n + 2; done = 1 }
  { print }
  END { split(at, p, " "); print "v", p[1], p[2] + 0.001, p[3]; print "v", p[1], p[2] + 0.002, p[3] }' \
  "$tmp/head.obj" >"$tmp/degenerate.obj"
expect_error "degenerate skin" 1 "skin.*degenerate" "$tmp/a.afm" -- \
  "$bin/afm-import" "$tmp/degenerate.obj" "$tmp/head.fdp" -o "$tmp/a.afm"

# --- a failed run leaves an existing output untouched
cp "$tmp/head.afm" "$tmp/keep.afm"
"$bin/afm-import" "$tmp/head.obj" "$tmp/no-36.fdp" -o "$tmp/keep.afm" >/dev/null 2>&1
cmp -s "$tmp/head.afm" "$tmp/keep.afm" || fail "a failed import changed an existing output"

# --- afm-info and afm-pack on bad files
head -c 100 "$tmp/head.afm" >"$tmp/truncated.afm"
expect_error "truncated AFM" 1 "truncated\.afm" - -- "$bin/afm-info" "$tmp/truncated.afm"
expect_error "not an AFM" 1 "magic" - -- "$bin/afm-info" "$tmp/head.fdp"
expect_error "pack a truncated AFM" 1 "truncated\.afm" "$tmp/p.afm" -- \
  "$bin/afm-pack" --draco "$tmp/truncated.afm" "$tmp/p.afm"
expect_error "pack into a missing directory" 1 "no/such/dir" - -- \
  "$bin/afm-pack" --draco "$tmp/head.afm" "$tmp/no/such/dir/p.afm"

# --- raw -> draco -> raw is exact, and afm-info reads both
"$bin/afm-pack" --draco "$tmp/head.afm" "$tmp/head-draco.afm" >/dev/null || fail "afm-pack --draco"
"$bin/afm-pack" --raw "$tmp/head-draco.afm" "$tmp/head-raw.afm" >/dev/null || fail "afm-pack --raw"
cmp -s "$tmp/head.afm" "$tmp/head-raw.afm" || fail "raw -> draco -> raw changed the file"
"$bin/afm-info" "$tmp/head-draco.afm" >"$tmp/info.txt" || fail "afm-info on a draco file"
grep -q "GEOM  draco" "$tmp/info.txt" || fail "afm-info does not show the draco GEOM chunk"
grep -q "skin .*skin" "$tmp/info.txt" || fail "afm-info does not list the skin part"

finish
