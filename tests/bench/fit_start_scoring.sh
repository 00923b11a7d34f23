#!/bin/bash
# bench_diagnose counts where each case's fitted candidates' fits ended (hypotheses[].fit_start,
# fitted ones only) from stored reports (--existing-only), in both scorers, and lists the cases
# whose held starts searched a profile and the names made from a held start (held_point or
# profile). A report without the field (older than 86d9c66) is not counted as read.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
report() {  # file verdict hypotheses ("name:fitted:start:profile_searched" comma-separated, "-": none, "old": no field)
  python3 - "$@" <<'PY'
import json, sys
path, verdict, spec = sys.argv[1:4]
hypotheses = []
if spec == "old":
    hypotheses = [{"name": "air_drag", "fitted": True}]
elif spec != "-":
    for item in spec.split(","):
        name, fitted, start, profiled = item.split(":")
        hypotheses.append({"name": name, "fitted": fitted == "yes", "fit_start": start,
                           "profile_searched": profiled == "yes"})
json.dump({"verdict": verdict, "candidates": [], "undecidable": [], "seconds": 1, "phases": [],
           "hypotheses": hypotheses,
           "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}}}, open(path, "w"))
PY
}
case_dir() {  # name effect verdict hypotheses
  mkdir -p "$dir/gen/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/gen/$1/answer.json"
  report "$dir/gen/$1/report.json" "$3" "$4"
}
# A control whose candidates were not fitted (their fit_start is not counted); a drag named from
# the first search, its adhesion kept on the null after held starts; an EPSD rolling named from
# the profile, its offset from a held point; a report older than the field.
case_dir control-01 none none air_drag:no:first_search:no,adhesion:no:first_search:no
case_dir air_drag-strong air_drag air_drag air_drag:yes:first_search:no,adhesion:yes:null_kept:no
case_dir epsd_rolling-strong epsd_rolling epsd_rolling epsd_rolling:yes:profile:yes,com_offset:yes:held_point:no
case_dir adhesion-strong adhesion none old
score_generated "$dir/gen"
expect_line "$dir/gen/summary.md" "fitted candidates by where their fit ended" \
  "fitted candidates by where their fit ended (fit_start): first_search 1, null_kept 1, held_point 1, profile 1; read in 3 of 4 reports; the profile searched in: epsd_rolling-strong; names from a held start: epsd_rolling-strong (profile)"
# An independent set scored with --recordings-set: a drag named from a held point, a control
# whose offset searched the profile and stayed on the null.
two_case_set
report "$dir/out/case-a/report.json" none com_offset:yes:null_kept:yes
report "$dir/out/case-b/report.json" air_drag air_drag:yes:held_point:no
score_set
expect_line "$dir/out/summary.md" "fitted candidates by where their fit ended" \
  "fitted candidates by where their fit ended (fit_start): first_search 0, null_kept 1, held_point 1, profile 0; read in 2 of 2 reports; the profile searched in: case-a; names from a held start: case-b (held_point)"
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
f = json.load(open(sys.argv[1]))["fit_starts"]
assert f["cases_read"] == 2 and f["counts"] == {"first_search": 0, "null_kept": 1, "held_point": 1, "profile": 0}, f
assert f["profile_searched"] == ["case-a"] and f["named_from_held_start"] == ["case-b (held_point)"], f
PY
echo ok
