#!/bin/bash
# bench_diagnose --recordings-set scores how far each missed effect moves the summary means,
# from the answers' twins (each trial's value with the effect and without it, same release), on
# stored reports (--existing-only). Analytic, to 1e-6: effect-free trials 1..6 have a standard
# error s = sqrt(3.5/6); two drops on one surface shifted by +3s and -3s give a noncentrality of
# 18, and no common level takes any of it off (18 over 1 degree of freedom is shown); shifts of
# 3s on trials 1..6 and 6s on trials 2,4..12 (the same relative shift) give 18 that one level
# takes off entirely; +0.5s twice gives 0.5, not shown; fixed trials shifted by 1 % and 3 % leave
# 1 % about their common level; a control has no twins, nor does a case whose twins are
# malformed (skipped, not thrown on). A generated two-surface answer keeps each surface's
# recordings apart.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import json, math, os, sys
d = sys.argv[1]
s = math.sqrt(3.5 / 6)
def rec(shift, scale=1.0, vary=True, relative=False):
    w = [scale * (1.0 + i) if vary else 2.0 for i in range(6)]
    return {"surface": "Q235", "test": "drop",
            "trials": [{"value": x * (1 + shift) if relative else x + shift, "value_without_effect": x} for x in w]}
cases = {
    "case-a": {"effect": "adhesion", "recordings": {"d1": rec(3 * s), "d2": rec(-3 * s)}},
    "case-b": {"effect": "adhesion", "recordings": {"d1": rec(0.5 * s), "d2": rec(0.5 * s)}},
    "case-c": {"effect": "adhesion", "recordings": {"d1": rec(0.01, vary=False, relative=True),
                                                    "d2": rec(0.03, vary=False, relative=True)}},
    "case-d": {"effect": "none",
               "recordings": {"d1": {"trials": [{"value": 1.0, "value_without_effect": None}] * 6}}},
    "case-e": {"effect": "adhesion", "recordings": {"d1": rec(3 * s), "d2": rec(6 * s, scale=2.0)}},
    # Malformed twins are skipped, not thrown on.
    "case-f": {"effect": "adhesion", "recordings": {
        "d1": {"surface": 5, "test": None, "trials": [{"value": "x", "value_without_effect": 1}] * 6},
        "d2": "not an object"}},
}
os.makedirs(f"{d}/set")
json.dump({"cases": cases}, open(f"{d}/set/ANSWERS.json", "w"))
for c in cases:
    os.makedirs(f"{d}/set/{c}")
    os.makedirs(f"{d}/out/{c}")
    json.dump({"verdict": "none", "undecidable": ["adhesion"], "seconds": 1,
               "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}}},
              open(f"{d}/out/{c}/report.json", "w"))
PY
"$bench" --recordings-set "$dir/set" -o "$dir/out" --existing-only >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
line=$(grep "missed effects by how far" "$dir/out/summary.md")
case "$line" in
  *"own level: case-a; only without those levels: case-e; not: case-b; trials that do not vary (relative shift the levels leave): case-c 1 %; no twins: case-f") ;;
  *) echo "unexpected: $line"; exit 1 ;;
esac
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))
t = s["missed_twin_shift"]
near = lambda a, b: abs(a - b) < 1e-6
assert near(t["case-a"]["noncentrality"], 18) and near(t["case-a"]["absorbed_noncentrality"], 18), t["case-a"]
assert t["case-a"]["absorbed_dof"] == 1 and t["case-a"]["absorbed_expected_p"] < 0.01, t["case-a"]
assert near(t["case-e"]["noncentrality"], 18) and near(t["case-e"]["absorbed_noncentrality"], 0), t["case-e"]
assert near(t["case-b"]["noncentrality"], 0.5) and t["case-b"]["expected_p"] > 0.01, t["case-b"]
assert t["case-c"]["recordings"] == 0 and t["case-c"]["fixed"] == 2, t["case-c"]
assert near(t["case-c"]["fixed_residual"], 0.01), t["case-c"]
rows = {r["case"]: r for r in s["cases"]}
assert rows["case-d"]["summary_shift"] is None, rows["case-d"]
PY
# A generated two-surface answer: each surface's drop-0.2m is kept (as its folder names it),
# shifted by +3s and -3s on one level each: 9 + 9 before the levels, 0 after (two levels).
python3 - "$dir" <<'PY'
import json, math, os, sys
d = sys.argv[1]
s = math.sqrt(3.5 / 6)
def part(surface, shift):
    w = [1.0 + i for i in range(6)]
    return {"surface": surface, "recordings": {"drop-0.2m": {"surface": surface, "test": "drop",
            "trials": [{"value": x + shift, "value_without_effect": x} for x in w]}}}
os.makedirs(f"{d}/gen/adhesion-strong")
json.dump({"effect": "adhesion", "surfaces": [part("Q235", 3 * s), part("soil", -3 * s)]},
          open(f"{d}/gen/adhesion-strong/answer.json", "w"))
json.dump({"verdict": "none", "undecidable": ["adhesion"], "seconds": 1,
           "fit": {"before": {"heldout_rms_mm": 0.1}, "after": {"heldout_rms_mm": 0.1}}},
          open(f"{d}/gen/adhesion-strong/report.json", "w"))
PY
"$bench" --nine-set-ups --effects adhesion --controls 0 --existing-only -o "$dir/gen" >"$dir/log" 2>&1 ||
  { cat "$dir/log"; exit 1; }
python3 - "$dir/gen/summary.json" <<'PY' || exit 1
import json, sys
t = json.load(open(sys.argv[1]))["missed_twin_shift"]["adhesion-strong"]
assert t["recordings"] == 2 and abs(t["noncentrality"] - 18) < 1e-6, t
assert t["absorbed_dof"] == 0 and abs(t["absorbed_noncentrality"]) < 1e-6, t
PY
echo ok
