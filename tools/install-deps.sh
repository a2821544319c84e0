#!/usr/bin/env bash
# Installs every Debian package semx needs. Idempotent: installs only what is missing, so a
# second run costs one dpkg query. Needs root (or sudo) when something is missing.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake pkg-config git ca-certificates
  # messaging: LCM library, lcm-gen, lcm-logger/lcm-logplayer, Java bindings for lcm-spy
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev default-jdk-headless libjchart2d-java
  # maths, maps, perception, config
  libeigen3-dev liboctomap-dev libpcl-dev libopencv-dev libyaml-cpp-dev zlib1g-dev
  libnanoflann-dev liblbfgspp-dev libnlopt-cxx-dev
  # the messages' authentication tags (libcrypto)
  libssl-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # headless display for lcm-spy and viewer checks; process tools for the launcher tests
  xvfb procps iproute2
)

# ROS 1 (Debian's Noetic-era packages) for semx-ros-bridge, rosbag and rviz (docs/ros.md); the
# bridge builds only where they are. SEMX_NO_ROS=1 leaves them out (semx works without them).
ros_packages=(
  libroscpp-dev libtf2-ros-dev libtf2-msgs-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev
  libvisualization-msgs-dev libdiagnostic-msgs-dev
  ros-core python3-rosbag python3-sensor-msgs python3-nav-msgs python3-geometry-msgs python3-visualization-msgs
  python3-diagnostic-msgs python3-tf2-msgs
  rviz
)
[ "${SEMX_NO_ROS:-0}" = 1 ] || packages+=("${ros_packages[@]}")

# One dpkg-query for all of them: every ./semx command runs this first. It exits 1 when dpkg has
# never heard of one of them (a fresh machine), which must not end the script under pipefail.
installed=$({ dpkg-query -W -f='${Package} ${Status}\n' "${packages[@]}" 2>/dev/null || true; } |
  awk '/ install ok installed$/ {print $1}')
missing=()
for p in "${packages[@]}"; do
  grep -qxF "$p" <<<"$installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "semx: installing ${#missing[@]} missing Debian packages: ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
    echo "semx: missing packages and not root (no sudo): ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "semx: packages installed" >&2
