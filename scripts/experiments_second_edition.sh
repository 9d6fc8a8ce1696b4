#!/usr/bin/env bash
# The second edition of docs/experiments.md: every sweep of its tables, merged, with the report
# (targets, comparisons with bootstrap intervals, charts). Runs are deterministic per
# configuration and seed, so the split into sweeps does not change them; each sweep resumes
# (an interrupted run of this script continues where it stopped).
#
# Usage: scripts/experiments_second_edition.sh [build dir] [output dir] [seeds] [-- extra experiments options]
#   scripts/experiments_second_edition.sh build out/second 10      # ~45 min on 2 cores
# Writes OUT/results.csv, results.json, tables.md (merged), OUT/report.md (the thesis condition),
# OUT/report-clamped.md and report-gain-all.md (the second conditions), OUT/charts/*.png and
# OUT/figures/*.png (seed 1 of every configuration).
set -euo pipefail
build="${1:-build}"
out="${2:-out/second-edition}"
seeds="${3:-10}"
shift $(( $# < 3 ? $# : 3 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
exe="$build/examples/experiments/experiments"
[ -x "$exe" ] || { echo "experiments_second_edition: $exe not built (bash scripts/setup.sh)" >&2; exit 1; }
mkdir -p "$out"
four=(diffuse absorbing transparent specular)

sweep() {  # NAME OPTIONS...: one sweep into OUT/sweeps/NAME
  local name="$1"
  shift
  echo "== $name: $*"
  "$exe" --out "$out/sweeps/$name" --resume --seeds "$seeds" "$@" "${extra[@]}"
}

# The thesis condition (the defaults: thesis presets, floor removed, gain over unknown voxels).
sweep bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --no-arm
sweep mean --surfaces "${four[@]}" --updates interval-mean --utilities entropy max-entropy --no-arm
sweep bounds-by-rule --surfaces diffuse specular --updates interval-lower interval-upper --utilities max-entropy \
  --unobserved by-rule --no-arm
sweep conflict-aware --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy \
  --planners conflict-aware --no-arm
sweep arm --no-mobile --arm-objects part bottle --arm-updates bayes interval-mean --utilities entropy max-entropy \
  --planners plain conflict-aware
# Second conditions: the library's clamped policies, the first edition's specular model, the gain
# over every voxel, never-observed space left unknown for the lower and upper rules.
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
report="$(dirname "$0")/experiments_report.py"
/usr/bin/python3 "$report" "$out/results.csv" --charts "$out/charts" > "$out/report.md"
# The second conditions' rows, each with its own summary and comparisons.
/usr/bin/python3 "$report" "$out/results.csv" --policies clamped > "$out/report-clamped.md"
/usr/bin/python3 "$report" "$out/results.csv" --gain all > "$out/report-gain-all.md"
echo "experiments_second_edition: $out/results.csv, report*.md, charts/, figures/"
