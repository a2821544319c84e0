#!/usr/bin/env bash
# The generated test set of issue 30: N apartments (semx-world gen) whose areas spread evenly on a
# log scale over 50-600 m² (golden-ratio steps, so every prefix of the set spans the range) with
# about one room per 40 m² (1-14). Nobody tuned a planner to them; the same N gives the same files.
#
#   tools/world-set.sh N DIR     writes DIR/set-K-aAREA-rROOMS.yaml for K = 1..N, prints the paths
set -euo pipefail
if [[ $# -ne 2 || ! "$1" =~ ^[0-9]+$ || "$1" -lt 1 ]]; then
  echo "usage: tools/world-set.sh N DIR" >&2
  exit 2
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
gen="$here/build/bin/semx-world"
[[ -x "$gen" ]] || { echo "tools/world-set.sh: $gen missing (./semx build)" >&2; exit 1; }
mkdir -p "$2"
for ((k = 1; k <= $1; ++k)); do
  read -r area rooms < <(awk -v k="$k" 'BEGIN {
    u = k * 0.6180339887; u -= int(u);
    a = int(50 * exp(u * log(12)) + 0.5);
    v = k * 0.4142135624; v -= int(v);
    r = int(a / 40 * (0.75 + 0.5 * v) + 0.5); if (r < 1) r = 1; if (r > 14) r = 14;
    print a, r }')
  file="$2/set-$k-a$area-r$rooms.yaml"
  [[ -f "$file" ]] || "$gen" gen --seed "$((1000 + k))" --area "$area" --rooms "$rooms" --out "$file" > /dev/null
  echo "$file"
done
