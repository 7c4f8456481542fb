#!/bin/sh
# afm-build: the model summary, the pictures (muscle map, influence, jaw,
# pose), the AFM (-o), and its errors (bad usage exits 2, bad input exits 1
# naming the file, nothing written).
test_name=test_build.sh
. "$(dirname "$0")/lib/common.sh"
gen="$bin/afm-headgen"
info="$bin/afm-info"
play="$bin/afm-play"
export_obj="$bin/afm-export"
bin="$bin/afm-build"

"$bin" --help | grep -q -- "--muscle-map" || fail "--help does not list --muscle-map"
"$bin" --list-muscles | grep -q "^orbicularis_oris .*sphincter" || fail "--list-muscles lacks orbicularis_oris"
[ "$("$bin" --list-muscles | grep -c '^[a-z]')" -eq 45 ] || fail "--list-muscles does not list the 25 muscles, 4 lid drivers, 2 lip protrusion drivers, 2 nostril dilators, 2 cheek puffs, the chin raiser, the 2 depressores supercilii, the 2 depressores labii and the nose's 4 tip drivers"

"$bin" --list-faps | grep -q "^ 3 open_jaw  *jaw-open" || fail "--list-faps lacks open_jaw"
[ "$("$bin" --list-faps | grep -c '^ *[0-9]')" -eq 66 ] || fail "--list-faps does not list FAPs 3..68"
[ "$("$bin" --list-faps | grep -c '^v[0-9]')" -eq 14 ] || fail "--list-faps does not list the 14 visemes"
[ "$("$bin" --list-faps | grep -c '^e[0-9]')" -eq 6 ] || fail "--list-faps does not list the 6 expressions"
"$bin" --list-faps | grep -q "^ 8 lower_t_lip_lm .*  second + upper_lip_left +100%, zygomaticus_minor_left -100%  second - " ||
  fail "--list-faps lacks FAP 8's second groups"

"$gen" --vertices 1000 -o "$tmp/h.wrl" >/dev/null 2>&1 || fail "afm-headgen failed"

# An AFM with two FAPs, a viseme and an expression: the report, the
# fidelity report's files, then the AFM as afm-info reads it. FAP 3 has
# in-betweens at 640 and 1024, and the jaw's controls bend there.
"$bin" "$tmp/h.wrl" "$tmp/h.fdp" -q --faps 3,12,v10,e1 --profile raw -o "$tmp/h.afm" --report "$tmp/report" \
  >"$tmp/afm.txt" 2>&1 || fail "an AFM build failed: $(cat "$tmp/afm.txt")"
grep -q "^3  *open_jaw  *320 " "$tmp/afm.txt" || fail "no report line for open_jaw: $(cat "$tmp/afm.txt")"
for r in 640 1024; do
  grep -q "^3  *open_jaw (in-between)  *$r " "$tmp/afm.txt" || fail "no report line for open_jaw at $r"
done
grep -q "^12  *raise_l_cornerlip (negative)  *-150 " "$tmp/afm.txt" || fail "no negative side for raise_l_cornerlip"
grep -q "^v10  *viseme A:  *63 " "$tmp/afm.txt" || fail "no report line for viseme A:"
grep -q "^e1  *joy  *63 " "$tmp/afm.txt" || fail "no report line for joy"
grep -q "^targets: 7 made, 0 not made" "$tmp/afm.txt" || fail "no summary: $(cat "$tmp/afm.txt")"
# Only the muscles these targets pose are calibrated (the brows are not).
grep -q "^zygomaticus_major_left .*[0-9]$" "$tmp/afm.txt" || fail "zygomaticus major left not calibrated"
grep -q "^frontalis_inner_left .* - *-$" "$tmp/afm.txt" || fail "frontalis calibrated for targets that do not use it"
r="$tmp/report"
[ "$(grep -c -x -F -f "$r/report.txt" "$tmp/afm.txt")" -eq "$(wc -l <"$r/report.txt")" ] &&
  [ "$(wc -l <"$r/report.txt")" -eq 9 ] || fail "report.txt is not the printed table: $(cat "$r/report.txt")"
