#!/bin/sh
# afm-export on the command line. glTF: the Khronos validator must report zero
# errors (on the analytic head's AFM and on an anatomical one); the morph target names, node tree and animation keys (read straight
# from the .glb) must match the AFM (afm-info) and the stream (weights =
# value / reference, eye and head angles = value x 1e-5 rad); three.js's
# GLTFLoader in headless Chromium loads it, plays a frame, and the screenshots
# must show the face and differ from the neutral frame. VRML and OBJ: the
# files and their counts (their contents are checked by tests/export). Then
# errors: exit 2 for bad usage, 1 for bad input, a message naming the file and
# line, nothing left behind.
#
# Needs node, the npm packages `make deps` installs into build/node, and
# chromium: without them the test fails (it never skips them).
test_name=test_export.sh
. "$(dirname "$0")/lib/common.sh"

top=${AFM_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}
NODE_PATH="$top/build/node/node_modules"
export NODE_PATH
js="$top/tests/cli/gltf"
chromium=${AFM_CHROMIUM:-/usr/bin/chromium}
export AFM_CHROMIUM="$chromium"
export_tool="$bin/afm-export"

"$export_tool" --help >"$tmp/help.txt" 2>&1 || fail "--help exits non-zero"
grep -q "usage: afm-export" "$tmp/help.txt" || fail "--help prints no usage line"

# A FAP mask sending FAPs 3 (open_jaw), 23 and 24 (eyes' yaw) and 48 (head
# pitch), then three frames: neutral, moved, neutral.
mask() {
  f=1
  while [ $f -le 68 ]; do
    case $f in 3|23|24|48) printf '1' ;; *) printf '0' ;; esac
    [ $f -lt 68 ] && printf ' '
    f=$((f + 1))
  done
  printf '\n'
}
"$bin/afm-headgen" --vertices 1000 -o "$tmp/head.wrl" --fdp "$tmp/head.fdp" >/dev/null || fail "afm-headgen failed"
"$bin/afm-import" "$tmp/head.wrl" "$tmp/head.fdp" -o "$tmp/head.afm" --analytic >/dev/null || fail "afm-import failed"
{
  printf '2.1 cli 25 3\n'
  mask; printf '0 0 0 0 0\n'
  mask; printf '1 600 20000 20000 10000\n'
  mask; printf '2 0 0 0 0\n'
} >"$tmp/move.fap"
model="$tmp/head.afm"
"$bin/afm-info" --targets "$model" >"$tmp/info.txt" || fail "afm-info failed"
targets=$(sed -n 's/^morph targets: \([0-9]*\) .*/\1/p' "$tmp/info.txt")
vertices=$(sed -n 's/^geometry: \([0-9]*\) vertices.*/\1/p' "$tmp/info.txt")
jaw_reference=$(awk '$1 == "FAP" && $2 == 3 { print $4 }' "$tmp/info.txt")
[ -n "$targets" ] && [ "$targets" -gt 60 ] || fail "afm-info lists '$targets' morph targets"

# --- the three exports in one run
"$export_tool" "$model" --gltf "$tmp/head.glb" --fap "$tmp/move.fap" --vrml "$tmp/head_afm.wrl" \
  --obj "$tmp/obj" >"$tmp/out.txt" 2>"$tmp/err.txt" || fail "export failed: $(cat "$tmp/err.txt")"
sed 's/^/  /' "$tmp/out.txt"
grep -q "$targets of $targets morph targets" "$tmp/out.txt" || fail "not every target in the glTF: $(cat "$tmp/out.txt")"
grep -q "3 animation keys" "$tmp/out.txt" || fail "no 3 animation keys: $(cat "$tmp/out.txt")"
head -1 "$tmp/head_afm.wrl" | grep -q '^#VRML V2.0 utf8' || fail "the VRML file has no VRML97 header"
grep -q 'DEF afm_morph_targets Switch' "$tmp/head_afm.wrl" || fail "no morph target Switch in the VRML file"
[ "$(grep -c '^DEF [a-zA-Z_]* Group' "$tmp/head_afm.wrl")" -eq "$targets" ] || fail "the VRML file does not hold $targets targets"
[ "$(ls "$tmp/obj" | grep -c '\.obj$')" -eq $((targets + 1)) ] || fail "OBJ files: $(ls "$tmp/obj" | grep -c '\.obj$'), expected $((targets + 1))"
[ "$(ls "$tmp/obj" | grep -vc '\.obj$')" -eq 1 ] && [ -s "$tmp/obj/materials.mtl" ] || fail "besides the OBJ files: $(ls "$tmp/obj" | grep -v '\.obj$')"
grep -q '^mtllib materials\.mtl$' "$tmp/obj/open_jaw.obj" || fail "open_jaw.obj names no material library"
[ "$(grep -c '^v ' "$tmp/obj/neutral.obj")" -eq "$vertices" ] || fail "neutral.obj does not have $vertices vertices"
[ "$(grep -c '^v ' "$tmp/obj/open_jaw.obj")" -eq "$vertices" ] || fail "open_jaw.obj does not have $vertices vertices"
cmp -s "$tmp/obj/neutral.obj" "$tmp/obj/open_jaw.obj" && fail "open_jaw.obj is the neutral face"

