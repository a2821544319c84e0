#!/usr/bin/env bash
# Runs one test binary's tests N times on a loaded machine and counts the failures: a test that
# passes alone and fails under CI's load (ctest -j2 beside other processes) shows here. The load:
# two busy loops and a disk writer (200 MB written with fsync, over and over), as long as the runs
# last. Each failing run's output is kept as OUT/run-K.log.
#
#   tools/stress-test.sh OUT N TEST-BINARY [GTEST-FILTER]
#   e.g. tools/stress-test.sh /tmp/stress 30 build/tests/test_processes Processes.StockLcmLoggerRecordsALockstepSetWhole
#
# Not run by CI (it is a measurement, minutes long). Exit status: 0 when every run passed.
set -u
if [ $# -lt 3 ]; then
  sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
out=$1 n=$2 bin=$3 filter=${4:-*}
case $n in '' | *[!0-9]*)
  echo "stress-test.sh: N '$n': expected a number of runs" >&2
  exit 2
  ;;
esac
if [ ! -x "$bin" ]; then
  echo "stress-test.sh: $bin: not an executable test binary" >&2
  exit 2
fi
mkdir -p "$out" || exit 2
load_file=$(mktemp "$out/load.XXXXXX") || exit 2
pids=()
cleanup() {
  [ ${#pids[@]} -gt 0 ] && kill "${pids[@]}" 2>/dev/null
  wait 2>/dev/null
  rm -f "$load_file"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
for _ in 1 2; do
  (while :; do :; done) &
  pids+=($!)
done
(while :; do dd if=/dev/zero of="$load_file" bs=1M count=200 conv=fsync 2>/dev/null; done) &
pids+=($!)
pass=0 fail=0
for k in $(seq 1 "$n"); do
  if "$bin" --gtest_filter="$filter" > "$out/run-$k.log" 2>&1; then
    pass=$((pass + 1))
    rm -f "$out/run-$k.log"
  else
    fail=$((fail + 1))
    echo "run $k failed: $out/run-$k.log"
    grep -m2 -A1 "Failure" "$out/run-$k.log"
  fi
  printf '\r%d of %d runs, %d failed' "$k" "$n" "$fail" >&2
done
echo >&2
echo "$bin --gtest_filter=$filter under load: $pass passed, $fail failed of $n"
[ "$fail" -eq 0 ]
