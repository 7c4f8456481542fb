#!/bin/sh
# The main job on data the project generates itself: generate the reference
# head, import it (FAPU and FDP summary), write a neutral AFM, describe it.
# AFM_BUILD names the build directory (tools in $AFM_BUILD/bin).
set -eu
: "${AFM_BUILD:=build}"
bin="$AFM_BUILD/bin"
out="$AFM_BUILD/demo"
mkdir -p "$out"

echo "== 1. generate the reference head (10k skin vertices)"
"$bin/afm-headgen" --vertices 10000 -o "$out/head.wrl" --fdp "$out/head.fdp" --render "$out/head.png"

echo
echo "== 2. import it: checks, FAPU, FDP summary, neutral AFM"
"$bin/afm-import" "$out/head.wrl" "$out/head.fdp" -o "$out/head.afm"

echo
echo "== 3. the AFM, and its draco-profile twin"
"$bin/afm-pack" --draco "$out/head.afm" "$out/head-draco.afm"
"$bin/afm-info" "$out/head-draco.afm"

echo
echo "demo outputs in $out/: head.wrl head.fdp head.png head.afm head-draco.afm"