# The same model in the draco profile exports to the same glTF bytes.
"$bin/afm-pack" --draco "$model" "$tmp/draco.afm" >/dev/null || fail "afm-pack failed"
"$export_tool" "$tmp/draco.afm" --gltf "$tmp/draco.glb" --fap "$tmp/move.fap" --quiet || fail "draco export failed"
cmp -s "$tmp/head.glb" "$tmp/draco.glb" || fail "the draco-profile AFM exports to another glTF"

# --- node, its packages, chromium: required
if ! command -v node >/dev/null 2>&1; then
  fail "node is missing: run make deps (tools/deps.sh)"
  finish
fi
for p in gltf-validator three playwright-core; do
  [ -d "$NODE_PATH/$p" ] || fail "npm package $p is missing from $NODE_PATH: run make deps"
done
[ -x "$chromium" ] || fail "$chromium is missing: run make deps"
[ "$failures" -eq 0 ] || finish

# --- Khronos validator: zero errors
node "$js/validate.cjs" "$tmp/head.glb" >"$tmp/validate.txt" 2>&1 || fail "validator: $(cat "$tmp/validate.txt")"
sed 's/^/  /' "$tmp/validate.txt"
grep -q ": 0 errors," "$tmp/validate.txt" || fail "the validator reports errors"
# An anatomical AFM (afm-build): viseme A moves every vertex of the lower
# teeth with the jaw, the tongue's and a pupil's targets their own parts.
# A sparse morph accessor that lists every vertex has no implicit zeros, and
# its bounds once counted them (54 errors on the demo head's AFM).
"$bin/afm-build" "$tmp/head.wrl" "$tmp/head.fdp" -q -o "$tmp/anat.afm" --faps v10,43,29 >"$tmp/anat.txt" 2>&1 ||
  fail "afm-build failed: $(tail -n 3 "$tmp/anat.txt")"
"$export_tool" "$tmp/anat.afm" --gltf "$tmp/anat.glb" --quiet || fail "the anatomical AFM's export failed"
node "$js/validate.cjs" "$tmp/anat.glb" >"$tmp/validate_anat.txt" 2>&1 || fail "validator: $(cat "$tmp/validate_anat.txt")"
grep -q ": 0 errors," "$tmp/validate_anat.txt" ||
  fail "the validator reports errors on an anatomical AFM: $(head -n 3 "$tmp/validate_anat.txt")"
node "$js/validate.cjs" "$tmp/obj/neutral.obj" >"$tmp/validate_bad.txt" 2>&1 &&
  fail "the validator accepts an OBJ file as glTF"
# A combination target (AFM 1.4): FAP 5's lower lip past its reach, gated by
# the jaw (FAP 3 at 1024). At key 1 the lip asks -1024 with the jaw at 512:
# the hold's weight is 1, the combination's min(1, 512 / 1024) = 0.5.
"$bin/afm-build" "$tmp/head.wrl" "$tmp/head.fdp" -q -o "$tmp/lip.afm" --faps 3,5 >"$tmp/lip.txt" 2>&1 ||
  fail "afm-build --faps 3,5 failed: $(tail -n 3 "$tmp/lip.txt")"
{
  printf '2.1 lip 25 2\n'
  for key in '0 0 0' '1 512 -1024'; do
    awk 'BEGIN { for (f = 1; f <= 68; ++f) printf "%s%d", (f > 1 ? " " : ""), (f == 3 || f == 5); print "" }'
    echo "$key"
  done
} >"$tmp/lip.fap"
"$export_tool" "$tmp/lip.afm" --gltf "$tmp/lip.glb" --fap "$tmp/lip.fap" --vrml "$tmp/lip_afm.wrl" --quiet ||
  fail "the combination's export failed"
node "$js/validate.cjs" "$tmp/lip.glb" >"$tmp/validate_lip.txt" 2>&1 || fail "validator: $(cat "$tmp/validate_lip.txt")"
grep -q ": 0 errors," "$tmp/validate_lip.txt" ||
  fail "the validator reports errors with a combination: $(head -n 3 "$tmp/validate_lip.txt")"
