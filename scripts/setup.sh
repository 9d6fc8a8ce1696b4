#!/usr/bin/env bash
# Installs what Intervox needs from Debian's packages, only what is missing, then configures and
# builds into build/ (or $INTERVOX_BUILD_DIR). Sourced by run-demo.sh and run-tests.sh; may be run alone.
set -euo pipefail

INTERVOX_PACKAGES=(g++ make cmake ninja-build libeigen3-dev catch2 libbenchmark-dev liboctomap-dev libpng-dev
                   libcli11-dev nlohmann-json3-dev libzstd-dev pybind11-dev python3-dev python3-numpy
                   python3-pytest python3-distributed python3-matplotlib libjs-three chromium
                   clang-format-14)
# The optional ROS 1 programs (ros/, docs/ros.md) and their tests: Debian's own ROS 1 packages (the
# node and bag tool's headers and libraries, the master for the node test, rosbag, tf2's Python
# binding, the message classes and scipy's rotations for intervox.ros_bag and its test). About
# 127 packages, 12.6 MB to download, 86 MB installed.
INTERVOX_ROS_PACKAGES=(pkg-config libroscpp-dev librosbag-storage-dev libtf2-ros-dev libsensor-msgs-dev libnav-msgs-dev
                       libvisualization-msgs-dev libstd-srvs-dev libgeometry-msgs-dev python3-rosmaster python3-rosbag
                       python3-tf2 python3-sensor-msgs python3-tf2-msgs python3-geometry-msgs python3-scipy)

intervox_install_missing() {
  local missing=()
  for pkg in "${INTERVOX_PACKAGES[@]}" "${INTERVOX_ROS_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "intervox: all packages present"
    return 0
  fi
  echo "intervox: installing ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      echo "intervox: need root (or sudo) to install: ${missing[*]}" >&2
      return 1
    fi
  fi
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

# intervox_generator DIR: "-G Ninja" for a build folder not configured yet when ninja is there
# (it schedules both cores better than make); nothing for a configured folder, which keeps its own.
intervox_generator() {
  if [ ! -f "$1/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then echo "-G Ninja"; fi
}

# intervox_build [extra cmake args...]: configure (Release) and build everything.
intervox_build() {
  local dir="${INTERVOX_BUILD_DIR:-build}"
  local jobs
  jobs="$(nproc 2>/dev/null || echo 2)"
  # Explicit ON: a build folder configured otherwise before (by hand) must not silently drop tests.
  cmake -S . -B "$dir" $(intervox_generator "$dir") -DCMAKE_BUILD_TYPE=Release -DINTERVOX_BUILD_TESTS=ON -DINTERVOX_BUILD_EXAMPLES=ON \
    -DINTERVOX_BUILD_BENCHMARKS=ON "$@"
  cmake --build "$dir" -j"$jobs"
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  cd "$(dirname "$0")/.."
  intervox_install_missing
  intervox_build "$@"
fi
