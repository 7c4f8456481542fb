#!/bin/sh
# The issue's fidelity goals on the generated reference heads of 2,000 and
# 10,000 skin vertices, every target made on the default simulation mesh:
# each FAP side's error along its direction at the table's reference, median
# at most 3 % and worst at most 10 %, and the off-axis median at most 15 %
# of the prescribed motion (afm-build's summary line; the figures behind it
# are the MPEG-4 table's, checked against the targets in tests/fap,
# EachTargetMovesItsFdpByReferenceTimesFapuAlongTheFapsDirection). Song's
# are checked in test_song.sh. Before the seventy-sixth session the 2k
# head's worst was 20.5 % (its brows drawn apart), the 10k head's 36.2 %
# (its outer lower lip lowered). Then no target turns a skin triangle over
# or sinks skin below the skull.
# Not under the sanitizers: the two whole AFMs with their reports take 17 s
# here and many minutes there, and the figures are the same.
test_name=test_fidelity.sh
. "$(dirname "$0")/lib/common.sh"

if [ "${AFM_CONFIG:-release}" = sanitize ]; then
  echo "test_fidelity.sh: skipped under the sanitizers (two whole AFMs; the release run checks the figures)"
  exit 0
fi

for n in 2000 10000; do
  "$bin/afm-headgen" --vertices $n -o "$tmp/h$n.wrl" >/dev/null 2>&1 || fail "afm-headgen --vertices $n failed"
  "$bin/afm-build" "$tmp/h$n.wrl" "$tmp/h$n.fdp" -q --threads 2 -o "$tmp/h$n.afm" --report "$tmp/r$n" \
    >"$tmp/h$n.txt" 2>&1 || fail "the $n-vertex head's build failed: $(tail -n 5 "$tmp/h$n.txt")"
  fidelity_goals "$tmp/h$n.txt" "the $n-vertex head"
  # No target turns a skin triangle over (the report's `turned`; a lower lip
  # side's combination as played with the other sides and FAP 3 at 1024).
  # Until the seventy-seventh session the lower lip's in-betweens at -1024
  # turned 2 (2k) and 8-11 (10k) each (test_song.sh says more). The 10k
  # head's joy and fear turned 2 each until an expression's share was judged
  # by its untangled skin too (fap_synthesis.cpp).
  sed 's/"[^"]*"//g' "$tmp/r$n/report.csv" |
    awk -F, 'NR == 1 && $21 != "turned" { print "no turned column: " $0 }
      NR > 1 && $21 > 0 { print $1, $2, "at", $5 ":", $21 }' >"$tmp/turned$n.txt"
  [ -s "$tmp/turned$n.txt" ] && fail "the $n-vertex head: targets turn skin triangles over: $(tr '\n' ';' <"$tmp/turned$n.txt")"
  # Nor sinks skin below the skull (the report's `sunk`: skull-tied vertices
  # more than an AFM quantum below their skull node's rest plane).
  sed 's/"[^"]*"//g' "$tmp/r$n/report.csv" |
    awk -F, 'NR == 1 && $22 != "sunk" { print "no sunk column: " $0 }
      NR > 1 && $22 > 0 { print $1, $2, "at", $5 ":", $22 }' >"$tmp/sunk$n.txt"
  [ -s "$tmp/sunk$n.txt" ] && fail "the $n-vertex head: targets sink skin below the skull: $(tr '\n' ';' <"$tmp/sunk$n.txt")"
done
finish