[ "$(grep -c '^[a-z]*,' "$r/report.csv")" -eq 8 ] || fail "report.csv: not a header and 7 rows: $(cat "$r/report.csv")"
grep -q '^viseme,10,"viseme A:",1,63,1,1,' "$r/report.csv" || fail "report.csv: no viseme A: row"
# The off-axis error's parts across the face and in depth make it up
# (squares add), and the summary gives their medians.
grep -q "off-axis median [0-9.]*% worst [0-9.]*% (across the face median [0-9.]*%, in depth [0-9.]*%)" \
  "$tmp/afm.txt" || fail "no off-axis parts in the summary: $(grep '^targets:' "$tmp/afm.txt")"
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
  $1 == "fap" { ++n; o = $c["off_axis"]; f = $c["off_face"]; d = $c["off_depth"]
    if (f < 0 || d < 0 || (f * f + d * d - o * o) ^ 2 > 1e-8 * (o * o + 1e-12) ^ 2) bad = bad " " $2 }
  END { exit (n != 5 || bad != "") }' "$r/report.csv" ||
  fail "report.csv: off_face and off_depth do not make up off_axis: $(cat "$r/report.csv")"
# Helpers steer the raised corner back onto FAP 12's direction, and the
# message names them; with --no-steer the group acts alone.
grep -q '^fap,12,"raise_l_cornerlip",1,.*steered by .*orbicularis_oris' "$r/report.csv" ||
  fail "report.csv: FAP 12 not steered: $(grep '^fap,12' "$r/report.csv")"
"$bin" "$tmp/h.wrl" "$tmp/h.fdp" -q --faps 12 --no-steer -o "$tmp/alone.afm" --report "$tmp/alone" \
  >"$tmp/alone.txt" 2>&1 || fail "a build with --no-steer failed: $(cat "$tmp/alone.txt")"
grep -q '^fap,12,"raise_l_cornerlip",1,' "$tmp/alone/report.csv" && ! grep -q steered "$tmp/alone/report.csv" ||
  fail "--no-steer: $(grep '^fap,12' "$tmp/alone/report.csv")"
# The contact sheet: neutral and 7 targets of 240 x 288 in one row, 4-pixel gaps.
for t in neutral fap03 fap03-640 fap03-1024 fap12 fap12-neg viseme10 expression1; do
  [ -s "$r/targets/$t.png" ] || fail "no picture targets/$t.png"
  grep -q "targets/$t.png" "$r/index.html" || fail "index.html does not show targets/$t.png"
done
size=$(od -An -tu1 -j16 -N8 "$r/sheet.png" | awk '{ printf "%dx%d", $3 * 256 + $4, $7 * 256 + $8 }')
[ "$size" = "1956x296" ] || fail "sheet.png is $size, not 8 tiles of 240x288 in a row (1956x296)"
"$info" --targets "$tmp/h.afm" >"$tmp/info.txt" 2>&1 || fail "afm-info cannot read the AFM"
grep -q "FAP  *3  *open_jaw  *320" "$tmp/info.txt" || fail "afm-info lists no open_jaw target: $(cat "$tmp/info.txt")"
grep -q "^  jaw .*; FAPs 3 3 3 (beyond 320) 3 (beyond 640) 3 (beyond 320) 3 (beyond 640)$" "$tmp/info.txt" ||
  fail "afm-info shows no jaw controls bent at 320 and 640: $(grep '^  jaw' "$tmp/info.txt")"
grep -qi "viseme  *10 " "$tmp/info.txt" || fail "afm-info lists no viseme 10: $(cat "$tmp/info.txt")"

# A skin of 2,000 vertices is simulated on 1,000 of them (the default; 999
# where a mirror pair of collapses ends the decimation, sim_mesh.cpp) and its
# targets carried back to all of them.
"$gen" --vertices 2000 -o "$tmp/h2.wrl" >/dev/null 2>&1 || fail "afm-headgen --vertices 2000 failed"
"$bin" "$tmp/h2.wrl" "$tmp/h2.fdp" -q --faps 12,59 -o "$tmp/h2.afm" >"$tmp/h2.txt" 2>&1 ||
  fail "the 2k build failed: $(tail -n 5 "$tmp/h2.txt")"
grep -Eq "^simulation mesh: (1000|999) of the skin's [0-9]* vertices" "$tmp/h2.txt" ||
  fail "no simulation mesh line: $(head -n 3 "$tmp/h2.txt")"
