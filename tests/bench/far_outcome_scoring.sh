#!/bin/bash
# bench_diagnose counts the cases whose reported null left the outcomes consistent yet one of them
# far out (leaves_far_outcome: the candidates were tried for it), how many controls, and their
# verdicts, on stored reports (--existing-only), in both scorers. A report's own `null_fit` is
# read where it has one (it overrides the z below, to show it is what is read); an older report's
# null is classified from its z: 16 comparisons of means, none fitted: one at z = 3.6 is far
# (Sidak family tail 0.0051) on a consistent chi^2 (12.96 over 16); one at 2.5 is not far (0.18);
# sixteen at 3 are an inconsistent null, not counted.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
report() {  # file verdict far-z other-z [null_fit]
  python3 - "$@" <<'PY'
import json, sys
path, verdict, far, other = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
cmp = [{"statistic": "mean", "outcome": "drift", "z": far}] + [{"statistic": "mean", "outcome": "drift", "z": other}] * 15
ensemble = {"comparisons": cmp, "calibrated_here": []}
if len(sys.argv) > 5:
    ensemble["null_fit"] = sys.argv[5]
json.dump({"verdict": verdict, "candidates": [], "undecidable": [], "seconds": 1,
           "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}},
           "ensemble": ensemble}, open(path, "w"))
PY
}
case_dir() {  # name effect verdict far-z other-z [null_fit]
  mkdir -p "$dir/gen/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/gen/$1/answer.json"
  report "$dir/gen/$1/report.json" "${@:3}"
}
case_dir air_drag-strong air_drag air_drag -3.6 0
case_dir adhesion-strong adhesion none 3 3 one_far_outcome
case_dir control-01 none none 3.6 0 consistent
case_dir control-02 none none 2.5 0
score_generated "$dir/gen"
expect_line "$dir/gen/summary.md" "consistent nulls that left one outcome far out" \
  "consistent nulls that left one outcome far out (Sidak family tail < 0.05: their candidates tried): 2/4 (0 controls); verdicts air_drag 1, none 1"
# An independent set scored with --recordings-set.
two_case_set
report "$dir/out/case-a/report.json" none 2.5 0 one_far_outcome
report "$dir/out/case-b/report.json" none 3.6 0
score_set
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))["consistent_nulls_one_far"]
assert s == {"cases": 2, "of": 2, "controls": 1, "verdicts": {"none": 2}}, s
PY
echo ok
