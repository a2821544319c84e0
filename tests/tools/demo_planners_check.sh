#!/usr/bin/env bash
# ./semx demo --planner accepts every planner the planner process knows (the list of its config
# error) and names them all when given another. Every call names a world file that does not
# exist, so an accepted planner stops at the world check, before anything is built or run.
# Usage: demo_planners_check.sh SOURCE_DIR BIN_DIR
set -uo pipefail
semx="$1/semx"
known=$("$2/semx-perf-planner" --world env1 --planner no-such-planner 2>&1 | sed -n 's/.*is not one of: //p')
if [ -z "$known" ]; then
  echo "FAIL: no planner list from semx-perf-planner's config error"
  exit 1
fi
fail=0
for p in ${known//,/ }; do
  out=$("$semx" demo --planner "$p" --world /nonexistent/world.yaml 2>&1); rc=$?
  if [ "$rc" -eq 0 ] || ! grep -qF -- "--world '/nonexistent/world.yaml': no such file" <<<"$out"; then
    echo "FAIL: ./semx demo --planner $p exited $rc with: $out (wanted the world error)"
    fail=1
  fi
done
out=$("$semx" demo --planner no-such-planner --world /nonexistent/world.yaml 2>&1); rc=$?
for p in ${known//,/ }; do
  if [ "$rc" -eq 0 ] || ! grep -qF -- "$p" <<<"$out"; then
    echo "FAIL: ./semx demo --planner no-such-planner exited $rc with: $out (wanted '$p' among the names)"
    fail=1
  fi
done
[ "$fail" = 0 ] && echo "demo accepts the planners: $known"
exit $fail
