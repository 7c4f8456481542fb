#!/bin/sh
# afm-view, the desktop preview, in a real window under Xvfb: scripted runs
# (--set, --keys, --screenshot, --exit) against afm-render's pictures of the
# same pose, with png_diff's tolerance (the goldens'); playback keys; the
# looks (wireframe, moved vertices) and the screenshot key; bad input and no
# display (a clear message, exit 1, no crash, no file). Skips only when Xvfb
# cannot run here; in CI (CI set) that is a failure, since `make deps`
# installs it.
test_name=test_view.sh
. "$(dirname "$0")/lib/common.sh"

view="$(cd "$bin" && pwd)/afm-view"
render="$bin/afm-render"
png_diff="$AFM_BUILD/tests/png_diff"
[ -x "$png_diff" ] || { fail "$png_diff is missing (make tests builds it)"; finish; }

# --- help: every key
"$view" --help >"$tmp/help.txt" 2>&1 || fail "--help exits non-zero"
grep -q "usage: afm-view MODEL.afm \[STREAM.fap\]" "$tmp/help.txt" || fail "--help prints no usage line"
for k in "Space " "Right, Left" "Home, End" "  L " "], =, +" "\[, -" "Tab, Shift+Tab" "  / " "Up, Down" \
         "  0 " "  R " "  W " "  V " "  P " "  C " "Q, Escape" "drag" "scroll"; do
  grep -q -- "^ *$k" "$tmp/help.txt" || grep -q -- "$k" "$tmp/help.txt" || fail "--help does not list the key '$k'"
done

# The reference head with analytic targets, and a two-frame stream: closed, open jaw.
"$bin/afm-headgen" --vertices 1000 -o "$tmp/head.wrl" --fdp "$tmp/head.fdp" >/dev/null || fail "afm-headgen failed"
"$bin/afm-import" "$tmp/head.wrl" "$tmp/head.fdp" -o "$tmp/head.afm" --analytic >/dev/null ||
  fail "afm-import failed"
{
  printf '2.1 cli 25 2\n'
  mask_fap3; printf '0 0\n'
  mask_fap3; printf '1 600\n'
} >"$tmp/jaw.fap"
model="$tmp/head.afm"
stream="$tmp/jaw.fap"
size=160x200
"$render" "$model" "$stream" -o "$tmp/render" --size $size --quiet || fail "afm-render failed"

# --- bad usage and bad input: checked before any window opens
o="$tmp/bad.png"
expect_error "no model" 2 "give a model" "$o" -- "$view"
expect_error "unknown option" 2 "unknown option '--bogus'" "$o" -- "$view" "$model" --bogus
expect_error "unknown control" 2 "--set nose=3: 'nose' is no FAP, viseme or expression" "$o" -- \
  "$view" "$model" --set nose=3 --screenshot "$o" --exit
expect_error "value out of range" 2 "--set open_jaw: expected a whole number from 0 to" "$o" -- \
  "$view" "$model" --set open_jaw=-5 --screenshot "$o" --exit
expect_error "unknown key" 2 "--keys: unknown key 'hyper'" "$o" -- "$view" "$model" --keys hyper --exit
expect_error "screenshot not PNG" 2 "must end in .png" "$tmp/s.jpg" -- "$view" "$model" --screenshot "$tmp/s.jpg"
expect_error "missing model" 1 "nope\.afm: cannot read" "$o" -- "$view" "$tmp/nope.afm" --screenshot "$o" --exit
cp "$tmp/head.wrl" "$tmp/not.afm"
expect_error "not an AFM" 1 "not\.afm: " "$o" -- "$view" "$tmp/not.afm" --screenshot "$o" --exit
{
  printf '2.1 cli 25 3\n'
  mask_fap3; printf '0 0\n'
  printf '0 0 1 0\n'
  printf '1 500\n'
} >"$tmp/bad.fap"
expect_error "bad FAP line" 1 "bad\.fap:4: mask has 4 entries" "$o" -- \
  "$view" "$model" "$tmp/bad.fap" --screenshot "$o" --exit
