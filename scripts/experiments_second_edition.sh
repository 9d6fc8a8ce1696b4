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
source "$(dirname "$0")/experiments_sweeps.sh"

# The thesis condition (the defaults: thesis presets, floor removed, gain over unknown voxels).
sweep bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --no-arm
sweep mean --surfaces "${four[@]}" --updates interval-mean --utilities entropy max-entropy --no-arm
second_edition_rest
merge_sweeps
report="$(dirname "$0")/experiments_report.py"
/usr/bin/python3 "$report" "$out/results.csv" --charts "$out/charts" > "$out/report.md"
# The second conditions' rows, each with its own summary and comparisons.
/usr/bin/python3 "$report" "$out/results.csv" --policies clamped > "$out/report-clamped.md"
/usr/bin/python3 "$report" "$out/results.csv" --gain all > "$out/report-gain-all.md"
echo "experiments_second_edition: $out/results.csv, report*.md, charts/, figures/"
