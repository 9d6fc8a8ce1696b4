#!/usr/bin/env bash
# Does the mobile planner gain from more candidates? Runs examples/mobile_exploration over seeds
# 1..N for every ring size (candidate positions per frontier; headings per position fixed), two runs
# at a time, each on one thread, and writes one CSV row per run (docs/planning.md "Candidates").
# Usage: scripts/candidate_sweep.sh [build dir] [seeds] [out.csv] [positions...] [-- extra mobile_exploration options]
#   scripts/candidate_sweep.sh build 10 candidates.csv 6 12 24 48
set -euo pipefail
build="${1:-build}"
seeds="${2:-10}"
out="${3:-candidates.csv}"
shift $(( $# < 3 ? $# : 3 ))
positions=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do positions+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
extra=("$@")
[ ${#positions[@]} -gt 0 ] || positions=(6 12 24 48)
bin="$build/examples/mobile_exploration/mobile_exploration"
[ -x "$bin" ] || { echo "candidate_sweep: $bin not built" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

one() {  # POSITIONS SEED: one run, one CSV row on standard output
  local n="$1" s="$2" log
  log="$("$bin" --out "$tmp/run_${n}_$s" --threads 1 --ring-positions "$n" --seed "$s" "${extra[@]}")"
  rm -rf "$tmp/run_${n}_$s"
  local term steps known dist coll total
  term="$(echo "$log" | sed -n 's/^  termination  *\(.*\) after \([0-9]*\) steps$/\1/p')"
  steps="$(echo "$log" | sed -n 's/^  termination  *.* after \([0-9]*\) steps$/\1/p')"
  known="$(echo "$log" | awk '/reachable area explored/ {print $4}')"
  dist="$(echo "$log" | awk '/distance driven/ {print $3}')"
  coll="$(echo "$log" | sed -n 's/.*distance driven .*(\([0-9]*\) poses in collision).*/\1/p')"
  total="$(echo "$log" | sed -n 's/.*time per step .*(total \([0-9.]*\) s).*/\1/p')"
  [ -n "$steps" ] && [ -n "$known" ] && [ -n "$dist" ] || { echo "candidate_sweep: run $n/$s: no summary" >&2; return 1; }
  echo "$n,$s,\"$term\",$steps,$known,$dist,$coll,$total"
}
export -f one
export bin tmp
export extra_joined="${extra[*]:-}"

echo "positions,seed,termination,steps,known_percent,distance_m,poses_in_collision,seconds" > "$out"
jobs=()
for n in "${positions[@]}"; do
  for s in $(seq 1 "$seeds"); do jobs+=("$n $s"); done
done
# Two runs at a time; rows sorted by positions and seed, so the file does not depend on timing.
printf '%s\n' "${jobs[@]}" | xargs -P 2 -L 1 bash -c 'extra=($extra_joined); one "$0" "$1"' > "$tmp/rows"
sort -t, -k1,1n -k2,2n "$tmp/rows" >> "$out"
echo "candidate_sweep: $(( $(wc -l < "$out") - 1 )) runs in $out"
