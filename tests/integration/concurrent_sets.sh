#!/usr/bin/env bash
# Two `./semx demo` and a `./semx bench` started together on one machine (issue 31): each run's
# metrics must equal those of the same run alone (lockstep, fixed seeds). Before set isolation,
# a second set on the port ran the other's clock (an office bench run fell from 91.8 % to 25.6 %).
#
#   tests/integration/concurrent_sets.sh [--out DIR] [--time-limit S]
#
# Runs: demo A (env1, seed 1), demo B (env2, seed 1), bench --quick --planners dep (env1, seed 1);
# first each alone, then the three at once, all on the default LCM URL (the launcher moves each
# set to a port of its own and says so). Prints a table; exit 1 if any metric differs. Runs in
# a private network namespace when it can (root), so no other set on the machine takes part.
set -uo pipefail
ROOT=$(cd "$(dirname "$(readlink -f "$0")")/../.." && pwd)
. "$ROOT/tests/integration/lib.sh"
semx_private_netns "$0" "$@"
out="" time_limit=60
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --time-limit) time_limit=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "concurrent_sets: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || out=$(mktemp -d /tmp/concurrent-sets.XXXXXX)
mkdir -p "$out" && out=$(readlink -f "$out")
unset LCM_DEFAULT_URL
say() { echo "concurrent_sets: $*"; }

demo_a() { "$ROOT/semx" demo --world env1 --seed 1 --time-limit "$time_limit" --out "$1" >"$1.console" 2>&1; }
demo_b() { "$ROOT/semx" demo --world env2 --seed 1 --time-limit "$time_limit" --out "$1" >"$1.console" 2>&1; }
bench() {
  "$ROOT/semx" bench --quick --planners dep --time-limit "$time_limit" --out "$1" >"$1.console" 2>&1
}

for phase in alone together; do
  rm -rf "${out:?}/$phase" && mkdir -p "$out/$phase"
  start=$SECONDS
  if [ "$phase" = alone ]; then
    say "each set alone"
    demo_a "$out/alone/demo_a"; demo_b "$out/alone/demo_b"; bench "$out/alone/bench"
  else
    say "the three sets at once"
    demo_a "$out/together/demo_a" & a=$!
    demo_b "$out/together/demo_b" & b=$!
    bench "$out/together/bench" & c=$!
    wait $a $b $c
  fi
  say "$phase: $((SECONDS - start)) s of wall time"
done

grep -h "uses udpm\|another semx set\|talks on port" "$out"/together/*.console 2>/dev/null | sort -u | sed 's/^/  /'
echo
echo "| run | metric | alone | together |"
echo "|---|---|---|---|"
same=1
for run in demo_a demo_b bench; do
  if [ "$run" = bench ]; then
    fa=$(find "$out/alone/bench/runs" -name metrics.json | head -1)
    fb=$(find "$out/together/bench/runs" -name metrics.json | head -1)
  else
    fa=$out/alone/$run/metrics.json fb=$out/together/$run/metrics.json
  fi
  if [ ! -f "$fa" ] || [ ! -f "$fb" ]; then
    say "FAIL: $run wrote no metrics.json (see $out/*/$run*.console)"
    same=0
    continue
  fi
  for k in world time_f_s coverage_pct time_r_s time_o_s distance_m collisions valid; do
    a=$(json "$fa" "$k") b=$(json "$fb" "$k")
    [ "$a" = "$b" ] || same=0
    echo "| $run | $k | $a | $b |"
  done
done
echo
if [ $same -eq 1 ]; then say "PASS: every run's metrics together equal its metrics alone"; else say "FAIL: a run differs"; fi
[ $same -eq 1 ]
