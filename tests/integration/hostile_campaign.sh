#!/usr/bin/env bash
# The hostile-input campaign of issue 31 (docs/runtime.md, "Who may talk"): a lockstep demo run
# while semx-hostile processes throw every kind of hostile message at every channel, against the
# same run undisturbed. Passes when no process of the set crashed, the attacked run's metrics are
# the undisturbed run's (so no spoofed, replayed or malformed message changed anything), and at
# least --min messages were sent. Prints each process's peak RSS (the launcher reports it when a
# process exits) beside the undisturbed run's.
#
#   tests/integration/hostile_campaign.sh [--world env1] [--seed 1] [--time-limit 60]
#       [--min 100000] [--streams 4] [--rate 3000] [--batch 600] [--out DIR] [--build DIR]
#
# Senders, per channel, in turn (--streams of them at once, each at --rate messages/s):
#   insider:  signed with the set's key: truncated, oversized, negative and huge array lengths,
#             wrong fingerprints, random bytes, and NaN/inf fields (the nodes' decoders and checks);
#   unsigned, foreign (another set's key): all of those, bit flips and extreme values (utime
#             INT64_MAX, far-future ticks, DONE, EPISODE_END, COLLISION counts);
#   replay:   the set's own messages on the channel, sent again unchanged;
#   tamper:   the same with one payload byte changed.
# Insider bit flips and extreme values are left out: a process with the key may say anything
# (the threat model, docs/runtime.md). Runs in a private network namespace when it can (root).
set -uo pipefail
ROOT=$(cd "$(dirname "$(readlink -f "$0")")/../.." && pwd)
. "$ROOT/tests/integration/lib.sh"
semx_private_netns "$0" "$@"
world=env1 seed=1 time_limit=60 min=100000 streams=4 rate=3000 batch=600 out="" build="$ROOT/build"
while [ $# -gt 0 ]; do
  case "$1" in
    --world) world=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --time-limit) time_limit=$2; shift 2 ;;
    --min) min=$2; shift 2 ;;
    --streams) streams=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --batch) batch=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    *) echo "hostile_campaign: unknown option '$1'" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || out=$(mktemp -d /tmp/hostile-campaign.XXXXXX)
mkdir -p "$out" && out=$(readlink -f "$out")
launch="$build/bin/semx-launch" hostile="$build/bin/semx-hostile"
for b in "$launch" "$hostile"; do [ -x "$b" ] || { echo "hostile_campaign: no $b (build first)" >&2; exit 2; }; done
say() { echo "hostile_campaign: $*"; }

# run NAME: a lockstep demo run in OUT/NAME (console in OUT/NAME.console); returns its exit code.
run() {
  local dir="$out/$1"
  rm -rf "$dir" "$dir.console" "$out/$1.key"
  "$launch" demo --no-color --key-out "$out/$1.key" --arg "world=$world" --arg "seed=$seed" \
    --arg "time_limit=$time_limit" --arg "out=$dir" >"$dir.console" 2>&1
}

# attack STREAM: sends batches to every channel in turn until OUT/attack.stop exists.
channels=($("$hostile" --list | cut -d' ' -f1))
attack() {
  local stream=$1 round=0 c k=0 cmd
  local -a senders=(
    "--as insider --kinds truncated,oversized,negative-length,huge-length,wrong-fingerprint,random-bytes,non-finite"
    "--as unsigned --kinds every"
    "--as foreign --kinds every"
    "--as replay --capture-timeout 0.5"
    "--as tamper --capture-timeout 0.5")
  while [ ! -e "$out/attack.stop" ]; do
    for c in "${channels[@]}"; do
      [ -e "$out/attack.stop" ] && break
      # The streams start at different channels and senders, so every pair is hit early.
      cmd=${senders[$(( (k + stream) % ${#senders[@]} ))]}
      k=$((k + 1))
      local n=$batch
      case "$cmd" in *kinds*) n=$(( (batch + 8) / 9 )) ;; esac
      # shellcheck disable=SC2086
      "$hostile" --name "hostile-$stream" --quiet --channel "$c" $cmd --count "$n" --rate "$rate" \
        --seed $((stream * 100000 + round * 100 + k)) >>"$out/attack-$stream.log" 2>&1
    done
    round=$((round + 1))
  done
}

say "undisturbed run ($world, seed $seed, lockstep) in $out/clean"
run clean || { say "the undisturbed run failed (see $out/clean.console)"; exit 1; }
drops0=$(awk '/^Udp:/ { n++; if (n == 2) print $6 }' /proc/net/snmp)
say "attacked run in $out/attacked: $streams streams at $rate messages/s over ${#channels[@]} channels"
rm -f "$out/attack.stop" "$out"/attack-*.log
(
  # The set's key, once the launcher has written it: the insider and the copying senders need it.
  for _ in $(seq 200); do [ -s "$out/attacked.key" ] && break; sleep 0.05; done
  export SEMX_AUTH_KEY_FILE=$out/attacked.key
  for s in $(seq 1 "$streams"); do attack "$s" & done
  wait
) &
attackers=$!
rc=0
run attacked || rc=$?
touch "$out/attack.stop"
wait "$attackers"
drops1=$(awk '/^Udp:/ { n++; if (n == 2) print $6 }' /proc/net/snmp)

sent=$(cat "$out"/attack-*.log 2>/dev/null | awk '/semx-hostile: sent/ { s += $3 } END { print s + 0 }')
crashes=$(grep -cE "killed by signal|restart [0-9]+/" "$out/attacked.console")
echo
echo "| | undisturbed | attacked |"
echo "|---|---|---|"
same=1
for k in time_f_s coverage_pct time_r_s time_o_s distance_m collisions termination valid disturbed; do
  a=$(json "$out/clean/metrics.json" "$k")
  b=$(json "$out/attacked/metrics.json" "$k" 2>/dev/null)
  [ "$a" = "$b" ] || same=0
  echo "| $k | $a | $b |"
done
for p in simulator mapper semantics planner controller evaluator logger; do
  a=$(grep -oP "\] $p: exited with [0-9]+ \(peak RSS \K[0-9]+" "$out/clean.console" | tail -1)
  b=$(grep -oP "\] $p: exited with [0-9]+ \(peak RSS \K[0-9]+" "$out/attacked.console" | tail -1)
  echo "| peak RSS $p (MB) | ${a:-?} | ${b:-?} |"
done
echo
say "hostile messages sent: $sent (at least $min asked); kernel receive-buffer drops during the attack: $((drops1 - drops0))"
ok=1
[ "$rc" -eq 0 ] || { say "FAIL: the attacked run's launcher exited $rc"; ok=0; }
[ "$crashes" -eq 0 ] || { say "FAIL: $crashes process crashes or restarts in the attacked run"; ok=0; }
[ "$same" -eq 1 ] || { say "FAIL: the attacked run's metrics differ from the undisturbed run's"; ok=0; }
[ "$sent" -ge "$min" ] || { say "FAIL: only $sent hostile messages sent"; ok=0; }
[ $ok -eq 1 ] && say "PASS: no crash, the same metrics, $sent hostile messages refused or dropped"
[ $ok -eq 1 ]
