#!/bin/sh
# The player core on ARMv5TE soft-float plays bit-exactly like on the host.
#
# The hash driver tests/arm/afm_hash.c, built from the core sources alone
# (Makefile: "ARM cross build"), runs as arm-O0 and arm-O2 under qemu-arm and
# as host-O0, host-O2 and host-O3 (sanitized in config=sanitize); every
# per-frame line must match host-O2's. Inputs: the reference head (afm-headgen + afm-import,
# raw profile), the same head with synthetic morph targets and rigid parts
# (afm_synth), a smaller head with them for the long streams and once more
# with control points (afm_synth --lift: the LIFT kernel), the FAP files
# in ../shared/data/fap when present, and a synthetic stream written here.
# Also checks that the ARM objects use no FPU: no VFP/NEON instructions, no
# FP attributes, soft-float ABI; and that the core (formats/src and
# player_c/src) calls no soft-float helper at all.
top=$(cd "$(dirname "$0")/../.." && pwd)
cd "$top" || exit 1
test_name=test_arm.sh
. tests/cli/lib/common.sh
: "${AFM_SHARED_DIR:=$top/../shared}"
arm="$AFM_BUILD/arm"
sysroot=/usr/arm-linux-gnueabi
variants="arm-O0 arm-O2 host-O0 host-O2 host-O3"

for tool in qemu-arm arm-linux-gnueabi-readelf arm-linux-gnueabi-objdump arm-linux-gnueabi-nm; do
  command -v "$tool" >/dev/null 2>&1 || { echo "FAIL: $tool not found (make deps installs it)"; exit 1; }
done
for v in $variants; do
  [ -x "$arm/$v/afm_hash" ] || { echo "FAIL: $arm/$v/afm_hash not built (make tests builds it)"; exit 1; }
done
[ -x "$arm/afm_synth" ] || { echo "FAIL: $arm/afm_synth not built"; exit 1; }

# run VARIANT ARGS...: the driver of that build.
run() {
  v=$1
  shift
  case "$v" in
    arm-*) qemu-arm -L "$sysroot" "$arm/$v/afm_hash" "$@" ;;
    *) "$arm/$v/afm_hash" "$@" ;;
  esac
}

# ---- no FPU in the ARM build -------------------------------------------------
# VFP/NEON mnemonics (UAL v*, pre-UAL f*) and coprocessor 10/11 accesses.
fp_insn='^[[:space:]]*[0-9a-f]+:[[:space:]]+[0-9a-f]+[[:space:]]+(v[a-z0-9.]+|f(ld|st|add|sub|mul|div|cmp|cpy|abs|neg|sqrt|mac|msc|nm|si|ui|to|cvt|mrs|msr|mrx|mxr|mdr|mrd|md|ms)[a-z0-9]*|(mcr|mrc|ldc|stc|cdp|mcrr|mrrc)2?[a-z]*[[:space:]]+(p10|p11|cp10|cp11)[^0-9])[[:space:]]'
fp_attr='Tag_FP_arch|Tag_Advanced_SIMD_arch|Tag_ABI_VFP_args|Tag_MVE_arch|Tag_VFP_HP_extension'
softfp_call='__aeabi_([fd][a-z0-9]*|[a-z]*2[fd][a-z]*)$|__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord)[sd]f[23]$|__(float|fix|extend|trunc)[a-z]*[sd]f[a-z0-9]*$'
for v in arm-O0 arm-O2; do
  objs=$(find "$arm/$v/obj" -name '*.o' | sort)
  [ -n "$objs" ] || fail "$v: no objects"
  for o in $objs "$arm/$v/afm_hash"; do
    if arm-linux-gnueabi-readelf -A "$o" | grep -Eq "$fp_attr"; then
      fail "$v: $o has FP attributes: $(arm-linux-gnueabi-readelf -A "$o" | grep -E "$fp_attr" | tr -s ' \n' ' ')"
    fi
    n=$(arm-linux-gnueabi-objdump -d "$o" | grep -Ec "$fp_insn")
    if [ "$n" -ne 0 ]; then
      fail "$v: $o holds $n floating-point instructions:"
      arm-linux-gnueabi-objdump -d "$o" | grep -E "$fp_insn" | head -5 | sed 's/^/    /'
    fi
  done
  arm-linux-gnueabi-readelf -h "$arm/$v/afm_hash" | grep -q 'soft-float ABI' ||
    fail "$v: afm_hash is not a soft-float ABI binary"
  arm-linux-gnueabi-readelf -A "$arm/$v/afm_hash" | grep -q 'Tag_CPU_arch: v5TE' ||
    fail "$v: afm_hash is not built for ARMv5TE"
  # The core promises no floating point: not even soft-float calls.
  for o in $(find "$arm/$v/obj/player_c" "$arm/$v/obj/formats" -name '*.o' 2>/dev/null | sort); do
    calls=$(arm-linux-gnueabi-nm -u "$o" | awk '{ print $NF }' | grep -E "$softfp_call" | tr '\n' ' ')
    [ -z "$calls" ] || fail "$v: $o calls soft-float helpers: $calls"
  done
