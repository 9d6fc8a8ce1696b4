#!/usr/bin/env bash
# Runs scripts/experiments_second_edition.sh on a tiny configuration (1 seed, coarse grids, one
# step) and checks that every sweep ran, the merge holds every run once, and the report and its
# charts were written. Exit 77 (skipped) without numpy or matplotlib.
# Usage: second_edition_test.sh SCRIPT BUILD_DIR OUT_DIR
set -euo pipefail
script="$1" build="$2" out="$3"
/usr/bin/python3 -c "import numpy, matplotlib" 2>/dev/null || exit 77
rm -rf "$out"
bash "$script" "$build" "$out" 1 -- --resolution 0.2 --max-steps 1 --gain-stride 8 --arm-resolution 0.02 \
  --arm-max-views 1 --no-figures --quiet > "$out.log" 2>&1 || { cat "$out.log"; exit 1; }
fail() { echo "second_edition_test: $*" >&2; cat "$out.log"; exit 1; }
sweeps=$(ls -d "$out"/sweeps/*/ | wc -l)
[ "$sweeps" -eq 11 ] || fail "expected 11 sweeps, found $sweeps"
rows=$(( $(wc -l < "$out/results.csv") - 1 ))
sum=0
for f in "$out"/sweeps/*/results.csv; do sum=$(( sum + $(wc -l < "$f") - 1 )); done
[ "$rows" -eq 45 ] || fail "expected 45 merged runs (45 configurations, 1 seed), found $rows"
[ "$rows" -eq "$sum" ] || fail "merged $rows runs, the sweeps hold $sum"
grep -q "^### Targets" "$out/report.md" || fail "report.md has no targets"
grep -q "mirror closet, conflict-aware interval-mean: completes" "$out/report.md" || fail "report.md misses the mirror target"
grep -q "policies clamped" "$out/report-clamped.md" || fail "report-clamped.md is not the clamped condition"
for c in steps completed collisions arm_coverage; do
  [ -s "$out/charts/$c.png" ] || fail "chart $c.png missing"
done
# Started again, every sweep resumes and runs nothing.
bash "$script" "$build" "$out" 1 -- --resolution 0.2 --max-steps 1 --gain-stride 8 --arm-resolution 0.02 \
  --arm-max-views 1 --no-figures --quiet > "$out.log2" 2>&1 || fail "second start failed"
ran=$(grep -c "^done in .*: 0 runs" "$out.log2" || true)
[ "$ran" -eq 11 ] || fail "a second start ran runs again ($ran of 11 sweeps ran nothing)"
echo "second_edition_test: ok ($rows runs)"
