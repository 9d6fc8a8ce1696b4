#!/usr/bin/env bash
# The arm on the polished part (the workcell's default material for it), plain against
# conflict-aware modelling, seeds 1..N, for the interval update and the two credal cells.
# Writes one CSV row per run (docs/planning.md "Conflict-aware arm" has the table).
# Usage: scripts/arm_conflict_sweep.sh [build dir] [seeds] [out.csv]
set -euo pipefail
build="${1:-build}"
seeds="${2:-10}"
out="${3:-arm_conflicts.csv}"
bin="$build/examples/arm_modelling/arm_modelling"
[ -x "$bin" ] || { echo "arm_conflict_sweep: $bin not built" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "update,planner,seed,coverage_percent,wrongly_free,wrongly_occupied,conflict_views,termination" > "$out"
for u in interval-mean dirichlet-mean belief-mean; do
  for pl in plain conflict-aware; do
    for s in $(seq 1 "$seeds"); do
      log="$("$bin" --out "$tmp" --threads 1 --material polished-metal --update "$u" --planner "$pl" --seed "$s")"
      cov="$(echo "$log" | awk '/surface known occupied/ {print $4}')"
      wf="$(echo "$log" | awk '/voxels wrongly free/ {print $4}')"
      wo="$(echo "$log" | awk '/voxels wrongly occupied/ {print $4}')"
      cv="$(echo "$log" | grep -c ' conflict  ' || true)"
      term="$(echo "$log" | awk '/termination/ {print $2}')"
      echo "$u,$pl,$s,$cov,$wf,$wo,$cv,$term" >> "$out"
    done
  done
done
