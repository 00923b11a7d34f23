#!/bin/bash
# bench_diagnose --recordings-set scores how far each missed effect moves the summary means,
# from the answers' twins (each trial's value with the effect and without it, same release), on
# stored reports (--existing-only). Analytic: effect-free trials 1..6 have a standard error of
# sd/sqrt(6) = 0.76376; a shift of 3 standard errors gives a noncentrality of 9 (to 1e-6), and
# 10 over 1 degree of freedom lies beyond p = 0.01; half a standard error (0.25) does not;
# trials that do not vary are counted apart; a control has no twins.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import json, math, os, sys
d = sys.argv[1]
se = math.sqrt(3.5) / math.sqrt(6)  # sd of 1..6 is sqrt(3.5)
def rec(shift, vary=True):
    w = [1.0 + i if vary else 2.0 for i in range(6)]
    return {"trials": [{"value": x + shift, "value_without_effect": x} for x in w]}
cases = {
    "case-a": {"particle": "tuber", "effect": "adhesion", "recordings": {"drop": rec(3 * se)}},
    "case-b": {"particle": "tuber", "effect": "adhesion", "recordings": {"drop": rec(0.5 * se)}},
    "case-c": {"particle": "sphere", "effect": "adhesion", "recordings": {"drop": rec(0.1, vary=False)}},
    "case-d": {"particle": "tuber", "effect": "none",
               "recordings": {"drop": {"trials": [{"value": 1.0, "value_without_effect": None}] * 6}}},
}
os.makedirs(f"{d}/set")
json.dump({"cases": cases}, open(f"{d}/set/ANSWERS.json", "w"))
for c, a in cases.items():
    os.makedirs(f"{d}/set/{c}")
    os.makedirs(f"{d}/out/{c}")
    json.dump({"verdict": "none", "undecidable": ["adhesion"], "seconds": 1,
               "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}}},
              open(f"{d}/out/{c}/report.json", "w"))
PY
"$bench" --recordings-set "$dir/set" -o "$dir/out" --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "missed effects by how far" "$dir/out/summary.md")
case "$line" in
  *"p < 0.01: case-a; not: case-b; trials that do not vary, only the coefficients hide it: case-c; no twins: -") ;;
  *) echo "unexpected: $line"; exit 1 ;;
esac
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
t = s["missed_twin_shift"]
assert abs(t["case-a"]["noncentrality"] - 9.0) < 1e-6, t["case-a"]
assert abs(t["case-b"]["noncentrality"] - 0.25) < 1e-6, t["case-b"]
assert t["case-a"]["expected_p"] < 0.01 < t["case-b"]["expected_p"], t
assert t["case-c"]["recordings"] == 0 and t["case-c"]["fixed"] == 1, t["case-c"]
rows = {r["case"]: r for r in s["cases"]}
assert rows["case-d"]["summary_shift"] is None, rows["case-d"]
PY
echo ok
