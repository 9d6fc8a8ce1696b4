#!/usr/bin/env bash
# The whole test suite on a fresh Debian machine: installs missing packages, builds (Release,
# tests at -O2 with _GLIBCXX_ASSERTIONS), runs every test with CTest, the benchmarks' smoke runs
# among them. `--sanitize` builds and runs the tests under ASan/UBSan instead, in build-asan/
# (all but the long episodes and sweeps); `--tsan` the threaded test cases under
# ThreadSanitizer, in build-tsan/.
# The sanitizer builds carry no debug information (-g0: a third less compile time; reports still
# name functions); set INTERVOX_DEBUG_FLAGS=-g for file and line numbers in their reports.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
intervox_install_missing

jobs="$(nproc 2>/dev/null || echo 2)"
debug_flags="${INTERVOX_DEBUG_FLAGS:--g0}"
# Every stage registers each Catch2 test case as a CTest test of its own and runs them on every
# core; what a sanitizer stage builds and runs is chosen by tests/CMakeLists.txt (its "test scope":
# docs/testing.md, "What each stage runs").
if [ "${1:-}" = "--tsan" ]; then
  # ThreadSanitizer over the test cases tagged [threaded] (raycast, plan, sim, core).
  dir="${INTERVOX_BUILD_DIR:-build-tsan}"
  cmake -S . -B "$dir" $(intervox_generator "$dir") -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="$debug_flags" \
    -DINTERVOX_SANITIZE_THREAD=ON -DINTERVOX_BUILD_TESTS=ON -DINTERVOX_BUILD_BENCHMARKS=OFF -DINTERVOX_BUILD_EXAMPLES=OFF
  cmake --build "$dir" -j"$jobs"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1"
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
elif [ "${1:-}" = "--sanitize" ]; then
  # ASan/UBSan over every test case but the long episodes and sweeps ([slow]; the Release stage
  # runs them with _GLIBCXX_ASSERTIONS).
  dir="${INTERVOX_BUILD_DIR:-build-asan}"
  cmake -S . -B "$dir" $(intervox_generator "$dir") -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="$debug_flags" \
    -DINTERVOX_SANITIZE=ON -DINTERVOX_BUILD_TESTS=ON -DINTERVOX_BUILD_BENCHMARKS=OFF -DINTERVOX_BUILD_EXAMPLES=OFF
  cmake --build "$dir" -j"$jobs"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
else
  dir="${INTERVOX_BUILD_DIR:-build}"
  INTERVOX_BUILD_DIR="$dir" intervox_build
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
fi
