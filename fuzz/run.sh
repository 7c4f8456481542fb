#!/bin/sh
# Runs the libFuzzer targets given as arguments (`make fuzz` builds them),
# each for FUZZ_SECONDS, one after the other.
#
# Seed corpora are made here, never committed: small reference heads
# (afm-headgen + afm-import), the same with synthetic targets and rigid parts
# (tests/arm/afm_synth, once with control points: LIFT), tiny files of every chunk kind (fuzz/afm_seed), each
# raw and draco; and the .fap files of ../shared/data/fap plus a synthetic one.
# Working corpora stay in $FUZZ_DIR/corpus/<target>/ between runs; crash
# inputs go to $FUZZ_DIR/crashes/, logs to $FUZZ_DIR/<target>.log.
# Exit status 1 when a target found a crash (or failed to run).
set -u
: "${AFM_BUILD:=build}"
: "${FUZZ_DIR:=$AFM_BUILD/fuzz}"
: "${FUZZ_SECONDS:=60}"
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top" || exit 1
: "${AFM_SHARED_DIR:=$top/../shared}"
bin="$AFM_BUILD/bin"
seeds="$FUZZ_DIR/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/afm" "$seeds/afm-raw" "$seeds/fap" "$FUZZ_DIR/crashes"

# ---- seeds ---------------------------------------------------------------------
tmp="$FUZZ_DIR/seed-work"
rm -rf "$tmp"
mkdir -p "$tmp"
if ! "$FUZZ_DIR/afm_seed" "$tmp" ||
   ! "$bin/afm-headgen" --vertices 1000 -o "$tmp/head.obj" --fdp "$tmp/head.fdp" >/dev/null ||
   ! "$bin/afm-import" "$tmp/head.obj" "$tmp/head.fdp" -o "$tmp/head.afm" >/dev/null ||
   ! "$AFM_BUILD/arm/afm_synth" "$tmp/head.afm" "$tmp/head-synth.afm" >/dev/null ||
   ! "$AFM_BUILD/arm/afm_synth" --lift "$tmp/head.afm" "$tmp/head-lift.afm" >/dev/null ||
   ! "$bin/afm-pack" --draco "$tmp/head-lift.afm" "$tmp/head-lift-draco.afm" >/dev/null ||
   ! "$bin/afm-pack" --draco "$tmp/head.afm" "$tmp/head-draco.afm" >/dev/null ||
   ! "$bin/afm-pack" --draco "$tmp/head-synth.afm" "$tmp/head-synth-draco.afm" >/dev/null; then
  echo "fuzz: cannot make the AFM seeds"
  exit 1
fi
for f in "$tmp"/*.afm; do
  cp "$f" "$seeds/afm/"
  case "$f" in *draco*) ;; *) cp "$f" "$seeds/afm-raw/" ;; esac
done
# FAP seeds: the input's first byte says how many chunk-size bytes follow (0).
# Each real file cut to its first 8 frames (the header's count set to match),
# so that the fuzzer runs fast; the small ones whole as well.
n=0
for f in $(find "$AFM_SHARED_DIR/data/fap" -name '*.fap' 2>/dev/null | sort); do
  n=$((n + 1))
  { printf '\000'; awk -v k=8 '
      /^[ \t]*(#|\r?$)/ { if (lines < 2 * k) print; next }
      !header { header = 1; cr = sub(/\r$/, ""); if ($NF + 0 < k) k = $NF + 0; $NF = k; print $0 (cr ? "\r" : ""); next }
      lines < 2 * k { lines++; print }' "$f"; } >"$seeds/fap/shared-$n-cut.fap"
  [ "$(wc -c <"$f")" -gt 4096 ] || { printf '\000'; cat "$f"; } >"$seeds/fap/shared-$n.fap"
done
[ "$n" -gt 0 ] || echo "note: $AFM_SHARED_DIR/data/fap is absent: synthetic FAP seeds only"
{
  printf '\003\000\007\377'
  printf '# synthetic\r\n2.0 seed 12.5 2\r\n'
  printf '1 1 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1 1 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1\r\n'
  printf '0 3 4 20 1 2 30 5 40 0 1 200 -512.5 1e3 -7 .5 10.\r\n'
  printf '0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\r\n'
  printf '7 1000 # a comment\r\n'
} >"$seeds/fap/synthetic.fap"

# ---- runs ------------------------------------------------------------------------
failed=""
for target in "$@"; do
  name=$(basename "$target")
  case "$name" in
    fuzz_afm) seed="$seeds/afm-raw" ;;
    fuzz_afm_draco) seed="$seeds/afm" ;;
    fuzz_fap) seed="$seeds/fap" ;;
    *) echo "fuzz: unknown target $target"; exit 1 ;;
  esac
  corpus="$FUZZ_DIR/corpus/$name"
  mkdir -p "$corpus"
  log="$FUZZ_DIR/$name.log"
  echo "== $name: $FUZZ_SECONDS s (corpus $corpus, seeds $seed)"
  "$target" -max_total_time="$FUZZ_SECONDS" -timeout=25 -rss_limit_mb=2560 \
    -print_final_stats=1 -artifact_prefix="$FUZZ_DIR/crashes/$name-" \
    "$corpus" "$seed" >"$log" 2>&1
  status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  cov=$(grep -E '^#[0-9]+' "$log" | tail -1 | sed -n 's/.*\(cov: [0-9]*\).*\(ft: [0-9]*\).*/\1 \2/p')
  if [ "$status" -ne 0 ]; then
    echo "FAIL: $name exits $status after ${runs:-?} runs; the end of $log:"
    grep -E 'ERROR|SUMMARY|fuzz(_fap)?:|artifact|Test unit written' "$log" | head -20 | sed 's/^/    /'
    failed="$failed $name"
  else
    echo "$name: ${runs:-?} runs, $cov, corpus $(find "$corpus" -type f | wc -l) files, no crash"
  fi
done
if [ -n "$failed" ]; then
  echo "fuzz: crashes in:$failed (inputs in $FUZZ_DIR/crashes/)"
  exit 1
fi
echo "fuzz: no crash"
