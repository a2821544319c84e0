#!/usr/bin/env bash
# lcm-spy, started as ./semx spy starts it, finds every semx type in the jar under Xvfb.
# Usage: spy_check.sh BUILD_DIR EXPECTED_TYPES
set -euo pipefail
build=$1
expected=$2
command -v xvfb-run >/dev/null || { echo "xvfb-run missing (package xvfb)"; exit 1; }
out=$(mktemp)
trap 'rm -f "$out"' EXIT
# The same classpath as ./semx spy; timeout ends the window after it has loaded its types.
CLASSPATH="$build/share/semx_types.jar" timeout 12 xvfb-run -a \
  java -cp "/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar:$build/share/semx_types.jar" \
  lcm.spy.Spy --lcm-url="udpm://239.255.76.67:$((21000 + $$ % 1000))?ttl=0" >"$out" 2>&1 || true
cat "$out"
grep -q "Found $expected LCM types" "$out" || { echo "FAIL: expected 'Found $expected LCM types'"; exit 1; }
if grep -qiE "exception|error" "$out"; then echo "FAIL: lcm-spy reported an error"; exit 1; fi
echo "lcm-spy loaded $expected semx types"
