#!/bin/sh
# Runs every gtest binary given as arguments and the command-line tests in
# tests/cli/. AFM_BUILD names the build directory (tools in $AFM_BUILD/bin).
#
# AFM_TEST_JOBS tests run at once (default 2, the machine's cores): the suite
# is mostly single-threaded solves, and under the sanitizers it is most of
# CI's time. Each test's output is printed whole when it ends, with its time.
# Every test writes into its own directory, so they do not collide.
set -u
: "${AFM_BUILD:=build}"
export AFM_BUILD
top=$(cd "$(dirname "$0")/.." && pwd)
export AFM_SOURCE_DIR="$top"
: "${AFM_SHARED_DIR:=$top/../shared}"
export AFM_SHARED_DIR
: "${AFM_TEST_JOBS:=2}"
case "$AFM_TEST_JOBS" in
  '' | *[!0-9]* | 0) echo "run-tests.sh: AFM_TEST_JOBS must be a positive number, not '$AFM_TEST_JOBS'"; exit 2 ;;
esac
if [ ! -d "$AFM_SHARED_DIR/data" ]; then
  echo "note: $AFM_SHARED_DIR/data is absent: tests that need the shared data files skip"
fi

# Sanitizer builds: keep LeakSanitizer's list of used suppressions (OSMesa's
# known leaks) out of the output the tests look at.
LSAN_OPTIONS="print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export LSAN_OPTIONS

run="$AFM_BUILD/test-output/run-tests"
rm -rf "$run"
mkdir -p "$run"

# The jobs: name.N holds the test. The longest start first, so that the
# lanes end together: these five take most of the time (under the
# sanitizers, two at a time: 26, 22, 7.1, 1.9 and 1.3 min).
slow="test_anatomy test_fap test_song.sh test_build.sh test_arm.sh"
: >"$run/all"
for t in "$@"; do printf '%s\n' "$t" >>"$run/all"; done
for t in "$top"/tests/cli/*.sh; do [ -e "$t" ] && printf '%s\n' "$t" >>"$run/all"; done
n=0
add() {
  n=$((n + 1))
  printf '%s\n' "$1" >"$run/name.$n"
}
run_one() {
  case "$1" in
    *.sh) sh "$1" ;;
    *) "$1" --gtest_brief=1 ;;
  esac
}
for s in $slow; do
  while IFS= read -r t; do [ "$(basename "$t")" = "$s" ] && add "$t"; done <"$run/all"
done
while IFS= read -r t; do
  case " $slow " in *" $(basename "$t") "*) ;; *) add "$t" ;; esac
done <"$run/all"

# A lane takes the next job nobody has claimed (mkdir is atomic), runs it,
# and prints its output under a lock so that outputs do not interleave.
lane() {
  i=1
  while [ "$i" -le "$n" ]; do
    if mkdir "$run/claim.$i" 2>/dev/null; then
      name=$(cat "$run/name.$i")
      start=$(date +%s)
      run_one "$name" >"$run/out.$i" 2>&1
      rc=$?
      secs=$(($(date +%s) - start))
      echo "$rc" >"$run/rc.$i"
      until mkdir "$run/lock" 2>/dev/null; do sleep 1; done
      echo "== $name (${secs} s)"
      cat "$run/out.$i"
      rmdir "$run/lock"
    fi
    i=$((i + 1))
  done
}

l=0
while [ "$l" -lt "$AFM_TEST_JOBS" ]; do
  lane &
  l=$((l + 1))
done
wait

failed=""
i=1
while [ "$i" -le "$n" ]; do
  if [ "$(cat "$run/rc.$i" 2>/dev/null)" != 0 ]; then failed="$failed $(cat "$run/name.$i")"; fi
  i=$((i + 1))
done
if [ -n "$failed" ]; then
  echo "FAILED:$failed"
  exit 1
fi
echo "all tests passed"
