#!/bin/bash
# bench_diagnose reads where each case's free flights sit against the diagnosis's two levels, from
# stored reports (--existing-only), in both scorers: the largest first-flight misfit per value
# (phases[].misfit_per_value, its level large_misfit_level) and the flights' wobble above the
# allowance in camera-noise levels ((wobble_mm - allowance_mm) / noise_mm, judged flights only).
# The controls' largest is given with its case; the effect cases at or above the level are
# listed. A roll's phases and unjudged flights are not read; a report without the field is not
# counted as read.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
report() {  # file verdict first-flight-misfits(comma-separated, "-" none) wobble allowance noise judged
  python3 - "$@" <<'PY'
import json, sys
path, verdict, misfits, wobble, allowance, noise, judged = sys.argv[1:8]
phases = [{"recording": "roll", "phase": "roll", "misfit_per_value": 50.0, "large_misfit_level": 10.0}]
if misfits != "-":
    for k, m in enumerate(misfits.split(",")):
        phases.append({"recording": f"drop-{k}", "phase": "flight", "misfit_per_value": float(m),
                       "large_misfit_level": 2.0})
        phases.append({"recording": f"drop-{k}", "phase": "rebound", "misfit_per_value": 40.0,
                       "large_misfit_level": 10.0})
# "null" as report.json writes a value it does not have (unjudged flights).
num = lambda v: None if v == "null" else float(v)
json.dump({"verdict": verdict, "candidates": [], "undecidable": [], "seconds": 1, "phases": phases,
           "flights": {"judged": judged == "yes", "wobble_mm": num(wobble), "allowance_mm": num(allowance),
                       "noise_mm": num(noise)},
           "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}}}, open(path, "w"))
PY
}
case_dir() {  # name effect verdict ...report's
  mkdir -p "$dir/gen/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/gen/$1/answer.json"
  report "$dir/gen/$1/report.json" "${@:3}"
}
# Controls: first flights 1.07 and 0.95 (largest 1.07), wobble (0.113 - 0.1) / 0.1 = 0.13; the
# other control's 0.9 wobble is not judged.
case_dir control-01 none none 0.98,1.07 0.113 0.1 0.1 yes
case_dir control-02 none none 0.95 0.19 0.1 0.1 no
# Effects: drag at 3.35 (crosses 2) with a wobble 0.2 below its allowance; an offset whose
# wobble is 4.1 levels up, its flights at 1.01; no first flight at all.
case_dir air_drag-strong air_drag air_drag 1.2,3.35 0.08 0.1 0.1 yes
case_dir com_offset-strong com_offset com_offset 1.01 0.51 0.1 0.1 yes
case_dir adhesion-strong adhesion none - 0.1 0.1 0.1 yes
score_generated "$dir/gen"
expect_line "$dir/gen/summary.md" "first-flight misfit per value" \
  "first-flight misfit per value (training trials, worse axis, against the camera noise; candidates fitted from 2): read in 4 of 5 reports; controls' largest 1.07 (control-01); effect cases at or above it: air_drag-strong 3.35"
expect_line "$dir/gen/summary.md" "free-flight wobble above its allowance" \
  "free-flight wobble above its allowance, in camera-noise levels (an offset claimed from 0.5): read in 4 of 5 reports; controls' largest 0.13 (control-01); effect cases at or above it: com_offset-strong 4.10"
# An independent set scored with --recordings-set: a control's flight at 2.5 is its largest, not
# an effect case; the drag's flights all below the level, and not judged (their wobble and
# noise null).
two_case_set
report "$dir/out/case-a/report.json" none 2.5 0.1 0.1 0.1 yes
report "$dir/out/case-b/report.json" air_drag 1.5 null 0.1 null no
score_set
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
f, w = s["first_flight_misfit"], s["flight_wobble"]
assert f["cases_read"] == 2 and f["controls_largest"] == 2.5 and f["controls_largest_case"] == "case-a", f
assert f["effects_at_level"] == [], f
assert w["cases_read"] == 1 and abs(w["controls_largest"]) < 1e-12 and w["margin"] == 0.5, w
PY
echo ok
