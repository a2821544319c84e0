#!/usr/bin/env bash
# What a stock lcm-logger records of a demo (docs/runtime.md, "Readers outside the set"): starts
# /usr/bin/lcm-logger as a user would, with no LCM_DEFAULT_URL (the kernel's default receive
# buffer, liblcm's queue of 30), runs ./semx demo, then checks the stock log message by message
# against the demo's RUN/run.lcmlog (its channels: the camera and ESDF_LOCAL only with
# --full-log), counts the datagrams the kernel dropped at the stock logger's socket, and
# evaluates the stock log with ./semx eval.
#
#   tools/stock_logger_check.sh OUT [DEMO-ARGS...]     e.g. tools/stock_logger_check.sh /tmp/stock --time-limit 60
#
# Runs in a private network and mount namespace (needs root, or unshare's user namespaces): no
# other set is heard, and the demo keeps port 7667, where the stock logger listens, however many
# sets other users run. SEMX_FOREIGN_HOLD=0 in the environment turns the set's waiting off.
set -euo pipefail
if [[ $# -lt 1 || "$1" == -* ]]; then
  sed -n '2,13p' "$0" >&2
  exit 2
fi
command -v lcm-logger >/dev/null || { echo "stock_logger_check: no lcm-logger on PATH (apt install liblcm-bin)" >&2; exit 1; }
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(mkdir -p "$1" && cd "$1" && pwd)
shift
rm -rf "$out/run" "$out/stock.lcmlog"
unshare --net --mount bash -s "$root" "$out" "$@" <<'INNER'
set -euo pipefail
root=$1 out=$2
shift 2
ip link set lo up
ip route add 224.0.0.0/4 dev lo
mkdir -p /tmp/semx-ports && mount -t tmpfs tmpfs /tmp/semx-ports
unset LCM_DEFAULT_URL
lcm-logger "$out/stock.lcmlog" >"$out/stock_logger.log" 2>&1 &
logger=$!
sleep 1
cd "$root"
nice -n 10 ./semx demo --out "$out/run" "$@" >"$out/demo.log" 2>&1 || echo "stock_logger_check: the demo exited $? (see $out/demo.log)"
# 1DF3: port 7667; the last column counts the datagrams the kernel dropped at the socket.
awk '$2 ~ /:1DF3$/ {print "kernel drops at the stock logger'"'"'s socket: " $NF}' /proc/net/udp
sleep 1
kill -INT "$logger"
wait "$logger" || true
INNER
python3 - "$out/stock.lcmlog" "$out/run/run.lcmlog" <<'PY'
import collections, struct, sys

def events(path):
    data = open(path, "rb").read()
    i = 0
    while i + 28 <= len(data):
        sync, _, _, cl, dl = struct.unpack_from(">IqqII", data, i)
        if sync != 0xEDA1DA01 or i + 28 + cl + dl > len(data):
            break
        yield data[i + 28:i + 28 + cl].decode(), data[i + 28 + cl:i + 28 + cl + dl]
        i += 28 + cl + dl

stock = collections.Counter(events(sys.argv[1]))
held, missing, frames = collections.Counter(), collections.Counter(), collections.Counter()
for channel, payload in stock:
    frames[channel] += stock[(channel, payload)]
for channel, payload in events(sys.argv[2]):
    held[channel] += 1
    if not stock[(channel, payload)]:
        missing[channel] += 1
print(f"{'channel':20s} {'run.lcmlog':>10s} {'missing':>8s} {'stock':>8s}")
for channel in sorted(set(held) | set(frames)):
    print(f"{channel:20s} {held[channel]:10d} {missing[channel]:8d} {frames[channel]:8d}")
print(f"of the {sum(held.values())} messages run.lcmlog holds, {sum(missing.values())} are not in the stock log")
PY
"$root/semx" eval "$out/stock.lcmlog" --auth-key "$out/run/session.key"
