#!/bin/bash
# bench_diagnose --cases diagnoses and scores only the cases it names: of a recordings set (two
# cases, each a drop of the lab-like sphere's mesh whose track is too short to decide anything, so
# undecidable at once) and of a generated set (its answers made with --generate-only: the one
# case named, the same bytes as in the whole set). A name that is no case of the set is refused,
# with the closest one, before anything is run.
set -u
bench=$1 mesh=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
for c in case-01 case-02; do short_drop_case "$dir/set" "$c" "$mesh"; done
echo '{"cases": {"case-01": {"effect": "none"}, "case-02": {"effect": "none"}}}' > "$dir/set/ANSWERS.json"

"$bench" --recordings-set "$dir/set" --cases case-02 -o "$dir/out" >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
[ -f "$dir/out/case-02/report.json" ] || { echo "case-02 not diagnosed"; cat "$dir/log"; exit 1; }
[ ! -e "$dir/out/case-01" ] || { echo "case-01 diagnosed though not named"; exit 1; }
grep -q "^| case-02 " "$dir/out/summary.md" || { echo "case-02 not in the summary"; exit 1; }
# Scored alone, even with another case's report beside it.
mkdir -p "$dir/out/case-01" && cp "$dir/out/case-02/report.json" "$dir/out/case-01/"
"$bench" --recordings-set "$dir/set" --cases case-02 -o "$dir/out" --existing-only >"$dir/log" 2>&1 ||
  { cat "$dir/log"; exit 1; }
! grep -q "^| case-01 " "$dir/out/summary.md" || { echo "case-01 scored though not named"; exit 1; }

if "$bench" --recordings-set "$dir/set" --cases case-3 -o "$dir/bad" >"$dir/log" 2>&1; then
  echo "an unknown case was accepted"; exit 1
fi
grep -q "'case-3' is not a case of this set (did you mean 'case-01'?)\|'case-3' is not a case of this set (did you mean 'case-02'?)" "$dir/log" ||
  { cat "$dir/log"; exit 1; }
[ ! -e "$dir/bad" ] || { echo "written before the refusal"; exit 1; }

# A generated set: the one case named is made, the same bytes as in the whole set.
"$bench" --generate-only --cases control-02 --controls 2 --effects air_drag --trials 2 -o "$dir/one" >"$dir/log" 2>&1 ||
  { cat "$dir/log"; exit 1; }
[ "$(ls "$dir/one")" = "control-02" ] || { ls "$dir/one"; exit 1; }
"$bench" --generate-only --controls 2 --effects air_drag --trials 2 -o "$dir/all" >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
diff -r "$dir/one/control-02" "$dir/all/control-02" >/dev/null || { echo "control-02 differs from the whole set's"; exit 1; }
echo ok
