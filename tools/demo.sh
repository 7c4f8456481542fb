#!/bin/sh
# The main job on data the project generates itself: generate the reference
# head, import it (FAPU and FDP summary), build its anatomical AFM (skin,
# muscles, jaw; a morph target per FAP, viseme and expression) with the
# fidelity report, then play a FAP stream the demo writes (a smile, spoken
# visemes, a blink, a head turn) and render it to PNG frames and a contact
# sheet.
# AFM_BUILD names the build directory (tools in $AFM_BUILD/bin).
set -eu
: "${AFM_BUILD:=build}"
bin="$AFM_BUILD/bin"
out="$AFM_BUILD/demo"
mkdir -p "$out"

echo "== 1. generate the reference head (2k skin vertices)"
"$bin/afm-headgen" --vertices 2000 -o "$out/head.wrl" --fdp "$out/head.fdp" --render "$out/head.png"

echo
echo "== 2. import it: checks, FAPU, FDP summary"
"$bin/afm-import" "$out/head.wrl" "$out/head.fdp" -o "$out/head-neutral.afm"

echo
echo "== 3. build its anatomical AFM: model, calibration, targets, fidelity report"
rm -rf "$out/report"
"$bin/afm-build" "$out/head.wrl" "$out/head.fdp" -o "$out/head.afm" --report "$out/report" \
  --muscle-map "$out/muscles.png" | grep -E "^(built|targets|wrote|warning)"
"$bin/afm-info" "$out/head.afm"

echo
echo "== 4. a FAP stream: 3 s at 25 fps (a smile, visemes, a blink, a head turn)"
# Mask: FAP 1 (viseme: 4 values), FAP 2 (expression: 6 values), FAPs 19 and 20
# (upper eyelids), FAP 49 (head yaw).
awk 'BEGIN {
  pi = 3.14159265358979
  print "# written by tools/demo.sh"
  print "2.1 demo.fap 25 75"
  mask = "1 1"
  for (f = 3; f <= 68; ++f) mask = mask ((f == 19 || f == 20 || f == 49) ? " 1" : " 0")
  split("1 10 12 4 13 9 11 1 14 10 8 12 1", vis, " ")
  for (i = 0; i < 75; ++i) {
    print mask
    k = int(i / 6) + 1; blend = int(63 * (i % 6) / 5)
    joy = (i < 40) ? int(63 * sin(pi * i / 40)) : 0
    # A whole blink: 1024 IRISD units shut the neutral eye of MPEG-4, whose
    # lids touch the iris (the upper lids have targets at 300, 600 and 1024:
    # report/).
    lid = (i >= 50 && i <= 56) ? int(1024 * sin(pi * (i - 50) / 6)) : 0
    yaw = (i >= 40) ? int(35000 * sin(2 * pi * (i - 40) / 35)) : 0
    printf "%d %d %d %d 0 1 %d 0 0 0 0 %d %d %d\n", i, vis[k + 1], vis[k], blend, joy, lid, lid, yaw
  }
}' >"$out/demo.fap"
"$bin/afm-play" "$out/head.afm" "$out/demo.fap" --quiet --stats

echo
echo "== 5. render it"
rm -rf "$out/frames"
"$bin/afm-render" "$out/head.afm" "$out/demo.fap" -o "$out/frames" --size 480x600 --closeup \
  --sheet "$out/demo-sheet.png" --sheet-every 6 --progress 25

echo
echo "demo outputs in $out/:"
echo "  head.wrl head.fdp head.png      the generated head and a picture of it"
echo "  muscles.png                     its 25 muscles, lid drivers and jaw as placed from the FDPs"
echo "  head.afm                        its anatomical AFM (draco)"
echo "  report/index.html sheet.png     the fidelity report: every target, pictured"
echo "  demo.fap                        the stream"
echo "  frames/frame_*.png              the rendered frames"
echo "  demo-sheet.png                  a contact sheet of every 6th frame"
