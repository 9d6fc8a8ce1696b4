#!/usr/bin/env bash
# The third edition of docs/experiments.md: the second edition's configurations, the safe planner
# and the new rooms (the front-only mirror closet, the open door to the annex), under the thesis
# condition and under the library's defaults, with the near-normal glint as a second condition;
# merged, with the report (targets fixed before the runs, comparisons with bootstrap intervals).
# Runs are deterministic per configuration and seed, so the split into sweeps does not change
# them; each sweep resumes (an interrupted run of this script continues where it stopped).
#
# Usage: scripts/experiments_third_edition.sh [build dir] [output dir] [seeds] [-- extra experiments options]
#   scripts/experiments_third_edition.sh build out/third-edition 10
# Writes OUT/results.csv, results.json, tables.md (merged), OUT/report.md (scripts/
# experiments_third_edition_report.py: the targets and the safe planner against the plain one, by
# condition), OUT/report-thesis.md (the second edition's report of the thesis condition on these
# runs), OUT/charts/*.png and OUT/figures/*.png (seed 1 of every configuration).
set -euo pipefail
build="${1:-build}"
out="${2:-out/third-edition}"
seeds="${3:-10}"
shift $(( $# < 3 ? $# : 3 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
exe="$build/examples/experiments/experiments"
[ -x "$exe" ] || { echo "experiments_third_edition: $exe not built (bash scripts/setup.sh)" >&2; exit 1; }
mkdir -p "$out"
four=(diffuse absorbing transparent specular)
# The library's defaults: clamped policies, every return inserted, the gain over every voxel, the
# rig's start rule and hits_block.
library=(--policies clamped --floors kept --gains all --rules library)

sweep() {  # NAME OPTIONS...: one sweep into OUT/sweeps/NAME
  local name="$1"
  shift
  echo "== $name: $*"
  "$exe" --out "$out/sweeps/$name" --resume --seeds "$seeds" "$@" "${extra[@]}"
}
# rooms NAME OPTIONS...: the front-only mirror closet and the annex door (diffuse closet), Bayes +
# entropy and interval-mean + max-entropy, plain and safe.
rooms() {
  local name="$1"
  shift
  sweep "$name-front-only-bayes" --surfaces specular --rooms front-only --updates bayes --utilities entropy --planners plain safe --no-arm "$@"
  sweep "$name-front-only-mean" --surfaces specular --rooms front-only --updates interval-mean --utilities max-entropy --planners plain safe --no-arm "$@"
  sweep "$name-annex-bayes" --surfaces diffuse --rooms annex --updates bayes --utilities entropy --planners plain safe --no-arm "$@"
  sweep "$name-annex-mean" --surfaces diffuse --rooms annex --updates interval-mean --utilities max-entropy --planners plain safe --no-arm "$@"
}

# The thesis condition (the program's defaults: thesis presets, floor removed, gain over unknown
# voxels, the thesis' start and map rules): the second edition's sweeps, the safe planner beside
# the plain one, the new rooms.
sweep bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --planners plain safe --no-arm
sweep mean --surfaces "${four[@]}" --updates interval-mean --utilities entropy max-entropy --no-arm
sweep mean-safe --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy --planners safe --no-arm
sweep bounds-by-rule --surfaces diffuse specular --updates interval-lower interval-upper --utilities max-entropy \
  --unobserved by-rule --no-arm
sweep conflict-aware --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy \
  --planners conflict-aware --no-arm
rooms thesis
sweep arm --no-mobile --arm-objects part bottle --arm-updates bayes interval-mean --utilities entropy max-entropy \
  --planners plain conflict-aware
# The library's defaults: the same closets and rooms, plain and safe.
sweep library-bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --planners plain safe --no-arm "${library[@]}"
sweep library-mean --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy --planners plain safe --no-arm "${library[@]}"
rooms library "${library[@]}"
# Second conditions: the near-normal glint at the mirror (library defaults), and the second
# edition's: clamped policies under the thesis' other conditions, the first edition's specular
# model, the gain over every voxel, never-observed space left unknown for the lower and upper rules.
sweep glint --surfaces specular --rooms lab front-only --updates interval-mean --utilities max-entropy --planners plain safe \
  --sensors glint --no-arm "${library[@]}"
sweep clamped-bayes --surfaces diffuse specular --updates bayes --utilities entropy --policies clamped --no-arm
sweep clamped-mean --surfaces diffuse specular --updates interval-mean --utilities max-entropy --policies clamped --no-arm
sweep random-range-bayes --surfaces specular-random --updates bayes --utilities entropy --no-arm
sweep random-range-mean --surfaces specular-random --updates interval-mean --utilities max-entropy \
  --planners plain conflict-aware --no-arm
sweep gain-all --surfaces diffuse --updates interval-mean --utilities entropy max-entropy --gains all --no-arm
sweep bounds-unknown --surfaces diffuse specular --updates interval-lower interval-upper --utilities max-entropy --no-arm

csvs=()
for d in "$out"/sweeps/*/; do csvs+=("$d/results.csv"); done
"$exe" --out "$out" --tables-from "${csvs[@]}"
mkdir -p "$out/figures"
for d in "$out"/sweeps/*/figures; do cp "$d"/*.png "$out/figures/" 2>/dev/null || true; done
here="$(dirname "$0")"
/usr/bin/python3 "$here/experiments_third_edition_report.py" "$out/results.csv" > "$out/report.md"
/usr/bin/python3 "$here/experiments_report.py" "$out/results.csv" --charts "$out/charts" > "$out/report-thesis.md"
echo "experiments_third_edition: $out/results.csv, report.md, report-thesis.md, charts/, figures/"