coarse=$(sed -n "s/^simulation mesh: \([0-9]*\) of the skin's.*/\1/p" "$tmp/h2.txt")
grep -q "^skin: part 'skin', $coarse vertices" "$tmp/h2.txt" || fail "the model is not built on the $coarse vertices"
skin=$(sed -n "s/^simulation mesh: [0-9]* of the skin's \([0-9]*\) vertices.*/\1/p" "$tmp/h2.txt")
"$info" "$tmp/h2.afm" >"$tmp/h2info.txt" 2>&1 || fail "afm-info cannot read the 2k AFM"
# (The AFM splits vertices at texture seams: at least the input's count.)
stored=$(awk '$1 == "skin" && $2 == "skin" { print $3 }' "$tmp/h2info.txt")
[ -n "$stored" ] && [ "$stored" -ge "$skin" ] || fail "the AFM's skin has ${stored:-no} vertices, not the input's $skin"
grep -q "^targets: 4 made" "$tmp/h2.txt" || fail "FAPs 12 and 59, two sides each, not made: $(tail -n 2 "$tmp/h2.txt")"

# FAPs 12 and 59 raise the inner and the outer lip corner, one vertex on this
# head. Sent together at their reference (150), as real streams send them,
# the corner rises by the prescription once (builder/fap/fap_partition.h);
# before, each target moved it all the way and the two twice. Sent alone,
# each raises it by half. afm-play --fdp-motion measures it against the
# MPEG-4 rule.
mask() { awk -v on="$1" 'BEGIN { n = split(on, f, ","); for (i = 1; i <= 68; ++i) { m = 0; for (j = 1; j <= n; ++j) if (f[j] == i) m = 1; printf "%s%d", (i > 1 ? " " : ""), m } print "" }'; }
{ echo "2.1 corner 25 2"; mask 12,59; echo "0 150 150"; mask 12,59; echo "1 150 150"; } >"$tmp/both.fap"
{ echo "2.1 corner 25 2"; mask 12; echo "0 150"; mask 12; echo "1 150"; } >"$tmp/alone.fap"
reached() {  # FDP group $2 of afm-play --fdp-motion's table in file $1: the median share reached
  awk -v g="$2" '$1 == g { for (i = 2; i <= NF; ++i) if ($i ~ /^[0-9]+$/) { print $(i + 1); exit } }' "$1"
}
for s in both alone; do
  "$play" "$tmp/h2.afm" "$tmp/$s.fap" --quiet --fdp-motion >"$tmp/$s.txt" 2>&1 ||
    fail "afm-play --fdp-motion failed: $(cat "$tmp/$s.txt")"
done
for g in 2 8; do
  r=$(reached "$tmp/both.txt" "$g")
  awk -v r="$r" 'BEGIN { exit !(r >= 95 && r <= 105) }' ||
    fail "FAPs 12 + 59 at 150 move the corner (FDP group $g) by ${r:-no} % of the prescription, not 95..105 %: $(cat "$tmp/both.txt")"
done
r=$(reached "$tmp/alone.txt" 2)
awk -v r="$r" 'BEGIN { exit !(r >= 45 && r <= 55) }' ||
  fail "FAP 12 alone moves the corner by ${r:-no} % of its prescription, not half: $(cat "$tmp/alone.txt")"
# The table per FDP: the corner 2.4, named by FAPs 6 and 12, is group 2's
# only point the stream moves, so its row is the group's. (Its FAPs stand
# between the FDP and the samples: the reached share follows the samples.)
r4=$(awk '$1 == "2.4" { for (i = 2; i <= NF; ++i) if ($i ~ /^[0-9]+$/ && $(i + 2) == "%") { print $(i + 1); exit } }' "$tmp/alone.txt")
grep -q '^  2\.4  *6 12  ' "$tmp/alone.txt" && [ "$r4" = "$r" ] ||
  fail "afm-play --fdp-motion: FDP 2.4's row (FAPs 6 12) does not give group 2's ${r:-no} %: $(cat "$tmp/alone.txt")"
expect_error "bad simulation size" 2 "at least 200, or full" - -- "$bin" "$tmp/h2.wrl" "$tmp/h2.fdp" --sim-vertices 50

