#!/usr/bin/env bash
# ./semx's udp_drops reads RcvbufErrors from /proc/net/snmp by its header (the column order is
# the kernel's), prints nothing where the counter is missing, and so the bench and the demo warn
# only when it grew. Usage: udp_drops_check.sh SOURCE_DIR
set -uo pipefail
eval "$(sed -n '/^udp_drops() {/,/^}/p; /^warn_udp_drops() {/,/^}/p' "$1/semx")"
declare -F udp_drops warn_udp_drops >/dev/null || { echo "FAIL: no udp_drops() or warn_udp_drops() in $1/semx"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
expect() {
  local want=$1 file=$2 got
  got=$(SEMX_SNMP="$file" udp_drops)
  if [ "$got" != "$want" ]; then echo "FAIL: udp_drops on $file gave '$got', wanted '$want'"; fail=1; fi
}
printf 'Ip: Forwarding DefaultTTL\nIp: 1 64\nUdp: InDatagrams NoPorts InErrors OutDatagrams RcvbufErrors SndbufErrors\nUdp: 635064952 0 307307 104921302 307307 0\nUdpLite: InDatagrams RcvbufErrors\nUdpLite: 0 5\n' >"$tmp/snmp"
expect 307307 "$tmp/snmp"
printf 'Udp: RcvbufErrors InDatagrams\nUdp: 12 99\n' >"$tmp/reordered"
expect 12 "$tmp/reordered"
printf 'Udp: InDatagrams NoPorts\nUdp: 1 2\n' >"$tmp/old-kernel"
expect "" "$tmp/old-kernel"
expect "" "$tmp/missing"
# The warning and udp_drops.txt only when the counter grew.
mkdir -p "$tmp/run"
out=$(warn_udp_drops 10 13 "$tmp/run" "[1/2] run")
if [ "$(cat "$tmp/run/udp_drops.txt" 2>/dev/null)" != 3 ] || [[ "$out" != "[1/2] run: warning: the kernel dropped 3 "* ]]; then
  echo "FAIL: warn_udp_drops 10 13 wrote '$(cat "$tmp/run/udp_drops.txt" 2>/dev/null)' and said '$out'"; fail=1
fi
for pair in "13 13" "" "5 "; do
  rm -f "$tmp/run/udp_drops.txt"
  read -r a b <<<"$pair"
  out=$(warn_udp_drops "${a:-}" "${b:-}" "$tmp/run" run)
  if [ -n "$out" ] || [ -e "$tmp/run/udp_drops.txt" ]; then echo "FAIL: warn_udp_drops '$pair' said '$out'"; fail=1; fi
done
[ "$fail" = 0 ] && echo "udp_drops reads RcvbufErrors by its header"
exit $fail
