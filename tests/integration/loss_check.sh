#!/usr/bin/env bash
# A lockstep run on a lossy bus is the run of a lossless one (docs/runtime.md, "Lost messages"):
# the demo set twice, clean and with every process dropping a share of its datagrams
# (SEMX_TEST_DROP_RATE), and their metrics.json compared figure by figure.
#
#   tests/integration/loss_check.sh [--world env1] [--seed 1] [--time-limit 60] [--drop 0.1]
#                                   [--drop-seed 3] [--planner semantic-dep] [--out DIR] [--build DIR]
#                                   [--clock lockstep|realtime] [--jitter MS] [--tolerance PTS]
#
# Lockstep: exit 0 when coverage, object coverage, Time_f, Time_r, Time_o, distance, collisions and
# the termination are equal and the lossy run is valid (no message lost for good); 1 otherwise.
# Realtime (`--clock realtime`, where no two runs are equal): exit 0 when the lossy run's coverage
# is within --tolerance points (2) of the clean run's and it is valid. `--jitter MS` also delays
# each datagram by up to MS milliseconds, out of order (SEMX_TEST_JITTER_MS). Also
# checks that each process of the lossy run asked for messages again (SIM_RESEND in run.lcmlog):
# the drop reached it. Runs in a private network namespace when it can (as root), so no other
# set hears it; otherwise the launcher's bus claim gives the set a port of its own.
set -uo pipefail
ROOT=$(cd "$(dirname "$(readlink -f "$0")")/../.." && pwd)
. "$ROOT/tests/integration/lib.sh"
semx_private_netns "$0" "$@"
world=env1 seed=1 time_limit=60 drop=0.1 drop_seed=3 planner=semantic-dep out="" build="$ROOT/build"
clock=lockstep jitter=0 tolerance=2
while [ $# -gt 0 ]; do
  case "$1" in
    --world) world=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --time-limit) time_limit=$2; shift 2 ;;
    --drop) drop=$2; shift 2 ;;
    --drop-seed) drop_seed=$2; shift 2 ;;
    --planner) planner=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --clock) clock=$2; shift 2 ;;
    --jitter) jitter=$2; shift 2 ;;
    --tolerance) tolerance=$2; shift 2 ;;
    *) echo "loss_check: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || out=$(mktemp -d /tmp/loss-check.XXXXXX)
mkdir -p "$out"
case "$clock" in lockstep|realtime) ;; *) echo "loss_check: --clock '$clock': expected lockstep or realtime" >&2; exit 2 ;; esac
launch="$build/bin/semx-launch"
[ -x "$launch" ] || { echo "loss_check: no $launch (build first)" >&2; exit 2; }

run() {  # run NAME [ENV=VALUE ...]
  local name=$1 dir="$out/$1"
  shift
  rm -rf "$dir"
  env "$@" "$launch" demo --no-color --arg "world=$world" --arg "seed=$seed" --arg "planner=$planner" \
    --arg "time_limit=$time_limit" --arg "clock=$clock" --arg "out=$dir" >"$dir.console" 2>&1
  echo $? >"$dir.rc"
}

run clean
run lossy SEMX_TEST_DROP_RATE="$drop" SEMX_TEST_DROP_SEED="$drop_seed" SEMX_TEST_JITTER_MS="$jitter"

failed=0
keys="coverage_pct object_coverage_pct time_f_s time_r_s time_o_s distance_m collisions termination"
printf '%-20s %16s %16s %s\n' figure clean "lossy ($drop, ${jitter} ms)" check
for k in $keys valid wall_s; do
  a=$(json "$out/clean/metrics.json" "$k" 2>/dev/null) b=$(json "$out/lossy/metrics.json" "$k" 2>/dev/null)
  check=ok
  case "$k" in
    wall_s) check="-" ;;
    valid) [ "$b" = true ] || { check="lossy run not valid"; failed=1; } ;;
    coverage_pct) if [ "$clock" = realtime ]; then
        awk -v a="${a:-0}" -v b="${b:-0}" -v t="$tolerance" 'BEGIN { exit !(a != "" && b != "" && a - b <= t && b - a <= t) }' ||
          { check="more than $tolerance points apart"; failed=1; }
      else
        [ -n "$a" ] && [ "$a" = "$b" ] || { check=DIFFERENT; failed=1; }
      fi ;;
    *) if [ "$clock" = realtime ]; then check="-"; else [ -n "$a" ] && [ "$a" = "$b" ] || { check=DIFFERENT; failed=1; }; fi ;;
  esac
  printf '%-20s %16s %16s %s\n' "$k" "${a:--}" "${b:--}" "$check"
done
for r in clean lossy; do
  [ "$(cat "$out/$r.rc")" = 0 ] || { echo "loss_check: the $r run exited with $(cat "$out/$r.rc")"; failed=1; }
done
# Who asked for messages again: every process that lost some (resend_t: utime, then the node's name).
python3 - "$out/lossy/run.lcmlog" <<'EOF' || failed=1
import collections, struct, sys
asked = collections.Counter()
data = open(sys.argv[1], 'rb').read()
pos = 0
while pos + 28 <= len(data):
    sync, _, _, cl, dl = struct.unpack('>IqqII', data[pos:pos + 28])
    if sync != 0xEDA1DA01:
        break
    ch = data[pos + 28:pos + 28 + cl].decode()
    p = data[pos + 28 + cl:pos + 28 + cl + dl]
    pos += 28 + cl + dl
    if ch == 'SIM_RESEND' and len(p) >= 20:
        n = struct.unpack('>i', p[16:20])[0]
        asked[p[20:20 + n - 1].decode(errors='replace')] += 1
print('SIM_RESEND requests in the lossy run:', ', '.join('%s %d' % kv for kv in sorted(asked.items())))
missing = {'simulator', 'mapper', 'semantics', 'planner', 'controller', 'evaluator'} - set(asked)
if missing:
    print('loss_check: never asked for a message again (did the drop reach them?):', ', '.join(sorted(missing)))
    sys.exit(1)
EOF
echo "runs in $out"
exit $failed
