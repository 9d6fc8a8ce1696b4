#!/usr/bin/env bash
# Issue 34's runs: the arm on a workcell object (default: the polished part), seeds 1..N, for
# Bayes, interval-mean and the credal dirichlet-mean, each with the gain rule alone and with views
# that seek normals (--seek-normals); the grid's coverage and the explained model's (the part's
# explained-occupied voxels) after 12 views. One CSV row per run; docs/planning.md, "Views that
# seek normals", has the table (scripts/arm_normals_report.py prints it from the CSV).
# Usage: scripts/arm_normals_sweep.sh [build dir] [seeds] [out.csv] [object] [material] [extra arm_modelling options...]
# (e.g. --striper-baseline -0.15, --normals-weight 3)
set -euo pipefail
build="${1:-build}"
seeds="${2:-10}"
out="${3:-arm_normals.csv}"
object="${4:-part}"
material="${5:-polished-metal}"
shift $(( $# < 5 ? $# : 5 ))
extra=("$@")
bin="$build/examples/arm_modelling/arm_modelling"
[ -x "$bin" ] || { echo "arm_normals_sweep: $bin not built" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "object,material,update,normals,seed,coverage_percent,wrongly_occupied,model_coverage_percent,model_voxels,model_wrongly_occupied,normals_views,views_to_80_model" > "$out"
for u in bayes interval-mean dirichlet-mean; do
  utility=max-entropy
  for n in off on; do
    flag=""
    [ "$n" = on ] && flag="--seek-normals"
    for s in $(seq 1 "$seeds"); do
      log="$("$bin" --out "$tmp" --threads 1 --object "$object" --material "$material" --update "$u" --utility "$utility" \
               --max-views 12 --seed "$s" $flag ${extra[@]+"${extra[@]}"})"
      cov="$(echo "$log" | awk '/surface known occupied/ {print $4}')"
      wo="$(echo "$log" | awk '/voxels wrongly occupied/ {print $4}')"
      mv="$(echo "$log" | awk '/explained model/ {print $3}')"
      mc="$(echo "$log" | awk '/explained model/ {print $5}')"
      mw="$(echo "$log" | awk '/explained model/ {print $11}')"
      nv="$(echo "$log" | grep -c ' normals ' || true)"
      # Views until the explained model first holds 80 % of the visible surface (column 'model %'; 0: never).
      v80="$(echo "$log" | awk 'BEGIN {v = 0} /^ *[0-9]+ +[0-9]+ / && v == 0 && $(NF-1) + 0 >= 80 {v = $2} END {print v}')"
      echo "$object,$material,$u,$n,$s,$cov,$wo,$mc,$mv,$mw,$nv,$v80" >> "$out"
    done
  done
done
