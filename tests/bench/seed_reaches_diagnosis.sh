#!/bin/bash
# bench_diagnose --seed reaches each diagnosis of a recordings set (the release orientations it
# draws), as diagnose --seed does: report.json's seed is the bench's, 1 by default. Before, a
# recordings set was diagnosed with seed 1 whatever --seed said. One case, a drop of the lab-like
# sphere's mesh whose track is too short to decide anything (undecidable at once).
set -u
bench=$1 mesh=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
short_drop_case "$dir/set" case-01 "$mesh"
echo '{"cases": {"case-01": {"effect": "none"}}}' > "$dir/set/ANSWERS.json"
for seed in default 7; do
  args=()
  [ "$seed" = default ] || args=(--seed "$seed")
  "$bench" --recordings-set "$dir/set" "${args[@]}" -o "$dir/out-$seed" >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
  want=$([ "$seed" = default ] && echo 1 || echo "$seed")
  python3 - "$dir/out-$seed/case-01/report.json" "$want" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
assert r["verdict"] == "undecidable", r["verdict"]
assert r["seed"] == int(sys.argv[2]), (r.get("seed"), sys.argv[2])
PY
done
echo ok
