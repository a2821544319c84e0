#!/usr/bin/env bash
# The ROS round trip of issue 32 (docs/ros.md): a simulated semx run mirrored to ROS and its
# sensor topics recorded with `rosbag record`; the bag played with `rosbag play` into the
# `external` set (no simulator), whose map must agree with the original run's on >= MIN % of
# the voxels the original knows (semx-map-compare on the two mappers' checkpoints).
#
#   tools/ros/bag_roundtrip.sh OUT_DIR [--world env1] [--time-limit S] [--min PERCENT]
#                              [--ros-port P] [--lcm-port P]
#
# Everything runs on a ROS master of its own (roscore on --ros-port, default 11411 + pid % 500)
# and LCM ports of its own, so it neither needs nor disturbs a running master or set.
set -euo pipefail

ROOT=$(cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/../.." && pwd)
BIN=${SEMX_BIN:-$ROOT/build/bin}
out="" world=env1 time_limit=12 min=99 ros_port=$((11411 + $$ % 500)) lcm_port=$((17000 + ($$ % 500) * 2))
while [ $# -gt 0 ]; do
  case "$1" in
    --world) world=$2; shift 2 ;;
    --time-limit) time_limit=$2; shift 2 ;;
    --min) min=$2; shift 2 ;;
    --ros-port) ros_port=$2; shift 2 ;;
    --lcm-port) lcm_port=$2; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    -*) echo "bag_roundtrip: unknown option '$1'" >&2; exit 2 ;;
    *) out=$1; shift ;;
  esac
done
[ -n "$out" ] || { echo "bag_roundtrip: which OUT_DIR?" >&2; exit 2; }
for tool in roscore rosbag rostopic; do
  command -v $tool >/dev/null || { echo "bag_roundtrip: $tool not installed (tools/install-deps.sh)" >&2; exit 2; }
done
[ -x "$BIN/semx-ros-bridge" ] || { echo "bag_roundtrip: $BIN/semx-ros-bridge not built" >&2; exit 2; }
rm -rf "$out" && mkdir -p "$out/logs" && out=$(readlink -f "$out")

export ROS_MASTER_URI=http://localhost:$ros_port ROS_HOME=$out/ros
url_a="udpm://239.255.76.67:$lcm_port?ttl=0&recv_buf_size=4194304"
url_b="udpm://239.255.76.67:$((lcm_port + 1))?ttl=0&recv_buf_size=4194304"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  sleep 1
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
say() { echo "bag_roundtrip: $*"; }
master_up() { /usr/bin/python3 -c 'import rosgraph,sys; sys.exit(0 if rosgraph.is_master_online() else 1)' 2>/dev/null; }
wait_for() {  # SECONDS COMMAND...: until the command succeeds
  local limit=$1; shift
  for _ in $(seq 1 $((limit * 5))); do "$@" && return 0; sleep 0.2; done
  return 1
}
subscribed() { rostopic info "$1" 2>/dev/null | sed -n '/Subscribers:/,$p' | grep -q '\* /'; }

roscore -p "$ros_port" >"$out/logs/roscore.log" 2>&1 &
pids+=($!)
wait_for 30 master_up || { say "roscore did not come up"; exit 1; }

# 1. The simulated run, mirrored to ROS and recorded. The bridge is not a child of the demo set,
# so it gets the set's key from a file made here (a set accepts only messages signed with its key),
# and the set shares the port the bridge already listens on (by default it would move away).
key_file=$out/session.key
(umask 077; od -An -tx1 -N32 /dev/urandom | tr -d ' \n' >"$key_file"; echo >>"$key_file")
SEMX_AUTH_KEY_FILE=$key_file "$BIN/semx-ros-bridge" --lcm-url "$url_a" >"$out/logs/bridge_mirror.log" 2>&1 &
bridge=$!
pids+=($bridge)
topics=(/semx/odom /tf /tf_static /clock /semx/camera/depth/image_raw /semx/camera/depth/camera_info
        /semx/camera/labels/image_raw /semx/camera/labels/camera_info)
wait_for 30 subscribed /clock 2>/dev/null || true
rosbag record -O "$out/sensors.bag" "${topics[@]}" >"$out/logs/rosbag_record.log" 2>&1 &
recorder=$!
pids+=($recorder)
wait_for 30 subscribed /semx/camera/depth/image_raw || { say "rosbag record did not subscribe"; exit 1; }
sleep 1  # the bridge sees the subscriber within 0.2 s and converts images from then on
say "recording a $time_limit s $world run (real time) to $out/sensors.bag"
"$BIN/semx-launch" demo --lcm-url "$url_a" --auth-key "$key_file" --port-policy share --no-color --arg "world=$world" --arg clock=realtime \
  --arg "time_limit=$time_limit" --arg "out=$out/original" \
  >"$out/logs/demo.log" 2>&1 || { say "the simulated run failed (logs in $out/original/logs)"; tail -20 "$out/logs/demo.log"; exit 1; }
sleep 2
kill -INT "$recorder"; wait "$recorder" || true
# rosbag record is a Python wrapper that passes SIGINT to its recorder child and exits at once; the
# child then closes the bag and renames sensors.bag.active to sensors.bag (a test lost a run to
# reading the bag before that).
bag_closed() { [ -f "$out/sensors.bag" ] && [ ! -e "$out/sensors.bag.active" ]; }
wait_for 30 bag_closed || { say "rosbag record did not close $out/sensors.bag"; exit 1; }
kill -INT "$bridge"; wait "$bridge" || true
# The demo set's mapper checkpoints into the run folder (where a restarted mapper resumes from).
original_ckpt=$out/original/state/mapper.ckpt
[ -f "$original_ckpt" ] || { say "the original run wrote no checkpoint ($original_ckpt)"; exit 1; }
rosbag info "$out/sensors.bag" >"$out/bag_info.txt"
grep -E "^(duration|messages)|image_raw|odom|tf" "$out/bag_info.txt" | sed 's/^/  /'

# 2. The bag into the external set.
"$BIN/semx-launch" external --lcm-url "$url_b" --no-color --log-dir "$out/external_logs" \
  --arg "checkpoint=$out/replayed.ckpt" >"$out/logs/external.log" 2>&1 &
external=$!
pids+=($external)
wait_for 30 subscribed /semx/camera/depth/image_raw || { say "the external bridge did not subscribe"; exit 1; }
sleep 2  # the mapper and the others up
say "playing the bag into the external set"
rosbag play -q --clock "$out/sensors.bag" >"$out/logs/rosbag_play.log" 2>&1
sleep 3  # the last frames integrated
kill -INT "$external"; wait "$external" || true
[ -f "$out/replayed.ckpt" ] || { say "the external mapper wrote no checkpoint"; exit 1; }
grep -h "semx-ros-bridge: published" "$out/external_logs/bridge.log" | sed 's/^/  /' || true

# 3. The maps.
"$BIN/semx-map-compare" "$original_ckpt" "$out/replayed.ckpt" --min "$min" | tee "$out/agreement.txt"
