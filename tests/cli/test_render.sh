#!/bin/sh
# afm-render on the command line: the files it writes (frames, their names and
# sizes, contact sheets), progress, textures found or missing, and its errors
# (bad usage exits 2, bad input 1; a message naming the file and line, part or
# field; no output left behind, even when a run fails half-way). The pictures
# themselves are checked by tests/render/test_render.cpp.
test_name=test_render.sh
. "$(dirname "$0")/lib/common.sh"

# png_size FILE: "WIDTHxHEIGHT" from the IHDR chunk.
png_size() {
  od -An -tu1 -j16 -N8 "$1" 2>/dev/null |
    awk '{ printf "%dx%d", $1 * 16777216 + $2 * 65536 + $3 * 256 + $4, $5 * 16777216 + $6 * 65536 + $7 * 256 + $8 }'
}

render="$bin/afm-render"
"$render" --help >"$tmp/help.txt" 2>&1 || fail "--help exits non-zero"
grep -q "usage: afm-render" "$tmp/help.txt" || fail "--help prints no usage line"

# A small head and a three-frame stream: closed, open, closed.
"$bin/afm-headgen" --vertices 1000 -o "$tmp/head.wrl" --fdp "$tmp/head.fdp" >/dev/null ||
  fail "afm-headgen failed"
"$bin/afm-import" "$tmp/head.wrl" "$tmp/head.fdp" -o "$tmp/head.afm" --analytic >/dev/null ||
  fail "afm-import failed"
{
  printf '2.1 cli 25 3\n'
  mask_fap3; printf '0 0\n'
  mask_fap3; printf '1 600\n'
  mask_fap3; printf '2 0\n'
} >"$tmp/jaw.fap"
model="$tmp/head.afm"
stream="$tmp/jaw.fap"

# --- frames: names, count, size, summary
"$render" "$model" "$stream" -o "$tmp/all" --size 64x48 >"$tmp/out.txt" 2>"$tmp/err.txt" ||
  fail "a plain run failed: $(cat "$tmp/err.txt")"
[ "$(ls "$tmp/all" 2>/dev/null | tr '\n' ' ')" = "frame_00000.png frame_00001.png frame_00002.png " ] ||
  fail "frames written: $(ls "$tmp/all" 2>/dev/null | tr '\n' ' ')"
[ "$(png_size "$tmp/all/frame_00001.png")" = "64x48" ] || fail "frame size $(png_size "$tmp/all/frame_00001.png")"
grep -q "wrote 3 frame(s) of 64x48" "$tmp/out.txt" || fail "no summary: $(cat "$tmp/out.txt")"
grep -q "time per frame" "$tmp/out.txt" || fail "no timing in the summary"
cmp -s "$tmp/all/frame_00000.png" "$tmp/all/frame_00001.png" && fail "the open jaw looks like the closed one"
cmp -s "$tmp/all/frame_00000.png" "$tmp/all/frame_00002.png" || fail "frames 0 and 2 (the same pose) differ"

# --- a range, progress lines, quiet
"$render" "$model" "$stream" -o "$tmp/range" --size 40x30 --frames 1: --progress 1 \
  >"$tmp/out.txt" 2>"$tmp/err.txt" || fail "--frames 1: failed"
[ "$(ls "$tmp/range" | tr '\n' ' ')" = "frame_00001.png frame_00002.png " ] ||
  fail "--frames 1: wrote $(ls "$tmp/range" | tr '\n' ' ')"
grep -q "frame 1, 1 of 2 (50%)" "$tmp/err.txt" || fail "no progress line: $(cat "$tmp/err.txt")"
"$render" "$model" "$stream" -o "$tmp/quiet" --size 40x30 --quiet >"$tmp/out.txt" 2>"$tmp/err.txt" ||
  fail "--quiet failed"
[ -s "$tmp/out.txt" ] || [ -s "$tmp/err.txt" ] && fail "--quiet prints something"

