#!/bin/bash
# bench_diagnose --compare OTHER sets a run's stored reports beside another run's, case by case:
# verdicts and bases that changed, the per-case time ratios (here over there) and their median,
# that of the cases judged alike (the same verdict, basis and particle-model resolution), the
# cases diagnosed in one run only, the trial replays' ratios and the smallest detectable
# magnitudes that changed; compare.md and compare.json in --out. A malformed report
# or a missing run folder is refused with the file named, and no comparison is written.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
report='{"verdict":"%s","basis":"%s","candidates":[],"undecidable":[],"seconds":%s,%s"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n'
mkdir -p "$dir/set"
printf '{"cases":{"case-a":{"effect":"air_drag"},"case-b":{"effect":"none"},"case-c":{"effect":"adhesion"},"case-d":{"effect":"none"},"case-e":{"effect":"none"},"case-f":{"effect":"none"}}}\n' \
  >"$dir/set/ANSWERS.json"
put() {  # run case verdict basis seconds [spheres judged] [more keys, each followed by a comma]
  mkdir -p "$dir/set/$2" "$dir/$1/$2"
  local model=""
  [ -n "${6:-}" ] && model="\"particle_model\":{\"resolution_needed_spheres\":$6},"
  printf "$report" "$3" "$4" "$5" "$model${7:-}" >"$dir/$1/$2/report.json"
}
limits() {  # trial_replays, then name=smallest_detectable (null: none claimed) ...
  local h="" sep=""
  for pair in "${@:2}"; do
    h="$h$sep{\"name\":\"${pair%%=*}\",\"smallest_detectable\":${pair#*=}}"
    sep=","
  done
  printf '"trial_replays":%s,"hypotheses":[%s],' "$1" "$h"
}
put old case-a air_drag frame_by_frame 100
put old case-b none consistent 40 "" "$(limits 1000 air_drag=0.0476 adhesion=0.0133 com_offset=0.0004)"
put old case-c none consistent 10 "" "$(limits 2000 air_drag=0.2)"
put old case-e none particle_model 50 128
put old case-f none particle_model 30 128
put new case-a air_drag frame_by_frame 90
put new case-b none slight_misfit 60 "" "$(limits 1500 air_drag=0.267 adhesion=0.4 com_offset=0.0004)"
put new case-c adhesion ensemble 12 "" "$(limits 2100 air_drag=null)"
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
# Trial replays in two cases' reports only (older reports lack them): 1.5 and 1.05.
grep -qx "trial replays per case, here over there: 1.050-1.500, median 1.275 (2 cases)" "$md" || { cat "$md"; exit 1; }
# Four limits claimed in either run; com_offset's is the same in both.
grep -qx "smallest detectable magnitudes changed: 3 of 4 claimed in either run (case-b: adhesion 0.0133 -> 0.4; case-b: air_drag 0.0476 -> 0.267; case-c: air_drag 0.2 -> null)" "$md" ||
  { cat "$md"; exit 1; }
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
assert abs(c["median_replays_ratio"] - 1.275) < 1e-12, c
assert c["limits_claimed"] == 4 and len(c["limits_changed"]) == 3, c
assert c["cases"][1]["limits_changed"] == ["adhesion 0.0133 -> 0.4", "air_drag 0.0476 -> 0.267"], c["cases"][1]
assert c["cases"][1]["trial_replays_there"] == 1000 and c["cases"][0]["trial_replays_here"] is None, c["cases"]
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