expect_error "missing stream" 1 "none\.fap: cannot read" "$o" -- "$view" "$model" "$tmp/none.fap" --exit
expect_error "frame past the end" 2 "--frame 5: .*jaw\.fap has frames 0 to 1" "$o" -- \
  "$view" "$model" "$stream" --frame 5 --exit
expect_error "no display" 1 "cannot open a window: .*(DISPLAY|display)" "$o" -- \
  env -u DISPLAY -u WAYLAND_DISPLAY "$view" "$model" --screenshot "$o" --exit

# --- a display: Xvfb on a free display number
xvfb_pid=""
stop_xvfb() { [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null; }
trap stop_xvfb EXIT
no_xvfb() {
  if [ -n "${CI:-}" ]; then
    fail "Xvfb $1 (CI installs it with make deps, so the preview must be tested)"
    finish
  fi
  echo "$test_name: skipped the window tests: Xvfb $1"
  finish "without a display"
}
command -v Xvfb >/dev/null 2>&1 || no_xvfb "is not installed (make deps installs the xvfb package)"
Xvfb -displayfd 3 -screen 0 1024x768x24 -nolisten tcp 3>"$tmp/display" >"$tmp/xvfb.log" 2>&1 &
xvfb_pid=$!
n=0
while [ ! -s "$tmp/display" ] && [ $n -lt 100 ] && kill -0 "$xvfb_pid" 2>/dev/null; do
  sleep 0.1
  n=$((n + 1))
done
[ -s "$tmp/display" ] || no_xvfb "does not start here: $(tr '\n' ' ' <"$tmp/xvfb.log")"
DISPLAY=":$(head -n 1 "$tmp/display")"
export DISPLAY

# shot NAME ARGS...: afm-view's scripted screenshot $tmp/NAME.png; the
# window's title (printed at --exit) in $tmp/NAME.txt.
shot() {
  name=$1
  shift
  if ! "$view" "$model" --size $size --screenshot "$tmp/$name.png" --exit "$@" >"$tmp/$name.txt" 2>"$tmp/err.txt"; then
    fail "$name: afm-view failed: $(cat "$tmp/err.txt")"
  elif [ ! -s "$tmp/$name.png" ]; then
    fail "$name: no screenshot"
  fi
}
# same A B WHAT / differ A B WHAT: the pictures match within the tolerance, or not.
same() {
  r=$("$png_diff" "$1" "$2" 2>&1) || fail "$3: $r"
  echo "  $3: $r"
}
differ() {
  r=$("$png_diff" "$1" "$2" 2>&1)
  [ $? -eq 1 ] || fail "$3 (expected a difference): $r"
}

# --- a live FAP against afm-render's frame of the same pose; and neutral
shot neutral
shot jaw --set open_jaw=600
same "$tmp/neutral.png" "$tmp/render/frame_00000.png" "neutral, afm-view against afm-render"
same "$tmp/jaw.png" "$tmp/render/frame_00001.png" "open_jaw=600, afm-view against afm-render"
differ "$tmp/jaw.png" "$tmp/neutral.png" "open_jaw=600 against neutral"
differ "$tmp/render/frame_00001.png" "$tmp/render/frame_00000.png" "afm-render's open jaw against neutral"
grep -q "open_jaw (FAP 3) = 600" "$tmp/jaw.txt" || fail "the title does not show the FAP: $(cat "$tmp/jaw.txt")"
shot jaw3 --set 3=600
same "$tmp/jaw3.png" "$tmp/jaw.png" "FAP 3 by number against by name"

# --- live controls by keys: pick by name, raise, lower, reset
shot joy --set joy=63
differ "$tmp/joy.png" "$tmp/neutral.png" "joy=63 against neutral"
shot joy_keys --keys "/,j,o,y,enter,shift+up,shift+up,shift+up,up,up,up,up"
grep -q "expression joy (1) = 63" "$tmp/joy_keys.txt" || fail "typed joy, raised to 63: $(cat "$tmp/joy_keys.txt")"
same "$tmp/joy_keys.png" "$tmp/joy.png" "joy raised by keys against --set joy=63"
shot reset --set open_jaw=600 --keys "r"
same "$tmp/reset.png" "$tmp/neutral.png" "R (reset) against neutral"
shot zero --set open_jaw=600 --keys "down,0"
grep -q "open_jaw (FAP 3) = 0" "$tmp/zero.txt" || fail "0 does not zero the control: $(cat "$tmp/zero.txt")"
shot tab --keys "tab,tab,shift+tab"
grep -q "lower_t_midlip (FAP 4) = 0" "$tmp/tab.txt" || fail "Tab, Tab, Shift+Tab: $(cat "$tmp/tab.txt")"

# --- the stream: stepping and seeking, against afm-render's frames
shot step "$stream" --keys right
grep -q "frame 1/1  0.040 s  x1  paused" "$tmp/step.txt" || fail "Right: $(cat "$tmp/step.txt")"
same "$tmp/step.png" "$tmp/render/frame_00001.png" "frame 1 (Right) against afm-render's"
shot back "$stream" --frame 1 --keys "left"
same "$tmp/back.png" "$tmp/render/frame_00000.png" "frame 0 (Left from 1) against afm-render's"
shot keys "$stream" --keys "end,l,],],],[,home"
grep -q "frame 0/1  0.000 s  x2  paused  loop" "$tmp/keys.txt" || fail "End, L, ] x3, [, Home: $(cat "$tmp/keys.txt")"
shot live_over "$stream" --frame 1 --set open_jaw=0
same "$tmp/live_over.png" "$tmp/render/frame_00000.png" "a live value over the stream's"
# Playing (Space): with --exit the clock moves one stream frame (x speed) per
# drawn frame. Without --loop it stops at the last frame; with it, it wraps.
# play NAME EXPECTED ARGS...
play() {
  name=$1 want=$2
  shift 2
  "$view" "$model" "$stream" --size 64x64 --exit --keys space "$@" >"$tmp/$name.txt" 2>"$tmp/err.txt" ||
    fail "$name: afm-view failed: $(cat "$tmp/err.txt")"
  grep -q -- "$want" "$tmp/$name.txt" || fail "$name: expected '$want': $(cat "$tmp/$name.txt")"
}
play play_end "frame 1/1  0.040 s  x1  paused" --frames 5
play play_loop "frame 0/1  0.000 s  x1  playing  loop" --frames 2 --loop
play play_slow "frame 0/1  0.000 s  x0.5  playing" --frames 1 --speed 0.5
play play_slow2 "frame 1/1  0.040 s  x0.5  paused" --frames 2 --speed 0.5

# --- looks: wireframe and moved vertices change the picture; moved shows dots only
shot wire --keys w
differ "$tmp/wire.png" "$tmp/neutral.png" "wireframe against neutral"
shot moved_none --moved
shot moved_jaw --moved --set open_jaw=600
differ "$tmp/moved_jaw.png" "$tmp/moved_none.png" "moved vertices of the open jaw against none"
grep -q "moved vertices: [1-9]" "$tmp/moved_jaw.txt" || fail "no moved vertices counted: $(cat "$tmp/moved_jaw.txt")"
grep -q "moved vertices: 0" "$tmp/moved_none.txt" || fail "neutral moves vertices: $(cat "$tmp/moved_none.txt")"

# --- the screenshot key writes afm-view-001.png in the current directory
mkdir -p "$tmp/keyshot"
abs_model="$(cd "$tmp" && pwd)/head.afm"
(cd "$tmp/keyshot" && "$view" "$abs_model" --size $size --set open_jaw=600 --keys p --exit) >"$tmp/out.txt" 2>&1 ||
  fail "P failed: $(cat "$tmp/out.txt")"
if [ -s "$tmp/keyshot/afm-view-001.png" ]; then
  same "$tmp/keyshot/afm-view-001.png" "$tmp/jaw.png" "the P screenshot against --screenshot"
else
  fail "P wrote no afm-view-001.png: $(cat "$tmp/out.txt")"
fi

# --- a screenshot that cannot be written: exit 1, the file named
expect_error "screenshot in no directory" 1 "no/dir/s\.png" "$tmp/no/dir/s.png" -- \
  "$view" "$model" --size $size --screenshot "$tmp/no/dir/s.png" --exit

finish