done

# ---- inputs ------------------------------------------------------------------
if ! "$bin/afm-headgen" -o "$tmp/head.obj" --fdp "$tmp/head.fdp" >/dev/null ||
   ! "$bin/afm-import" "$tmp/head.obj" "$tmp/head.fdp" -o "$tmp/head.afm" >/dev/null ||
   ! "$arm/afm_synth" "$tmp/head.afm" "$tmp/head-synth.afm" >/dev/null ||
   ! "$bin/afm-headgen" --vertices 2000 -o "$tmp/small.obj" --fdp "$tmp/small.fdp" >/dev/null ||
   ! "$bin/afm-import" "$tmp/small.obj" "$tmp/small.fdp" -o "$tmp/small.afm" >/dev/null ||
   ! "$arm/afm_synth" "$tmp/small.afm" "$tmp/small-synth.afm" >/dev/null ||
   ! "$arm/afm_synth" --lift "$tmp/small.afm" "$tmp/small-lift.afm" >/dev/null ||
   ! "$bin/afm-pack" --draco "$tmp/small-synth.afm" "$tmp/small-draco.afm" >/dev/null; then
  echo "FAIL: making the test heads"
  exit 1
fi

# A synthetic stream: FAPs 1 and 2, every low-level FAP with changing masks
# (unsent values persist) up to 800 (past the synthetic in-betweens at 640),
# decimals with halves, values beyond range, eyeball,
# jaw and head rotations, comment lines.
awk 'BEGIN {
  n = 60
  print "# synthetic stream for tests/cli/test_arm.sh"
  print "2.1 arm-synthetic 25 " n
  for (i = 0; i < n; ++i) {
    mask = ""; vals = i
    for (f = 1; f <= 68; ++f) {
      on = (i % 10 == 0) || ((f + i) % 3 != 0 && f > 2) || (f <= 2 && i % 4 != 3)
      mask = mask (f > 1 ? " " : "") (on ? 1 : 0)
      if (!on) continue
      if (f == 1) { vals = vals " " (i % 15) " " ((i * 7) % 15) " " ((i * 5) % 64) " " (i % 2); continue }
      if (f == 2) { vals = vals " " (i % 7) " " ((i * 9) % 64) " " ((i * 3) % 7) " " ((i * 11) % 64) " 0 1"; continue }
      v = ((i * 37 + f * 101) % 1601) - 800
      if ((f >= 23 && f <= 26) || (f >= 48 && f <= 50)) v = v * 15
      if (f == 3 && i == 5) v = 99999
      if ((i + f) % 7 == 0) v = v ".5"
      else if ((i + f) % 11 == 0) v = v ".25"
      vals = vals " " v
    }
    if (i % 20 == 7) print "# a comment between frames"
    print mask
    print vals
  }
}' >"$tmp/synthetic.fap"

shared_faps=""
if [ -d "$AFM_SHARED_DIR/data/fap" ]; then
  shared_faps=$(find "$AFM_SHARED_DIR/data/fap" -name '*.fap' | sort)
else
  echo "note: $AFM_SHARED_DIR/data/fap is absent: the synthetic stream only"
fi

