#!/usr/bin/env bash
# The main job on a fresh Debian machine: installs missing packages, builds, and runs the
# mobile exploration demo with its built-in defaults. Extra arguments go to the demo
# (see `build/examples/mobile_exploration/mobile_exploration --help`).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
intervox_install_missing
dir="${INTERVOX_BUILD_DIR:-build}"
# Same configuration as run-tests.sh (so the two share build/), but only the demo is built.
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DINTERVOX_BUILD_TESTS=ON -DINTERVOX_BUILD_EXAMPLES=ON \
  -DINTERVOX_BUILD_BENCHMARKS=ON
cmake --build "$dir" -j"$(nproc 2>/dev/null || echo 2)" --target mobile_exploration
"$dir/examples/mobile_exploration/mobile_exploration" "$@"
