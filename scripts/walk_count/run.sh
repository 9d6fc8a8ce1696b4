#!/usr/bin/env bash
# The code walks of issue 73 (docs/notes/code-walks.md): builds scripts/walk_count/walk_driver.cpp
# against this tree (and, with a second argument, against an older tree's include/ whose planners
# still kept their own evidence: INTERVOX_WALK_API=1), traces a scan into the map, one planning
# step and the planner's decision alone, and prints what scripts/walk_count.py counts.
# Usage: scripts/walk_count/run.sh OUT_DIR [OLD_TREE]     (about 2 minutes a build, 1 a trace)
set -euo pipefail
cd "$(dirname "$0")/../.."
out="${1:?usage: run.sh OUT_DIR [OLD_TREE]}"
mkdir -p "$out"
build() {  # build NAME INCLUDE_DIR API
  g++ -std=c++20 -O0 -g -no-pie -fno-pie -finstrument-functions \
    -finstrument-functions-exclude-file-list=/usr/include,/usr/lib -DINTERVOX_WALK_API="$3" \
    -I"$2" -isystem /usr/include/eigen3 scripts/walk_count/walk_driver.cpp -o "$out/driver_$1" -lpthread
}
trees=(new)
build new include 2
if [ -n "${2:-}" ]; then
  build old "$2/include" 1
  trees=(old new)
fi
args=()
for t in "${trees[@]}"; do
  for mode in frame plan decide; do
    "$out/driver_$t" "$out/trace_${t}_$mode.txt" "$mode"
    args+=("$out/driver_$t" "$out/trace_${t}_$mode.txt")
  done
done
/usr/bin/python3 scripts/walk_count.py --list "${args[@]}"
