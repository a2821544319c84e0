#!/usr/bin/env bash
# ./semx bench starts the worlds with the longest time limit first (with --jobs N the short runs
# then fill the end), keeps the comparison before the sweep within a world and seed, and
# --dry-run runs nothing. Usage: bench_order_check.sh SOURCE_DIR
set -uo pipefail
semx="$1/semx"
fail=0
check() {
  local want=$1; shift
  local out rc
  out=$("$semx" bench --dry-run "$@" 2>&1); rc=$?
  if [ "$rc" -ne 0 ] || [ "$out" != "$want" ]; then
    echo "FAIL: ./semx bench --dry-run $* exited $rc with:"
    echo "$out"
    echo "wanted:"
    echo "$want"
    fail=1
  fi
}
check "[1/3] env3-dep-s45-seed1: time limit 900 s
[2/3] env2-dep-s45-seed1: time limit 600 s
[3/3] env1-dep-s45-seed1: time limit 300 s" --worlds env1,env2,env3 --planners dep --seeds 1 --sweep ""
# Equal limits keep the order given; the limit, not the name, decides.
check "[1/4] env1-dep-s45-seed1: time limit 500 s
[2/4] env1-semantic-dep-s30-seed1: time limit 500 s
[3/4] env3-dep-s45-seed1: time limit 60 s
[4/4] env3-semantic-dep-s30-seed1: time limit 60 s" --worlds env3,env1 --planners dep --seeds 1 --sweep 30 \
  --time-limits env1=500,env3=60
check "[1/2] env2-dep-s45-seed1: time limit 120 s
[2/2] env1-dep-s45-seed1: time limit 120 s" --worlds env2,env1 --planners dep --seeds 1 --sweep "" --time-limit 120
# The default sweep is the paper's Table II rows for each world (env3's differ), 45 shared with the
# comparison.
check "[1/5] env3-semantic-dep-s45-seed1: time limit 900 s
[2/5] env3-semantic-dep-s30-seed1: time limit 900 s
[3/5] env3-semantic-dep-s35-seed1: time limit 900 s
[4/5] env3-semantic-dep-s40-seed1: time limit 900 s
[5/5] env3-semantic-dep-s50-seed1: time limit 900 s" --worlds env3 --planners semantic-dep --seeds 1
# Without semantic-dep in the comparison, its 45 is a sweep run.
check "[1/6] env1-dep-s45-seed1: time limit 300 s
[2/6] env1-semantic-dep-s25-seed1: time limit 300 s
[3/6] env1-semantic-dep-s30-seed1: time limit 300 s
[4/6] env1-semantic-dep-s35-seed1: time limit 300 s
[5/6] env1-semantic-dep-s40-seed1: time limit 300 s
[6/6] env1-semantic-dep-s45-seed1: time limit 300 s" --worlds env1 --planners dep --seeds 1
[ "$fail" = 0 ] && echo "bench runs start with the longest time limit"
exit $fail
