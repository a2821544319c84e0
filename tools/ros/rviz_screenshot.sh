#!/usr/bin/env bash
# The picture in docs/ros.md: rviz (tools/ros/semx.rviz) on a live semx run, under Xvfb.
#   tools/ros/rviz_screenshot.sh OUT.png [--world env3] [--after S] [-- demo args]
# Runs ./semx demo --ros (lockstep) in a run folder next to OUT.png, opens rviz on a virtual
# display once the bridge is up, and grabs the screen S wall seconds later (needs xwd from
# x11-apps and netpbm's xwdtopnm, pnmquant, pnmtopng). Its own ROS master port and display.
set -euo pipefail
ROOT=$(cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/../.." && pwd)
png="" world=env3 after=60
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --world) world=$2; shift 2 ;;
    --after) after=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,6p' "$0"; exit 0 ;;
    *) png=$1; shift ;;
  esac
done
[ -n "$png" ] || { echo "rviz_screenshot: which OUT.png?" >&2; exit 2; }
for t in Xvfb xwd xwdtopnm pnmquant pnmtopng rviz; do command -v $t >/dev/null || { echo "rviz_screenshot: $t missing" >&2; exit 2; }; done
png=$(readlink -f "$png")
run="${png%.png}-run"
display=:$((90 + $$ % 9))
export ROS_MASTER_URI=http://localhost:$((11711 + $$ % 200)) ROS_HOME="$run-ros"
pids=()
stop_all() {  # the demo stops its bridge and roscore on SIGINT: give it the time
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for _ in $(seq 1 40); do
    alive=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive = 0 ] && return 0
    sleep 0.5
  done
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
}
trap stop_all EXIT
Xvfb "$display" -screen 0 1400x860x24 >/dev/null 2>&1 &
pids+=($!)
"$ROOT/semx" demo --ros --world "$world" --out "$run" --force "${extra[@]}" >"$run.console" 2>&1 &
demo=$!
pids+=($demo)
for _ in $(seq 1 120); do grep -q "registered with the ROS master" "$run/logs/ros_bridge.log" 2>/dev/null && break; sleep 0.5; done
DISPLAY=$display rviz -d "$ROOT/tools/ros/semx.rviz" >"$run-rviz.log" 2>&1 &
pids+=($!)
sleep "$after"
DISPLAY=$display xwd -root -silent | xwdtopnm 2>/dev/null | pnmquant 256 2>/dev/null | pnmtopng >"$png"
echo "rviz_screenshot: $png ($(wc -c <"$png") bytes); run folder $run"