# --- resampling: 50 fps gives 5 frames over the same 80 ms
"$render" "$model" "$stream" -o "$tmp/fps" --size 40x30 --fps 50 --quiet || fail "--fps 50 failed"
[ "$(ls "$tmp/fps" | wc -l)" -eq 5 ] || fail "--fps 50 wrote $(ls "$tmp/fps" | wc -l) frames, expected 5"

# --- contact sheet only: the chosen frames, tiles of 64x48 with 4-pixel gaps
"$render" "$model" "$stream" --sheet "$tmp/sheet.png" --sheet-frames 0,2 --size 64x48 --quiet ||
  fail "--sheet failed"
[ "$(png_size "$tmp/sheet.png")" = "140x56" ] || fail "sheet size $(png_size "$tmp/sheet.png"), expected 140x56"
"$render" "$model" "$stream" -o "$tmp/both" --sheet "$tmp/sheet2.png" --sheet-every 1 --sheet-columns 1 \
  --sheet-shrink 2 --size 64x48 --quiet || fail "-o with --sheet failed"
[ "$(png_size "$tmp/sheet2.png")" = "40x88" ] || fail "sheet2 size $(png_size "$tmp/sheet2.png"), expected 40x88"
[ "$(ls "$tmp/both" | wc -l)" -eq 3 ] || fail "-o with --sheet wrote $(ls "$tmp/both" | wc -l) frames"

# --- bad usage: exit 2, a message, nothing written
o="$tmp/bad"
expect_error "unknown option" 2 "unknown option '--bogus'" "$o" -- "$render" "$model" "$stream" -o "$o" --bogus
expect_error "one argument" 2 "give a model" "$o" -- "$render" "$model" -o "$o"
expect_error "nothing to write" 2 "nothing to write" "$o" -- "$render" "$model" "$stream"
expect_error "bad size" 2 "--size.*10y" "$o" -- "$render" "$model" "$stream" -o "$o" --size 10y
expect_error "tiny size" 2 "16 to 4096, got '8'" "$o" -- "$render" "$model" "$stream" -o "$o" --size 8x8
expect_error "frames backwards" 2 "comes before" "$o" -- "$render" "$model" "$stream" -o "$o" --frames 2:1
expect_error "frames past the end" 2 "frames 0 to 2 at 25 fps, not 0 to 9" "$o" -- \
  "$render" "$model" "$stream" -o "$o" --frames 0:9
expect_error "sheet frame not rendered" 2 "frame 0 is not rendered" "$tmp/s.png" -- \
  "$render" "$model" "$stream" --sheet "$tmp/s.png" --frames 1:2 --sheet-frames 0
expect_error "sheet not PNG" 2 "must end in .png" "$tmp/s.jpg" -- \
  "$render" "$model" "$stream" --sheet "$tmp/s.jpg"
expect_error "sheet options alone" 2 "need --sheet" "$o" -- "$render" "$model" "$stream" -o "$o" --sheet-every 2
expect_error "bad fps" 2 "--fps.*got '0'" "$o" -- "$render" "$model" "$stream" -o "$o" --fps 0
expect_error "bad mirror" 2 "use lr, io or lr,io" "$o" -- "$render" "$model" "$stream" -o "$o" --mirror x
expect_error "missing value" 2 "--yaw needs a value" "$o" -- "$render" "$model" "$stream" -o "$o" --yaw

# --- bad input: exit 1, the file (and line) named, nothing written
expect_error "missing model" 1 "nope\.afm: cannot read" "$o" -- "$render" "$tmp/nope.afm" "$stream" -o "$o"
cp "$tmp/head.wrl" "$tmp/not.afm"
expect_error "not an AFM" 1 "not\.afm: " "$o" -- "$render" "$tmp/not.afm" "$stream" -o "$o"
{
  printf '2.1 cli 25 3\n'
  mask_fap3; printf '0 0\n'
  printf '0 0 1 0\n'
  printf '1 500\n'
} >"$tmp/bad.fap"
expect_error "bad FAP line" 1 "bad\.fap:4: mask has 4 entries" "$o" -- "$render" "$model" "$tmp/bad.fap" -o "$o"
expect_error "missing stream" 1 "none\.fap: cannot read" "$o" -- "$render" "$model" "$tmp/none.fap" -o "$o"
expect_error "no such parent" 1 "no/such/out: cannot create" "$tmp/no" -- \
  "$render" "$model" "$stream" -o "$tmp/no/such/out"