node "$js/inspect.cjs" "$tmp/lip.glb" >"$tmp/inspect_lip.txt" 2>&1 || fail "inspect: $(cat "$tmp/inspect_lip.txt")"
awk '$1 == "weight" && $4 == 1 { w[$3] = $5 }
  END {
    c = w["raise_b_midlip_neg_1024_with_open_jaw"]; h = w["raise_b_midlip_neg_1024"]
    if (c == "" || c < 0.499 || c > 0.501 || h == "" || h < 0.999 || h > 1.001) {
      printf "key 1: the combination weighs %s (expected 0.5), the hold %s (expected 1)\n", c, h; exit 1 }
  }' "$tmp/inspect_lip.txt" >"$tmp/weights_lip.txt" || fail "$(cat "$tmp/weights_lip.txt")"
grep -q '"target raise_b_midlip_neg_1024_with_open_jaw combination 5 reference -1024 gate 3 gate_reference 1024 parts' \
  "$tmp/lip_afm.wrl" || fail "the VRML file's WorldInfo does not give the combination's gate"

# --- what the file holds
node "$js/inspect.cjs" "$tmp/head.glb" >"$tmp/inspect.txt" 2>&1 || fail "inspect: $(cat "$tmp/inspect.txt")"
[ "$(awk '$1 == "target" { print $3 }' "$tmp/inspect.txt" | sort -u | wc -l)" -eq "$targets" ] ||
  fail "the glTF names $(awk '$1 == "target" { print $3 }' "$tmp/inspect.txt" | sort -u | wc -l) targets, the AFM has $targets"
awk '$1 == "FAP" || $1 == "viseme" || $1 == "expression" { print $3 }' "$tmp/info.txt" | head -3 >"$tmp/some.txt"
grep -q '^target skin open_jaw$' "$tmp/inspect.txt" || fail "no open_jaw target on the skin"
grep -q '^target skin viseme_A$' "$tmp/inspect.txt" || fail "no viseme_A target on the skin"
grep -q '^target skin expression_joy$' "$tmp/inspect.txt" || fail "no expression_joy target on the skin"
for edge in "head_pivot_offset head_pivot" "jaw_pivot head_pivot_offset" "teeth_lower jaw_pivot_offset" \
  "eye_left eye_left_pivot_offset" "eye_right eye_right_pivot_offset" "skin head_pivot_offset"; do
  grep -q "^node $edge\$" "$tmp/inspect.txt" || fail "no node '${edge% *}' under '${edge#* }'"
done
grep -q '^keys 3$' "$tmp/inspect.txt" || fail "not 3 animation keys"
# Weight at key 1: 600 / reference; nothing else moves the skin there.
awk -v ref="$jaw_reference" '
  $1 == "weight" && $3 == "open_jaw" && $4 == 1 { w = $5; n++ }
  $1 == "weight" && $4 != 1 { other++ }
  END {
    want = 600 / ref
    if (n != 1 || w - want > 1e-3 || want - w > 1e-3) { printf "open_jaw weight %s, expected %.4f\n", w, want; exit 1 }
    if (other) { printf "%d weights outside key 1\n", other; exit 1 }
  }' "$tmp/inspect.txt" >"$tmp/weights.txt" || fail "$(cat "$tmp/weights.txt")"
# Angles at key 1: 2 acos(w) = value x 1e-5 rad (eyes 20000, head 10000).
awk '
  function acos(x) { return atan2(sqrt(1 - x * x), x) }
  $1 == "rotation" && $3 == 1 { a[$2] = 2 * acos($7) }
  END {
    bad = 0
    if (a["eye_left_pivot"] < 0.199 || a["eye_left_pivot"] > 0.201) { print "eye_left angle " a["eye_left_pivot"]; bad = 1 }
    if (a["eye_right_pivot"] < 0.199 || a["eye_right_pivot"] > 0.201) { print "eye_right angle " a["eye_right_pivot"]; bad = 1 }
    if (a["head_pivot"] < 0.099 || a["head_pivot"] > 0.101) { print "head angle " a["head_pivot"]; bad = 1 }
    if (a["jaw_pivot"] < 0.01) { print "the jaw does not turn: " a["jaw_pivot"]; bad = 1 }
    exit bad
  }' "$tmp/inspect.txt" >"$tmp/angles.txt" || fail "$(cat "$tmp/angles.txt")"

