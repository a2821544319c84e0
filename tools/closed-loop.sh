#!/usr/bin/env bash
# Planners compared in the closed loop (semx-perf-planner: ideal vehicle and camera, emulated
# semantics, no processes), one run folder per world, planner and seed, then semx-bench-report's
# tables (paired by world and seed, 95 % intervals) with OURS against every other planner.
#
#   tools/closed-loop.sh OUT OURS PLANNERS SEEDS WORLD... [-- PERF-PLANNER-ARGS...]
#     OUT       output folder (runs already there are kept: an interrupted comparison continues)
#     OURS      the planner the others are compared with
#     PLANNERS  comma-separated, e.g. dep,semantic-dep,semantic-room
#     SEEDS     seeds 1..SEEDS per world
#     WORLD     env1|env2|env3 or a world file (tools/world-set.sh writes the generated set)
#   e.g. tools/closed-loop.sh /tmp/cmp semantic-dep dep,semantic-dep 3 env2 env3 -- --max-time 600
set -euo pipefail
if [[ $# -lt 5 ]]; then
  sed -n '2,12p' "$0" >&2
  exit 2
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${SEMX_BUILD_DIR:-$here/build}/bin"  # as ./semx: SEMX_BUILD_DIR picks another build
out="$1" ours="$2" planners="$3" seeds="$4"
shift 4
worlds=()
while [[ $# -gt 0 && "$1" != "--" ]]; do worlds+=("$1"); shift; done
[[ $# -gt 0 ]] && shift
extra=("$@")
mkdir -p "$out/runs"
IFS=, read -r -a plist <<< "$planners"
for w in "${worlds[@]}"; do
  for p in "${plist[@]}"; do
    for ((s = 1; s <= seeds; ++s)); do
      stamp="$out/done/$(basename "$w" .yaml)-$p-seed$s"
      [[ -f "$stamp" ]] && continue
      "$bin/semx-perf-planner" --world "$w" --planner "$p" --seed "$s" --runs 1 --semantics \
        --time-split --out "$out" "${extra[@]}" > "$out/last.log" 2>&1 || { cat "$out/last.log" >&2; exit 1; }
      grep -E '^run_(T_coverage|T_time_o|collisions|end):' "$out/last.log" | tr '\n' ' ' | sed "s|^|$(basename "$w" .yaml) $p seed $s: |"
      echo
      mkdir -p "$out/done" && touch "$stamp"
    done
  done
done
"$bin/semx-bench-report" "$out" --sweep-planner "$ours" > /dev/null
echo "tools/closed-loop.sh: $out/tables.md"
