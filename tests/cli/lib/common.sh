# Sourced by the command-line tests (tests/cli/*.sh). Before sourcing, set
# test_name (it names the output directory and the verdict line). Gives:
#   bin, tmp          $AFM_BUILD/bin, and a fresh $AFM_BUILD/test-output/<test_name>
#   fail MESSAGE      counts a failure
#   expect_error NAME STATUS PATTERN OUTPUT -- COMMAND...
#                     the command exits with STATUS, its stderr matches PATTERN
#                     (grep -E), OUTPUT ('-' for none) does not exist, and no
#                     temporary file is left in $tmp
#   finish [NOTE]     prints the verdict and exits 0 or 1
#   mask_fap3         prints a FAP stream's mask line sending FAP 3 (open_jaw) only
#   fidelity_goals FILE NAME
#                     afm-build's summary line in FILE meets the issue's fidelity
#                     goals (along the FAP's direction median <= 3 %, worst
#                     <= 10 %; off-axis median <= 15 %); prints the figures
set -u
: "${AFM_BUILD:=build}"
bin="$AFM_BUILD/bin"
tmp="$AFM_BUILD/test-output/$test_name"
rm -rf "$tmp"
mkdir -p "$tmp"
failures=0

fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

expect_error() {
  name=$1 status=$2 pattern=$3 output=$4
  shift 5
  "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
  got=$?
  if [ "$got" -ne "$status" ]; then
    fail "$name: exit $got, expected $status"
    sed 's/^/    /' "$tmp/err.txt"
  elif ! grep -Eq -- "$pattern" "$tmp/err.txt"; then
    fail "$name: message does not match '$pattern':"
    sed 's/^/    /' "$tmp/err.txt"
  fi
  if [ "$output" != "-" ] && [ -e "$output" ]; then
    fail "$name: left $output behind"
  fi
  if find "$tmp" -name '*.tmp*' | grep -q .; then
    fail "$name: left a temporary file: $(find "$tmp" -name '*.tmp*')"
  fi
}

mask_fap3() {
  printf '0 0 1'
  i=4
  while [ $i -le 68 ]; do
    printf ' 0'
    i=$((i + 1))
  done
  printf '\n'
}

fidelity_goals() {
  line=$(grep '^targets: ' "$1")
  [ -n "$line" ] || { fail "$2: no summary line: $(tail -n 3 "$1")"; return; }
  echo "$line" | awk -v name="$2" '{
      if (!match($0, /along the direction median [0-9.]+% worst [0-9.]+%; off-axis median [0-9.]+%/)) {
        print "FAIL: " name ": no along and off-axis figures: " $0; exit 1 }
      split(substr($0, RSTART, RLENGTH), w, /[ %;]+/)
      median = w[5]; worst = w[7]; off = w[10]
      printf "%s: along the direction median %s %%, worst %s %%; off-axis median %s %%\n", name, median, worst, off
      if (median > 3 || worst > 10 || off > 15) {
        print "FAIL: " name ": the goals are median <= 3 %, worst <= 10 %, off-axis median <= 15 %"; exit 1 }
    }' || failures=$((failures + 1))
}

finish() {
  if [ "$failures" -ne 0 ]; then
    echo "$test_name: $failures failure(s)"
    exit 1
  fi
  echo "$test_name: all passed${1:+ ($1)}"
  exit 0
}