# Lips that are one surface, as a scan's: the generated head with its closed
# mouth slit welded shut, its FDPs as coordinates. The import cuts the lip
# line, and the lower lip's FAP parts the lips: raise_b_midlip's negative
# side lowers the lower lip's middle (2.3), the upper one's (2.2) stays. The
# opened jaw does not open the mouth (fap/jaw_lips.h): the chin (2.1) drops,
# neither lip's middle does.
"$gen" --vertices 1000 -o "$tmp/hs.obj" >/dev/null 2>&1 || fail "afm-headgen -o hs.obj failed"
awk 'NR == FNR { if ($1 == "o") part = $2; if ($1 == "v") { ++n; if (part == "skin") { k = $2 " " $3 " " $4; if (k in first) to[n] = first[k]; else first[k] = n } }; next }
     $1 == "f" { for (i = 2; i <= NF; ++i) { split($i, c, "/"); if (c[1] in to) sub(/^[0-9]+/, to[c[1]], $i) } }
     { print }' "$tmp/hs.obj" "$tmp/hs.obj" >"$tmp/fused.obj"
awk 'NR == FNR { if ($1 == "o") { part = $2; n = 0 } else if ($1 == "v") { xyz[part, n++] = $2 " " $3 " " $4 }; next }
     /^[0-9]+\.[0-9]+[[:space:]]/ && NF == 3 { print $1, xyz[$2, $3]; next } { print }' \
  "$tmp/hs.obj" "$tmp/hs.fdp" | sed 's/+//g' >"$tmp/fused.fdp"
"$bin" "$tmp/fused.obj" "$tmp/fused.fdp" -q --faps 3,5 -o "$tmp/fused.afm" >"$tmp/fused.txt" 2>&1 ||
  fail "the fused lips' build failed: $(tail -n 5 "$tmp/fused.txt")"
grep -q "the lips are one surface (FDPs 2.2 and 2.3 on vertex [0-9]*): cut along the lip line" "$tmp/fused.txt" ||
  fail "the fused lips are not cut: $(head -n 4 "$tmp/fused.txt")"
"$export_obj" "$tmp/fused.afm" --obj "$tmp/fused_obj" --quiet || fail "afm-export --obj of the fused head failed"
"$info" --fdps "$tmp/fused.afm" | awk '$1 == "2.1" || $1 == "2.2" || $1 == "2.3" { print $1, $3 }' >"$tmp/fused_v.txt"
drops() {  # the drop of 2.1, 2.2 and 2.3 in target $1's OBJ, model units
  awk 'NR == FNR { at[$1] = $2 + 1; next }
    FILENAME ~ /neutral/ && $1 == "v" { y0[++a] = $3 }
    FILENAME !~ /neutral/ && $1 == "v" { y1[++b] = $3 }
    END { printf "%.6f %.6f %.6f", y0[at["2.1"]] - y1[at["2.1"]], y0[at["2.2"]] - y1[at["2.2"]], y0[at["2.3"]] - y1[at["2.3"]] }' \
    "$tmp/fused_v.txt" "$tmp/fused_obj/neutral.obj" "$tmp/fused_obj/$1.obj"
}
d=$(drops raise_b_midlip_neg)
echo "$d" | awk '{ exit !($3 > 0.002 && $2 < 0.1 * $3) }' ||
  fail "raise_b_midlip's negative side does not part the cut lips (drop of 2.1, 2.2, 2.3 in model units: $d)"
d=$(drops open_jaw)
echo "$d" | awk '{ exit !($1 > 0.003 && $2 < 0.1 * $1 && $3 < 0.1 * $1 && $3 > -0.1 * $1) }' ||
  fail "open_jaw opens the mouth (drop of 2.1, 2.2, 2.3 in model units: $d)"

# --stats: the solver's work, the model's and the targets', the same on
# every run at one worker.
for run in 1 2; do
  "$bin" "$tmp/h.wrl" "$tmp/h.fdp" -q --faps 12 --threads 1 --stats -o "$tmp/s$run.afm" >"$tmp/stats$run.txt" 2>&1 ||
    fail "a --stats build failed: $(tail -n 3 "$tmp/stats$run.txt")"
  grep "^solver work" "$tmp/stats$run.txt" >"$tmp/work$run.txt"
done
grep -Eq "^solver work \(the model\): [1-9][0-9]* solves \(0 failed\), [1-9][0-9]* Newton iterations, [0-9]+ CG iterations, [1-9][0-9]* factorisations, [1-9][0-9]* tangents assembled, [1-9][0-9]* energies$" "$tmp/work1.txt" ||
  fail "--stats: no line for the model's work: $(cat "$tmp/stats1.txt")"
grep -Eq "^solver work \(after the model\): [1-9][0-9]* solves" "$tmp/work1.txt" || fail "--stats: no line for the targets' work"
cmp -s "$tmp/work1.txt" "$tmp/work2.txt" || fail "--stats: two runs at one worker differ: $(cat "$tmp/work1.txt" "$tmp/work2.txt")"

