#!/usr/bin/env bash
# ./semx bench --arg: a key the bench sets itself, or no KEY=VALUE, is an error that names the flag
# (before anything is built or run). Every call also names a world file that does not exist, so
# that without the --arg check the bench still stops at its argument checks, with another message
# (the test fails at once instead of starting a bench).
# Usage: bench_args_check.sh SOURCE_DIR
set -uo pipefail
semx="$1/semx"
fail=0
expect_error() {
  local want=$1; shift
  local out rc
  out=$("$semx" bench --worlds /nonexistent/world.yaml "$@" 2>&1); rc=$?
  if [ "$rc" -eq 0 ] || ! grep -qF -- "$want" <<<"$out"; then
    echo "FAIL: ./semx bench $* exited $rc with: $out (wanted '$want')"
    fail=1
  fi
}
expect_error "--arg world=env2: the bench sets 'world' itself" --arg world=env2
expect_error "--arg seed=7: the bench sets 'seed' itself" --planners dep --arg seed=7
expect_error "--arg 'semantics_config': expected KEY=VALUE" --arg semantics_config
expect_error "--arg needs KEY=VALUE" --arg
[ "$fail" = 0 ] && echo "bench --arg errors name the flag"
exit $fail
