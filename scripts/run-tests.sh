#!/usr/bin/env bash
# The whole test suite on a fresh Debian machine: installs missing packages, builds (Release,
# tests at -O2), runs every test with CTest. `--sanitize` builds and runs them under ASan/UBSan
# instead, in build-asan/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
intervox_install_missing

jobs="$(nproc 2>/dev/null || echo 2)"
if [ "${1:-}" = "--sanitize" ]; then
  dir="${INTERVOX_BUILD_DIR:-build-asan}"
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Debug -DINTERVOX_SANITIZE=ON -DINTERVOX_BUILD_TESTS=ON \
    -DINTERVOX_BUILD_BENCHMARKS=OFF -DINTERVOX_BUILD_EXAMPLES=OFF
  cmake --build "$dir" -j"$jobs"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs" -E "^(consumer|compile_fail)\."
else
  dir="${INTERVOX_BUILD_DIR:-build}"
  INTERVOX_BUILD_DIR="$dir" intervox_build
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
fi