expect_error "sheet in no directory" 1 "the directory .*no/dir does not exist" "$o" -- \
  "$render" "$model" "$stream" -o "$o" --sheet "$tmp/no/dir/s.png"

# --- a run that fails half-way removes the frames it wrote: frame 1 cannot
# be written (a directory is in its way)
mkdir -p "$tmp/half/frame_00001.png"
expect_error "failing half-way" 1 "frame_00001\.png" "$tmp/half/frame_00000.png" -- \
  "$render" "$model" "$stream" -o "$tmp/half" --size 40x30 --quiet

# --- textures: the skin textured with skin.tga (a 2x2 TGA written here)
awk '!done && /material Material/ { print; print "        texture ImageTexture { url \"skin.tga\" }"; done = 1; next }
     { print }' "$tmp/head.wrl" >"$tmp/tex.wrl"
mkdir -p "$tmp/tex" "$tmp/elsewhere"
"$bin/afm-import" "$tmp/tex.wrl" "$tmp/head.fdp" -o "$tmp/tex/tex.afm" --analytic >"$tmp/out.txt" 2>&1 ||
  fail "afm-import of the textured head failed: $(cat "$tmp/out.txt")"
grep -q "skin.tga" "$tmp/out.txt" || fail "the textured head has no texture: $(cat "$tmp/out.txt")"
# 2x2, 24-bit, uncompressed, stored bottom-up: blue, white, then red, green.
printf '\000\000\002\000\000\000\000\000\000\000\000\000\002\000\002\000\030\000' >"$tmp/elsewhere/skin.tga"
printf '\377\000\000\377\377\377\000\000\377\000\377\000' >>"$tmp/elsewhere/skin.tga"
expect_error "missing texture" 1 "part skin: texture 'skin\.tga' is not in .*--no-textures" "$o" -- \
  "$render" "$tmp/tex/tex.afm" "$stream" -o "$o"
"$render" "$tmp/tex/tex.afm" "$stream" -o "$tmp/textured" --textures "$tmp/elsewhere" --size 64x48 \
  --frames 0 >"$tmp/out.txt" 2>&1 || fail "--textures DIR failed: $(cat "$tmp/out.txt")"
grep -q "1 textured, 1 texture files" "$tmp/out.txt" || fail "not textured: $(cat "$tmp/out.txt")"
cmp -s "$tmp/textured/frame_00000.png" "$tmp/all/frame_00000.png" && fail "the texture changes nothing"
cp "$tmp/elsewhere/skin.tga" "$tmp/tex/skin.tga"
"$render" "$tmp/tex/tex.afm" "$stream" -o "$tmp/beside" --size 64x48 --frames 0 --quiet ||
  fail "a texture beside the model is not found"
cmp -s "$tmp/textured/frame_00000.png" "$tmp/beside/frame_00000.png" || fail "same texture, different picture"
"$render" "$tmp/tex/tex.afm" "$stream" -o "$tmp/untextured" --size 64x48 --frames 0 --quiet --no-textures ||
  fail "--no-textures failed"
cmp -s "$tmp/untextured/frame_00000.png" "$tmp/all/frame_00000.png" ||
  fail "--no-textures differs from the model without a texture"
head -c 25 "$tmp/elsewhere/skin.tga" >"$tmp/tex/skin.tga"
expect_error "truncated texture" 1 "skin\.tga: pixel data: the file ends in stored row 1 of 2" "$o" -- \
  "$render" "$tmp/tex/tex.afm" "$stream" -o "$o"

finish
