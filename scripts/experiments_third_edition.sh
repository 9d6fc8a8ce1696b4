#!/usr/bin/env bash
# The third edition of docs/experiments.md: the second edition's configurations, the safe planner
# and the new rooms (the front-only mirror closet, the open door to the annex), under the thesis
# condition and under the library's defaults, with the near-normal glint, the robot seen in the
# mirror and one forward camera as second conditions;
# merged, with the report (targets fixed before the runs, comparisons with bootstrap intervals).
# Runs are deterministic per configuration and seed, so the split into sweeps does not change
# them; each sweep resumes (an interrupted run of this script continues where it stopped).
#
# Usage: scripts/experiments_third_edition.sh [build dir] [output dir] [seeds] [-- extra experiments options]
#   scripts/experiments_third_edition.sh build out/third-edition 10
# Writes OUT/results.csv, results.json, tables.md (merged), OUT/planted/*.txt (the planted scenes),
# OUT/arm_normals.csv and report-arm-normals.md (the polished part's explained model),
# OUT/report.md (scripts/
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
source "$(dirname "$0")/experiments_sweeps.sh"
# The library's defaults: clamped policies, every return inserted, the gain over every voxel, the
# rig's start rule and hits_block.
library=(--policies clamped --floors kept --gains all --rules library)

# room NAME SURFACE ROOM UPDATE UTILITY OPTIONS...: the plain and the safe planner in one of the new
# rooms (the front-only mirror closet, the door to the annex with the diffuse closet).
room() {
  local name="$1" surface="$2" where="$3" update="$4" utility="$5"
  shift 5
  sweep "$name" --surfaces "$surface" --rooms "$where" --updates "$update" --utilities "$utility" --planners plain safe \
    --no-arm "$@"
}

# In the order of what the targets need first (an interrupted run has those; the sweeps are
# independent, so the order changes no run). The thesis condition is the program's defaults
# (thesis presets, floor removed, gain over unknown voxels, the thesis' start and map rules).
# 1. Interval-mean, plain and safe, under both conditions, in the lab closets and the new rooms.
sweep mean --surfaces "${four[@]}" --updates interval-mean --utilities entropy max-entropy --no-arm
sweep mean-safe --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy --planners safe --no-arm
room thesis-front-only-mean specular front-only interval-mean max-entropy
room thesis-annex-mean diffuse annex interval-mean max-entropy
sweep library-mean --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy --planners plain safe --no-arm "${library[@]}"
room library-front-only-mean specular front-only interval-mean max-entropy "${library[@]}"
room library-annex-mean diffuse annex interval-mean max-entropy "${library[@]}"
# 2. Bayes, plain and safe, the same.
sweep bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --planners plain safe --no-arm
room thesis-front-only-bayes specular front-only bayes entropy
room thesis-annex-bayes diffuse annex bayes entropy
sweep library-bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --planners plain safe --no-arm "${library[@]}"
room library-front-only-bayes specular front-only bayes entropy "${library[@]}"
room library-annex-bayes diffuse annex bayes entropy "${library[@]}"
# 3. The near-normal glint at the mirror (library defaults), and the rest of the second edition:
# the lower and upper rules, the conflict-aware planner, the arm, and its second conditions
# (clamped policies under the thesis' other conditions, the first edition's specular model, the
# gain over every voxel, never-observed space left unknown for the lower and upper rules).
sweep glint --surfaces specular --rooms lab front-only --updates interval-mean --utilities max-entropy --planners plain safe \
  --sensors glint --no-arm "${library[@]}"
# The robot seen in the mirror (sim::SimOptions::body: reflected beams meet the robot's own body),
# library defaults, both updates.
sweep body-mean --surfaces specular --rooms lab front-only --updates interval-mean --utilities max-entropy \
  --planners plain safe --sensors body --no-arm "${library[@]}"
sweep body-bayes --surfaces specular --rooms lab front-only --updates bayes --utilities entropy \
  --planners plain safe --sensors body --no-arm "${library[@]}"
# One forward camera (target 9), library defaults, the five closets, both updates.
sweep one-camera-mean --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy --planners plain safe \
  --sensors one-camera --no-arm "${library[@]}"
room one-camera-front-only-mean specular front-only interval-mean max-entropy --sensors one-camera "${library[@]}"
sweep one-camera-bayes --surfaces "${four[@]}" --updates bayes --utilities entropy --planners plain safe \
  --sensors one-camera --no-arm "${library[@]}"
room one-camera-front-only-bayes specular front-only bayes entropy --sensors one-camera "${library[@]}"
second_edition_rest

# 4. The window and the symmetric rooms (and the doorway to a deeper room): the planted scenes of
# examples/experiments/planted_scenes.hpp, unbounded grids at 10 cm, plain and safe, interval-mean
# and Bayes. A file with its three summary lines is kept (resumed at file level).
planted="$build/examples/experiments/planted_scenes"
[ -x "$planted" ] || { echo "experiments_third_edition: $planted not built (bash scripts/setup.sh)" >&2; exit 1; }
mkdir -p "$out/planted"
read -r -a planted_extra <<< "${INTERVOX_PLANTED_OPTIONS:-}"  # e.g. a coarser grid for a quick try
for grid in interval bayes; do
  for planner in plain safe; do
    f="$out/planted/$grid-$planner.txt"
    if [ -f "$f" ] && [ "$(grep -c '^summary |' "$f")" -eq 3 ]; then continue; fi
    echo "== planted $grid $planner"
    "$planted" --seeds "$seeds" --scenes 4,5,6 --grid "$grid" --planner "$planner" "${planted_extra[@]}" > "$f.partial"
    mv "$f.partial" "$f"
  done
done

# 5. The polished part on the arm: its explained model, with and without views that seek normals
# (Bayes, interval-mean, dirichlet-mean; scripts/arm_normals_sweep.sh). A file with every run is
# kept (resumed at file level).
arm_runs=$(( 6 * seeds + 1 ))
read -r -a arm_extra <<< "${INTERVOX_ARM_OPTIONS:-}"  # e.g. a coarser grid for a quick try
if [ ! -f "$out/arm_normals.csv" ] || [ "$(wc -l < "$out/arm_normals.csv")" -ne "$arm_runs" ]; then
  echo "== arm normals"
  bash "$(dirname "$0")/arm_normals_sweep.sh" "$build" "$seeds" "$out/arm_normals.csv.partial" part polished-metal \
    "${arm_extra[@]}"
  mv "$out/arm_normals.csv.partial" "$out/arm_normals.csv"
fi

merge_sweeps
here="$(dirname "$0")"
/usr/bin/python3 "$here/experiments_third_edition_report.py" "$out/results.csv" --planted "$out/planted" \
  --arm-normals "$out/arm_normals.csv" --charts "$out/charts" > "$out/report.md"
/usr/bin/python3 "$here/experiments_report.py" "$out/results.csv" --charts "$out/charts" > "$out/report-thesis.md"
/usr/bin/python3 "$here/arm_normals_report.py" "$out/arm_normals.csv" > "$out/report-arm-normals.md"
echo "experiments_third_edition: $out/results.csv, report.md, report-thesis.md, charts/, figures/"
