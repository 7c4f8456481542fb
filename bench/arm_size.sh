#!/bin/sh
# The player core on ARMv5TE soft-float: code size per object (text, data,
# bss from arm-linux-gnueabi-size; text includes read-only data such as the
# MPEG-4 and sine tables) at -O2, -Os and -Os -mthumb; the largest stack
# frames; and the RAM the core needs for the reference head, as the ARM
# driver (tests/arm/afm_hash.c under qemu-arm) measures it.
# AFM_BUILD names the build directory; `make bench` builds what this needs.
set -u
: "${AFM_BUILD:=build}"
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top" || exit 1
: "${AFM_SHARED_DIR:=$top/../shared}"
arm="$AFM_BUILD/arm"
bin="$AFM_BUILD/bin"
tmp="$AFM_BUILD/bench-output/arm"
mkdir -p "$tmp"

echo "ARMv5TE soft-float (arm-linux-gnueabi-gcc -march=armv5te -mfloat-abi=soft), the core:"
echo "formats/src (AFM reader, writer, tables) + player_c/src (FAP reader, player)"
for v in arm-O2 arm-Os arm-Os-thumb; do
  objs=$(cd "$arm/$v/obj" && find formats player_c -name '*.o' | sort)
  [ -n "$objs" ] || { echo "bench/arm_size.sh: no objects in $arm/$v (make bench builds them)"; exit 1; }
  echo
  echo "-- $v: bytes"
  # shellcheck disable=SC2086
  (cd "$arm/$v/obj" && arm-linux-gnueabi-size $objs) | awk '
    NR == 1 { printf "%-36s %8s %6s %6s\n", "object", "text", "data", "bss"; next }
    { name = $6; sub(/\.c\.o$/, ".c", name)
      printf "%-36s %8d %6d %6d\n", name, $1, $2, $3
      t += $1; d += $2; b += $3
      if (name ~ /^player_c/) { pt += $1; pd += $2; pb += $3 } }
    END {
      printf "%-36s %8d %6d %6d\n", "total", t, d, b
      printf "%-36s %8d %6d %6d\n", "  of which player_c/src", pt, pd, pb
      printf "%-36s %8d %6d %6d\n", "  of which formats/src", t - pt, d - pd, b - pb }'
done

echo
echo "-- largest stack frames (arm-O2, -fstack-usage, bytes)"
cat "$arm/arm-O2/obj/formats/src/"*.su "$arm/arm-O2/obj/player_c/src/"*.su 2>/dev/null |
  sort -t "$(printf '\t')" -k2,2 -n -r | head -6 |
  awk -F '\t' '{ n = split($1, a, ":"); printf "  %6d  %s (%s)\n", $2, a[n], a[1] }'

# RAM for the reference head: afm-headgen's default (10k skin vertices).
if ! "$bin/afm-headgen" -o "$tmp/head.obj" --fdp "$tmp/head.fdp" >/dev/null ||
   ! "$bin/afm-import" "$tmp/head.obj" "$tmp/head.fdp" -o "$tmp/head.afm" >/dev/null ||
   ! "$arm/afm_synth" "$tmp/head.afm" "$tmp/head-synth.afm" >/dev/null; then
  echo "bench/arm_size.sh: cannot make the reference head"
  exit 1
fi
fap=""
[ -f "$AFM_SHARED_DIR/data/fap/xface/joy.fap" ] && fap="$AFM_SHARED_DIR/data/fap/xface/joy.fap"
echo
echo "-- RAM for the reference head (10k skin vertices), ARM build, bytes"
for afm in head head-synth; do
  # shellcheck disable=SC2086
  qemu-arm -L /usr/arm-linux-gnueabi "$arm/arm-O2/afm_hash" "$tmp/$afm.afm" $fap >"$tmp/$afm.out" ||
    { echo "bench/arm_size.sh: the ARM driver failed on $afm.afm"; exit 1; }
  awk -v name="$afm" '
    /^afm / { desc = $3 " " $4 " " $6 " " $7 }
    /^# ram afm / { for (i = 1; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == "file") file = kv[2]; if (kv[1] == "doc") doc = kv[2] } }
    /^# ram player=/ { split($3, kv, "="); player = kv[2] }
    /^# ram player_normal_deltas=/ { split($3, kv, "="); nd = kv[2] }
    /^# ram .*\.fap:/ { for (i = 1; i <= NF; ++i) { split($i, kv, "="); if (kv[1] == "reader") reader = kv[2]; if (kv[1] == "frames") { frames = kv[2]; fname = $3; sub(/:$/, "", fname) } } }
    END {
      printf "%s.afm (%s)\n", name, desc
      printf "  %-52s %9d\n", "AFM file (freed once decoded)", file
      printf "  %-52s %9d\n", "decoded model (afm_doc_read buffer)", doc
      printf "  %-52s %9d\n", "player (afm_player_measure)", player
      printf "  %-52s %9d\n", "player with AFM_PLAYER_NORMAL_DELTAS", nd
      if (reader) {
        printf "  %-52s %9d\n", "FAP reader, streaming (afm_fap_reader)", reader
        printf "  %-52s %9d\n", "or all frames of " fname " parsed", frames
      }
      printf "  %-52s %9d\n", "model + player + streaming reader", doc + player + reader }' "$tmp/$afm.out"
done
[ -n "$fap" ] || echo "(no ../shared/data/fap: FAP reader figures left out)"