# ---- runs and comparison -----------------------------------------------------
# case NAME AFM FAP...: every build gives host-O2's lines.
cases=0
lines=0
check_case() {
  name=$1
  shift
  # Two lanes (CI machines have two cores): arm-O0, the slowest, beside the rest.
  for lane in arm-O0 "$(echo "$variants" | sed 's/arm-O0//')"; do
    (for v in $lane; do
      run "$v" "$@" >"$tmp/$name.$v.out" 2>"$tmp/$name.$v.err"
      echo $? >"$tmp/$name.$v.status"
    done) &
  done
  wait
  for v in $variants; do
    st=$(cat "$tmp/$name.$v.status")
    if [ "$st" -ne 0 ]; then
      fail "$name: $v exits $st"
      sed 's/^/    /' "$tmp/$name.$v.err" | head -20
    fi
    grep -v '^#' "$tmp/$name.$v.out" >"$tmp/$name.$v.txt"
  done
  for v in $variants; do
    [ "$v" = host-O2 ] && continue
    if ! cmp -s "$tmp/$name.host-O2.txt" "$tmp/$name.$v.txt"; then
      fail "$name: $v differs from host-O2 ($(diff "$tmp/$name.host-O2.txt" "$tmp/$name.$v.txt" | grep -c '^<') lines differ); first differences:"
      diff "$tmp/$name.host-O2.txt" "$tmp/$name.$v.txt" | head -10 | sed 's/^/    /'
    fi
  done
  if [ "$name" != draco ] && grep -q '^error' "$tmp/$name.host-O2.txt"; then
    echo "note: $name: $(grep '^error' "$tmp/$name.host-O2.txt" | head -3 | tr '\n' ' ')"
  fi
  cases=$((cases + 1))
  lines=$((lines + $(wc -l <"$tmp/$name.host-O2.txt")))
}

# shellcheck disable=SC2086
check_case small "$tmp/small-synth.afm" "$tmp/synthetic.fap" $shared_faps
check_case head "$tmp/head.afm" "$tmp/synthetic.fap"
check_case head-synth "$tmp/head-synth.afm" "$tmp/synthetic.fap"
check_case draco "$tmp/small-draco.afm"
check_case lift "$tmp/small-lift.afm" "$tmp/synthetic.fap"

# ---- the outputs say what they should ------------------------------------------
out="$tmp/small.host-O2.txt"
grep -q "^afm small-synth.afm .* targets=[1-9][0-9]* rigids=4 " "$out" ||
  fail "small: the synthetic head has no targets or rigid parts: $(grep '^afm' "$out")"
grep -q '^error small-draco.afm: .*Draco' "$tmp/draco.host-O2.txt" ||
  fail "draco: a draco-profile file is not refused for want of a codec: $(cat "$tmp/draco.host-O2.txt")"
a=$(grep '^afm' "$tmp/head.host-O2.txt" | sed 's/.* doc=//')
b=$(grep '^afm' "$tmp/head-synth.host-O2.txt" | sed 's/.* doc=//')
[ -n "$a" ] && [ "$a" != "$b" ] || fail "the document hash does not see the morph targets ($a, $b)"
fap_reader=no
player=no
if grep -q '^fap \|^error synthetic.fap' "$out"; then
  fap_reader=yes
  grep -q '^fap synthetic.fap: version 2.1 fps 25/1 frames=60 ' "$out" ||
    fail "the synthetic stream does not read as 60 frames: $(grep 'synthetic.fap' "$out" | head -2)"
  if [ -n "$shared_faps" ]; then
    n=$(grep -c '^fap ' "$out")
    [ "$n" -eq $(($(echo "$shared_faps" | wc -l) + 1)) ] ||
      fail "only $n of the FAP files read: $(grep '^error' "$out" | head -3)"
  fi
fi
if grep -q '^pose ' "$out"; then
  player=yes
  # The poses must move: many distinct position hashes over the streams.
  distinct=$(grep -o 'pose=[0-9a-f]*' "$out" | sort -u | wc -l)
  [ "$distinct" -ge 50 ] || fail "only $distinct distinct poses over the streams"
  distinct=$(grep '^frame' "$tmp/head-synth.host-O2.txt" | grep -o 'pose=[0-9a-f]*' | sort -u | wc -l)
  [ "$distinct" -ge 50 ] || fail "only $distinct distinct poses of the synthetic stream on the reference head"
  # Control points (LIFT): the lifted head moves through the whole stream.
  distinct=$(grep '^frame' "$tmp/lift.host-O2.txt" | grep -o 'pose=[0-9a-f]*' | sort -u | wc -l)
  [ "$distinct" -ge 50 ] || fail "only $distinct distinct poses of the synthetic stream on the lifted head"
  grep '^frame' "$tmp/lift.host-O2.txt" | grep -o 'pose=[0-9a-f]*' >"$tmp/lift.poses"
  [ "$(grep -c . "$tmp/lift.poses")" -ge 60 ] || fail "the lifted head played fewer than 60 frames"
fi

finish "$cases cases, $lines lines each identical on $variants; FAP reader: $fap_reader, player: $player"
