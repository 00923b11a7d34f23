#!/bin/bash
# bench_diagnose --compare OTHER sets a run's stored reports beside another run's, case by case:
# verdicts and bases that changed, the per-case time ratios (here over there) and their median,
# that of the cases judged alike (the same verdict, basis and particle-model resolution), the
# cases diagnosed in one run only; compare.md and compare.json in --out. A malformed report
# or a missing run folder is refused with the file named, and no comparison is written.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
report='{"verdict":"%s","basis":"%s","candidates":[],"undecidable":[],"seconds":%s,%s"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n'
mkdir -p "$dir/set"
printf '{"cases":{"case-a":{"effect":"air_drag"},"case-b":{"effect":"none"},"case-c":{"effect":"adhesion"},"case-d":{"effect":"none"},"case-e":{"effect":"none"},"case-f":{"effect":"none"}}}\n' \
  >"$dir/set/ANSWERS.json"
put() {  # run case verdict basis seconds [spheres judged]
  mkdir -p "$dir/set/$2" "$dir/$1/$2"
  local model=""
  [ -n "${6:-}" ] && model="\"particle_model\":{\"resolution_needed_spheres\":$6},"
  printf "$report" "$3" "$4" "$5" "$model" >"$dir/$1/$2/report.json"
}
put old case-a air_drag frame_by_frame 100
put old case-b none consistent 40
put old case-c none consistent 10
put old case-e none particle_model 50 128
put old case-f none particle_model 30 128
put new case-a air_drag frame_by_frame 90
put new case-b none slight_misfit 60
put new case-c adhesion ensemble 12
put new case-d none consistent 5
put new case-e none particle_model 80 256
put new case-f none particle_model 33 128
"$bench" --recordings-set "$dir/set" -o "$dir/new" --existing-only --compare "$dir/old" >"$dir/log" 2>&1 ||
  { cat "$dir/log"; exit 1; }
md="$dir/new/compare.md"
grep -qx "verdicts changed: 1/5 (case-c)" "$md" || { cat "$md"; exit 1; }
grep -qx "bases changed: 2/5 (case-b, case-c)" "$md" || { cat "$md"; exit 1; }
# Ratios 0.9, 1.5, 1.2, 1.6, 1.1: median 1.2; medians of the times 40 and 60 s.
grep -qx "time per case, here over there: 0.90-1.60, median 1.20; median time there 40.0 s, here 60.0 s" "$md" ||
  { cat "$md"; exit 1; }
# Judged alike: case-a (0.9) and case-f (1.1); case-e was judged on 256 spheres here, 128 there.
grep -qx "time per case judged alike (the same verdict, basis and spheres judged): 2 of 5, median 1.00" "$md" ||
  { cat "$md"; exit 1; }
grep -qx "diagnosed here only: 1 (case-d); there only: 0" "$md" || { cat "$md"; exit 1; }
grep -qx "| case-c | none -> adhesion | consistent -> ensemble | - | 10.0 -> 12.0 | 1.20 |" "$md" || { cat "$md"; exit 1; }
grep -qx "| case-e | none | particle_model | 128 -> 256 | 50.0 -> 80.0 | 1.60 |" "$md" || { cat "$md"; exit 1; }
python3 - "$dir/new/compare.json" <<'PY' || exit 1
import json, sys
c = json.load(open(sys.argv[1]))
assert c["verdicts_changed"] == ["case-c"], c
assert c["bases_changed"] == ["case-b", "case-c"], c
assert abs(c["median_time_ratio"] - 1.2) < 1e-12, c
assert abs(c["median_time_ratio_judged_alike"] - 1.0) < 1e-12, c
assert c["only_here"] == ["case-d"] and c["only_there"] == [], c
assert [k["case"] for k in c["cases"]] == ["case-a", "case-b", "case-c", "case-e", "case-f"], c
e = c["cases"][3]
assert (e["spheres_judged_there"], e["spheres_judged_here"], e["judged_alike"]) == (128, 256, False), e
PY
# A report that is not JSON: refused, the file named, no comparison written.
rm "$dir/new/compare.md" "$dir/new/compare.json"
echo '{"verdict":' >"$dir/old/case-b/report.json"
if "$bench" --recordings-set "$dir/set" -o "$dir/new" --existing-only --compare "$dir/old" >"$dir/log" 2>&1; then
  echo "a malformed report was accepted"; exit 1
fi
grep -q "$dir/old/case-b/report.json: not a JSON object" "$dir/log" || { cat "$dir/log"; exit 1; }
[ ! -e "$dir/new/compare.md" ] && [ ! -e "$dir/new/compare.json" ] || { echo "a comparison was written"; exit 1; }
# A run folder that does not exist.
if "$bench" --recordings-set "$dir/set" -o "$dir/new" --existing-only --compare "$dir/nowhere" >"$dir/log" 2>&1; then
  echo "a missing run folder was accepted"; exit 1
fi
grep -q "$dir/nowhere: no such run folder" "$dir/log" || { cat "$dir/log"; exit 1; }
echo ok