# --- three.js in headless Chromium: the neutral frame and the moved one (key 1, 40 ms)
mkdir -p "$tmp/shots"
node "$js/view.cjs" "$tmp/head.glb" "$tmp/shots" 0.04 >"$tmp/view.txt" 2>&1 || fail "view: $(cat "$tmp/view.txt")"
sed 's/^/  /' "$tmp/view.txt"
grep -q "^loaded: 1 animation(s), $targets morph targets" "$tmp/view.txt" || fail "three.js did not load the animation and every target"
[ -s "$tmp/shots/neutral.png" ] && [ -s "$tmp/shots/played.png" ] || fail "no screenshots"
awk '
  $1 == "neutral:" && $2 < 5 { print "the neutral frame is " $2 " % face: background only?"; bad = 1 }
  $1 == "played:" && $2 < 5 { print "the played frame is " $2 " % face: background only?"; bad = 1 }
  $1 == "changed:" { seen = 1; if ($2 < 1) { print "the played frame differs from the neutral one in " $2 " % of pixels"; bad = 1 } }
  END { exit bad || !seen }' "$tmp/view.txt" >"$tmp/judge.txt" || fail "screenshots: $(cat "$tmp/judge.txt")"

# --- a textured skin (the neutral screenshot as its image): embedded, still valid
sed '0,/appearance Appearance {/s//appearance Appearance { texture ImageTexture { url "skin.png" }/' \
  "$tmp/head.wrl" >"$tmp/tex.wrl"
cp "$tmp/shots/neutral.png" "$tmp/skin.png"
"$bin/afm-import" "$tmp/tex.wrl" "$tmp/head.fdp" -o "$tmp/tex.afm" --analytic >/dev/null || fail "afm-import of the textured head failed"
"$export_tool" "$tmp/tex.afm" --gltf "$tmp/tex.glb" >"$tmp/out.txt" 2>&1 || fail "textured export failed: $(cat "$tmp/out.txt")"
grep -q " 1 textures" "$tmp/out.txt" || fail "the texture is not embedded: $(cat "$tmp/out.txt")"
node "$js/validate.cjs" "$tmp/tex.glb" >"$tmp/validate_tex.txt" 2>&1 || fail "tex.glb: $(cat "$tmp/validate_tex.txt")"

# --- a real stream, when ../shared/data is there
joy="${AFM_SHARED_DIR:-$top/../shared}/data/fap/xface/joy.fap"
note=""
if [ -f "$joy" ]; then
  "$export_tool" "$model" --gltf "$tmp/joy.glb" --fap "$joy" --quiet || fail "export with joy.fap failed"
  node "$js/validate.cjs" "$tmp/joy.glb" >"$tmp/validate_joy.txt" 2>&1 || fail "joy.glb: $(cat "$tmp/validate_joy.txt")"
else
  note="../shared/data absent: the joy.fap export skipped"
  echo "note: $note"
fi

# --- errors
e="$tmp/err"
mkdir -p "$e"
expect_error "no output" 2 "no output" - -- "$export_tool" "$model"
expect_error "no model" 2 "no model" - -- "$export_tool" --gltf "$e/a.glb"
expect_error "--fap without --gltf" 2 "needs --gltf" - -- "$export_tool" "$model" --vrml "$e/a.wrl" --fap "$tmp/move.fap"
expect_error "unknown option" 2 "unknown option --bogus" - -- "$export_tool" "$model" --bogus
expect_error "missing value" 2 "--obj needs a directory" - -- "$export_tool" "$model" --obj
expect_error "missing model" 1 "nothing.afm: cannot open" "$e/a.glb" -- "$export_tool" "$tmp/nothing.afm" --gltf "$e/a.glb"
printf 'not an AFM file at all, but long enough to be read' >"$e/bad.afm"
expect_error "not an AFM" 1 "bad.afm: " "$e/a.glb" -- "$export_tool" "$e/bad.afm" --gltf "$e/a.glb"
{ printf '2.1 cli 25 2\n'; mask; printf '0 0 0 0 0\n'; mask; printf '1 zero 0 0 0\n'; } >"$e/bad.fap"
expect_error "bad stream" 1 "bad.fap:5: " "$e/a.glb" -- "$export_tool" "$model" --gltf "$e/a.glb" --fap "$e/bad.fap"
printf 'x' >"$e/file"
expect_error "OBJ into a file" 1 "file" "$e/a.glb" -- "$export_tool" "$model" --gltf "$e/a.glb" --vrml "$e/a.wrl" --obj "$e/file"
[ -e "$e/a.wrl" ] && fail "OBJ into a file: left the VRML file of the same run behind"
expect_error "unwritable glTF" 1 "missing_dir" - -- "$export_tool" "$model" --gltf "$e/missing_dir/a.glb"

finish "$note"
