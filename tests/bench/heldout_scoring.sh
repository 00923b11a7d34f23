#!/bin/bash
# bench_diagnose's held-out improvement, on stored reports (--existing-only), in both scorers: a
# name made on the outcomes and checked on the held-out trials' outcomes (fit.heldout_outcomes)
# counts by their RMS z; any other named case by its held-out tracks' RMS [mm]. Cases not named
# right do not count.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# verdict basis tracks-before tracks-after [heldout_outcomes JSON]
report() {
  local outcomes=""
  [ $# -ge 5 ] && outcomes=",\"heldout_outcomes\":$5"
  printf '{"verdict":"%s","basis":"%s","candidates":[],"undecidable":[],"seconds":1,"fit":{"before":{"heldout_rms_mm":%s},"after":{"heldout_rms_mm":%s}%s}}\n' \
    "$1" "$2" "$3" "$4" "$outcomes"
}
on_outcomes='{"training_trials":8,"heldout_trials":8,"statistics":16,"chi2_null":1600,"chi2_named":16,"rms_z_null":10.0,"rms_z_named":1.0,"improvement":0.9}'
for c in static_kinetic_friction-strong air_drag-strong adhesion-strong control-01; do mkdir -p "$dir/gen/$c"; done
answer() { printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' "$2" >"$dir/gen/$1/answer.json"; }
answer static_kinetic_friction-strong static_kinetic_friction
answer air_drag-strong air_drag
answer adhesion-strong adhesion
answer control-01 none
# Named on the outcomes: RMS z 10 -> 1 (90 %), its tracks unchanged (0 %).
report static_kinetic_friction ensemble 0.2 0.2 "$on_outcomes" >"$dir/gen/static_kinetic_friction-strong/report.json"
# Named frame by frame: 0.4 -> 0.1 mm (75 %).
report air_drag frame_by_frame 0.4 0.1 >"$dir/gen/air_drag-strong/report.json"
# Missed: does not count, whatever its figures.
report none consistent 0.4 0.4 >"$dir/gen/adhesion-strong/report.json"
report none consistent 0.1 0.1 >"$dir/gen/control-01/report.json"
"$bench" -o "$dir/gen" --full-set --controls 1 --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "median held-out improvement" "$dir/gen/summary.md")
case "$line" in
  "median held-out improvement (named cases): 82.5 % "*) ;;
  *) echo "generated: $line"; exit 1 ;;
esac
grep -q "static_kinetic_friction-strong .* held-out 10.00 -> 1.00 z (outcomes)" "$dir/log" || { cat "$dir/log"; exit 1; }
grep -q "air_drag-strong .* held-out 0.400 -> 0.100 mm" "$dir/log" || { cat "$dir/log"; exit 1; }
# An independent set scored with --recordings-set.
for c in a b c; do mkdir -p "$dir/set/case-$c" "$dir/out/case-$c"; done
printf '{"cases":{"case-a":{"effect":"com_offset"},"case-b":{"effect":"air_drag"},"case-c":{"effect":"none"}}}\n' \
  >"$dir/set/ANSWERS.json"
report com_offset ensemble 0.2 0.2 "$on_outcomes" >"$dir/out/case-a/report.json"
report air_drag frame_by_frame 0.5 0.4 >"$dir/out/case-b/report.json"
report none consistent 0.1 0.1 >"$dir/out/case-c/report.json"
"$bench" --recordings-set "$dir/set" -o "$dir/out" --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "median held-out improvement" "$dir/out/summary.md")
case "$line" in
  "median held-out improvement of the cases named right: 55.0 % "*) ;;
  *) echo "recordings set: $line"; exit 1 ;;
esac
grep -q "| case-a | .* | 10.00 -> 1.00 z (outcomes) | 90.0 % |" "$dir/out/summary.md" || { cat "$dir/out/summary.md"; exit 1; }
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
rows = {r["case"]: r for r in s["cases"]}
assert rows["case-a"]["heldout_on"] == "outcomes" and rows["case-a"]["heldout_before"] == 10.0, rows["case-a"]
assert rows["case-b"]["heldout_on"] == "tracks" and rows["case-b"]["heldout_after"] == 0.4, rows["case-b"]
PY
echo ok
