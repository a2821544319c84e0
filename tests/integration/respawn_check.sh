#!/usr/bin/env bash
# kill -9 of each process of the demo set at a random time of a lockstep run: every run must
# complete, with coverage within 2 points of the undisturbed run, metrics.json written and
# marked disturbed, and no map lost (docs/launch.md, "When a process dies").
#
#   tests/integration/respawn_check.sh [--world env1] [--seed 1] [--rng 1] [--out DIR]
#                                      [--procs "mapper planner ..."] [--build DIR]
#
# One undisturbed run, then one run per process, each killed once when the run's simulated time
# reaches a time drawn uniformly from [1 s, 0.9 Time_f of the undisturbed run] (--rng seeds the
# draws, so a rerun kills at the same simulated times). Prints a table; exit 1 if a run fails a
# check. Runs in a private network namespace when it can (as root), so no other set hears it.
set -uo pipefail
ROOT=$(cd "$(dirname "$(readlink -f "$0")")/../.." && pwd)
. "$ROOT/tests/integration/lib.sh"
semx_private_netns "$0" "$@"
world=env1 seed=1 rng=1 out="" build="$ROOT/build"
procs="mapper planner controller semantics simulator evaluator logger"
while [ $# -gt 0 ]; do
  case "$1" in
    --world) world=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --rng) rng=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --procs) procs=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    *) echo "respawn_check: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || out=$(mktemp -d /tmp/respawn-check.XXXXXX)
mkdir -p "$out"
launch="$build/bin/semx-launch"
[ -x "$launch" ] || { echo "respawn_check: no $launch (build first)" >&2; exit 2; }

# run NAME [PROC AT_S]: a demo run, PROC killed with SIGKILL once the evaluator reports
# simulated time AT_S (its progress line every simulated second).
run() {
  local name=$1 proc=${2:-} at=${3:-} dir="$out/$1"
  rm -rf "$dir" "$dir.console"
  "$launch" demo --no-color --arg "world=$world" --arg "seed=$seed" --arg "out=$dir" --arg progress=1 \
    >"$dir.console" 2>&1 &
  local launcher=$! killed=""
  while kill -0 "$launcher" 2>/dev/null; do
    if [ -n "$proc" ] && [ -z "$killed" ]; then
      local t
      t=$(grep -oP 'semx-evaluator: t=\K[0-9.]+' "$dir.console" | tail -1)
      if [ -n "$t" ] && awk -v t="$t" -v at="$at" 'BEGIN { exit !(t >= at) }'; then
        local pid
        pid=$(grep -oP "\] $proc: started \(pid \K[0-9]+" "$dir.console" | head -1)
        kill -9 "$pid" && killed="$t"
      fi
    fi
    sleep 0.05
  done
  wait "$launcher"
  echo $? >"$dir.rc"
  echo "$killed" >"$dir.killed"
}

run base
base_cov=$(json "$out/base/metrics.json" coverage_pct)
base_tf=$(json "$out/base/metrics.json" time_f_s)
[ -n "$base_cov" ] || { echo "respawn_check: the undisturbed run wrote no metrics.json" >&2; exit 1; }
printf '%-10s %8s %8s %4s %9s %9s %8s %-10s %-13s %s\n' run killed_s restarts rc coverage d_points time_f \
  disturbed termination check
printf '%-10s %8s %8s %4s %9.2f %9s %8.2f %-10s %-13s %s\n' base - 0 "$(cat "$out/base.rc")" "$base_cov" - \
  "$base_tf" "$(json "$out/base/metrics.json" disturbed)" "$(json "$out/base/metrics.json" termination)" -
RANDOM=$rng
failed=0
for p in $procs; do
  at=$(awk -v r="$RANDOM" -v tf="$base_tf" 'BEGIN { printf "%.1f", 1 + (0.9 * tf - 1) * r / 32767 }')
  run "$p" "$p" "$at"
  m="$out/$p/metrics.json" rc=$(cat "$out/$p.rc") killed=$(cat "$out/$p.killed")
  cov="" tf="" dist="" term="" restarts=0 why=""
  if [ -f "$m" ]; then
    cov=$(json "$m" coverage_pct) tf=$(json "$m" time_f_s) dist=$(json "$m" disturbed) term=$(json "$m" termination)
    restarts=$(grep -o '"node": ' "$m" | wc -l)
  fi
  [ "$rc" = 0 ] || why+="exit $rc; "
  [ -f "$m" ] || why+="no metrics.json; "
  [ -n "$killed" ] || why+="never killed; "
  [ "$dist" = true ] || why+="not marked disturbed; "
  case "$term" in planner_done|time_limit) ;; *) why+="ended $term; " ;; esac
  [ -n "$cov" ] && awk -v a="$cov" -v b="$base_cov" 'BEGIN { d = a - b; exit !(d >= -2 && d <= 2) }' ||
    why+="coverage off by more than 2 points; "
  [ -s "$out/$p/map.bt" ] || why+="no map.bt; "
  [ -z "$why" ] || failed=1
  printf '%-10s %8s %8s %4s %9.2f %+9.2f %8s %-10s %-13s %s\n' "$p" "${killed:--}" "$restarts" "$rc" "${cov:-0}" \
    "$(awk -v a="${cov:-0}" -v b="$base_cov" 'BEGIN { print a - b }')" "${tf:--}" "${dist:--}" "${term:--}" \
    "${why:-ok}"
done
echo "runs in $out"
exit $failed
