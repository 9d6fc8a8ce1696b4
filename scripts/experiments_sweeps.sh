# The sweeps the editions of docs/experiments.md share; sourced by experiments_second_edition.sh and
# experiments_third_edition.sh, which set `exe` (the experiments program), `out` (the output
# folder), `seeds` and `extra` (options added to every sweep) first.

four=(diffuse absorbing transparent specular)

# sweep NAME OPTIONS...: one resumable sweep into OUT/sweeps/NAME.
sweep() {
  local name="$1"
  shift
  echo "== $name: $*"
  "$exe" --out "$out/sweeps/$name" --resume --seeds "$seeds" "$@" "${extra[@]}"
}

# The second edition's sweeps after its Bayes and interval-mean ones: the lower and upper rules
# with the thesis' classification of never-observed space, the conflict-aware planner, the arm,
# and its second conditions (the library's clamped policies under the thesis' other conditions,
# the first edition's specular model, the gain over every voxel, never-observed space left unknown
# for the lower and upper rules).
second_edition_rest() {
  sweep bounds-by-rule --surfaces diffuse specular --updates interval-lower interval-upper --utilities max-entropy \
    --unobserved by-rule --no-arm
  sweep conflict-aware --surfaces "${four[@]}" --updates interval-mean --utilities max-entropy \
    --planners conflict-aware --no-arm
  sweep arm --no-mobile --arm-objects part bottle --arm-updates bayes interval-mean --utilities entropy max-entropy \
    --planners plain conflict-aware
  sweep clamped-bayes --surfaces diffuse specular --updates bayes --utilities entropy --policies clamped --no-arm
  sweep clamped-mean --surfaces diffuse specular --updates interval-mean --utilities max-entropy --policies clamped --no-arm
  sweep random-range-bayes --surfaces specular-random --updates bayes --utilities entropy --no-arm
  sweep random-range-mean --surfaces specular-random --updates interval-mean --utilities max-entropy \
    --planners plain conflict-aware --no-arm
  sweep gain-all --surfaces diffuse --updates interval-mean --utilities entropy max-entropy --gains all --no-arm
  sweep bounds-unknown --surfaces diffuse specular --updates interval-lower interval-upper --utilities max-entropy --no-arm
}

# merge_sweeps: every sweep's results.csv merged into OUT/results.csv, results.json and tables.md;
# the pictures of seed 1 of every configuration copied into OUT/figures.
merge_sweeps() {
  local csvs=() d
  for d in "$out"/sweeps/*/; do csvs+=("$d/results.csv"); done
  "$exe" --out "$out" --tables-from "${csvs[@]}"
  mkdir -p "$out/figures"
  for d in "$out"/sweeps/*/figures; do cp "$d"/*.png "$out/figures/" 2>/dev/null || true; done
}