# Placement only: the summary and three pictures.
"$bin" "$tmp/h.wrl" "$tmp/h.fdp" --no-calibrate -q --muscle-map "$tmp/map.png" \
  --influence zygomaticus_major_left "$tmp/zyg.png" --jaw-map "$tmp/jaw.png" >"$tmp/out.txt" 2>&1 ||
  fail "a placement run failed: $(cat "$tmp/out.txt")"
grep -q "^skin: part 'skin', [0-9]* vertices" "$tmp/out.txt" || fail "no skin summary"
grep -q "^orbicularis_oris " "$tmp/out.txt" || fail "no muscle table"
grep -q "^jaw: .* skin vertices .*, [1-9][0-9]* below and [1-9][0-9]* beside them follow in part" "$tmp/out.txt" ||
  fail "no jaw summary with its followers"
grep -q "^  lips: [1-9][0-9]* vertex pairs" "$tmp/out.txt" || fail "no lip contact pairs in the summary"
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
expect_error "bad collapse floor" 2 "use a modulus" - -- "$bin" "$h" "$f" --collapse-floor -1
expect_error "pose without calibration" 2 "needs calibrated" "$tmp/bad.png" -- \
  "$bin" "$h" "$f" --no-calibrate --jaw 50 --pose "$tmp/bad.png"
expect_error "AFM without calibration" 2 "needs calibrated" "$tmp/bad.afm" -- \
  "$bin" "$h" "$f" --no-calibrate -o "$tmp/bad.afm"
expect_error "bad FAP list" 2 "not a FAP number" "$tmp/bad.afm" -- "$bin" "$h" "$f" --faps 3,x -o "$tmp/bad.afm"
expect_error "bad viseme" 2 "not a viseme v1..v14" "$tmp/bad.afm" -- "$bin" "$h" "$f" --faps v15 -o "$tmp/bad.afm"
expect_error "report without -o" 2 "--report needs -o" "$tmp/r" -- "$bin" "$h" "$f" --report "$tmp/r"
expect_error "FAP without target" 2 "has no morph target" "$tmp/bad.afm" -- "$bin" "$h" "$f" --faps 48 -o "$tmp/bad.afm"
expect_error "bad profile" 2 "use draco or raw" "$tmp/bad.afm" -- "$bin" "$h" "$f" --profile zip -o "$tmp/bad.afm"

# Bad input: exit 1 naming the file; nothing written.
expect_error "missing mesh" 1 "missing.wrl" "$tmp/bad.png" -- \
  "$bin" "$tmp/missing.wrl" "$f" --no-calibrate --muscle-map "$tmp/bad.png"

# Outputs that cannot be written: refused before the work (no model summary
# on stdout), exit 1 naming the path; nothing written.
before_work() {
  if grep -q "^skin: " "$tmp/out.txt"; then fail "$1: refused only after the model was built"; fi
}
expect_error "AFM into a missing directory" 1 "nodir/h.afm: cannot create" "$tmp/nodir" -- \
  "$bin" "$h" "$f" -o "$tmp/nodir/h.afm"
before_work "AFM into a missing directory"
mkdir -p "$tmp/adir"
expect_error "AFM onto a directory" 1 "adir: cannot create: it is a directory" - -- "$bin" "$h" "$f" -o "$tmp/adir"
before_work "AFM onto a directory"
[ -z "$(ls -A "$tmp/adir")" ] || fail "AFM onto a directory: wrote into it: $(ls -A "$tmp/adir")"
: >"$tmp/afile"
expect_error "report onto a file" 1 "afile: not a directory" "$tmp/bad.afm" -- \
  "$bin" "$h" "$f" -o "$tmp/bad.afm" --report "$tmp/afile"
before_work "report onto a file"
expect_error "report under a file" 1 "afile/r: cannot make the directory" "$tmp/bad.afm" -- \
  "$bin" "$h" "$f" -o "$tmp/bad.afm" --report "$tmp/afile/r"
expect_error "influence picture into a missing directory" 1 "nodir/z.png: cannot create" "$tmp/nodir" -- \
  "$bin" "$h" "$f" --no-calibrate --influence zygomaticus_major_left "$tmp/nodir/z.png"
before_work "influence picture into a missing directory"
finish
