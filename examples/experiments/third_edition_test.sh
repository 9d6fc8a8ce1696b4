#!/usr/bin/env bash
# Runs scripts/experiments_third_edition.sh on a tiny configuration (1 seed, coarse grids, one
# step) and checks that every sweep ran, the merge holds every run once, the report names its
# targets, and a second start runs nothing. Exit 77 (skipped) without numpy or matplotlib.
# Usage: third_edition_test.sh SCRIPT BUILD_DIR OUT_DIR
set -euo pipefail
script="$1" build="$2" out="$3"
/usr/bin/python3 -c "import numpy, matplotlib" 2>/dev/null || exit 77
rm -rf "$out"
opts=(--resolution 0.2 --max-steps 1 --gain-stride 8 --arm-resolution 0.02 --arm-max-views 1 --no-figures --quiet)
export INTERVOX_PLANTED_OPTIONS="--resolution 0.4 --max-steps 1"
export INTERVOX_ARM_OPTIONS="--resolution 0.05"
bash "$script" "$build" "$out" 1 -- "${opts[@]}" > "$out.log" 2>&1 || { cat "$out.log"; exit 1; }
fail() { echo "third_edition_test: $*" >&2; cat "$out.log"; exit 1; }
sweeps=$(ls -d "$out"/sweeps/*/ | wc -l)
[ "$sweeps" -eq 29 ] || fail "expected 29 sweeps, found $sweeps"
rows=$(( $(wc -l < "$out/results.csv") - 1 ))
sum=0
for f in "$out"/sweeps/*/results.csv; do sum=$(( sum + $(wc -l < "$f") - 1 )); done
# Thesis condition 48 (arm 12), library defaults 24, glint 4, body 8, one camera 20, the second
# edition's second conditions 13.
[ "$rows" -eq 117 ] || fail "expected 117 merged runs (117 configurations, 1 seed), found $rows"
[ "$rows" -eq "$sum" ] || fail "merged $rows runs, the sweeps hold $sum"
grep -q "^## Targets (fixed before the runs)" "$out/report.md" || fail "report.md has no targets"
grep -q "| 5 | 0 runs with a collision (safe planner) | library |" "$out/report.md" || fail "report.md misses target 5 under the library defaults"
grep -q "^## Safe − plain: thesis" "$out/report.md" || fail "report.md misses the thesis condition's comparison"
grep -q "^## Per configuration: library, body" "$out/report.md" || fail "report.md misses the robot seen in the mirror"
grep -q "^| 9 | one camera" "$out/report.md" || fail "report.md misses target 9"
grep -q "^### Targets" "$out/report-thesis.md" || fail "report-thesis.md has no targets"
[ -s "$out/charts/steps.png" ] || fail "chart steps.png missing"
for f in safe_vs_plain_collisions safe_vs_plain_floor; do [ -s "$out/charts/$f.png" ] || fail "chart $f.png missing"; done
for f in interval-plain interval-safe bayes-plain bayes-safe; do
  [ "$(grep -c '^summary |' "$out/planted/$f.txt")" -eq 3 ] || fail "planted/$f.txt lacks its three scenes"
done
grep -q "^## The planted scenes" "$out/report.md" || fail "report.md misses the planted scenes"
[ "$(wc -l < "$out/arm_normals.csv")" -eq 7 ] || fail "arm_normals.csv lacks its 6 runs"
grep -q "interval-mean" "$out/report-arm-normals.md" || fail "report-arm-normals.md is empty"
grep -q "^| 10 | polished part" "$out/report.md" || fail "report.md misses target 10"
# Started again, every sweep resumes and runs nothing.
bash "$script" "$build" "$out" 1 -- "${opts[@]}" > "$out.log2" 2>&1 || fail "second start failed"
ran=$(grep -c "^done in .*: 0 runs" "$out.log2" || true)
[ "$ran" -eq 29 ] || fail "a second start ran runs again ($ran of 29 sweeps ran nothing)"
! grep -q "^== planted" "$out.log2" || fail "a second start ran the planted scenes again"
! grep -q "^== arm normals" "$out.log2" || fail "a second start ran the arm again"
echo "third_edition_test: ok ($rows runs)"
