#!/bin/sh
# Runs every gtest binary given as arguments, then the command-line tests in
# tests/cli/. AFM_BUILD names the build directory (tools in $AFM_BUILD/bin).
set -u
: "${AFM_BUILD:=build}"
export AFM_BUILD
top=$(cd "$(dirname "$0")/.." && pwd)
export AFM_SOURCE_DIR="$top"
: "${AFM_SHARED_DIR:=$top/../shared}"
export AFM_SHARED_DIR
if [ ! -d "$AFM_SHARED_DIR/data" ]; then
  echo "note: $AFM_SHARED_DIR/data is absent: tests that need the shared data files skip"
fi

# Sanitizer builds: keep LeakSanitizer's list of used suppressions (OSMesa's
# known leaks) out of the output the tests look at.
LSAN_OPTIONS="print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export LSAN_OPTIONS

failed=""
for t in "$@"; do
  echo "== $t"
  if ! "$t" --gtest_brief=1; then failed="$failed $t"; fi
done
for t in "$top"/tests/cli/*.sh; do
  [ -e "$t" ] || continue
  echo "== $t"
  if ! sh "$t"; then failed="$failed $t"; fi
done
if [ -n "$failed" ]; then
  echo "FAILED:$failed"
  exit 1
fi
echo "all tests passed"
