#!/bin/bash
# A rolling law the fit from the null never reaches is named from a held start (docs/diagnose.md,
# "A held start for a fit that ends on the null"). The sphere benchmark's EPSD rolling cases (the
# bench's default seed; an exact sphere of the independent simulator's radius with the EPSD rolling
# resistance concealed; diagnosed with its mesh's one-sphere fill). From the null, the candidate's
# fit never left compliance 0 in either (constant torque and the EPSD spring are two rolling
# models, and the truth needs the compliance up and mu_r down together). The strong case
# (compliance 30) ended `unexplained`; the realistic one (compliance 3), whose null's misfit pulled
# the restitution to 0.965 (the drops' 0.728), was named `elastic_plastic_restitution`. Held at the
# first search's two points nearest the null (compliance 16 and 40, neither the truth) with the
# coefficients calibrated there the baseline's way, and (realistic) the profile searched between
# the null and 40, the fit reaches the truth and the law is named. At compliance 12, 20, 25, 40
# and 60 (the same seed) the fit from the null finds it alone.
# Usage: sphere_epsd_held_start.sh SOURCE_DIR BUILD_DIR SPHERE_MESH strong|realistic
set -u
export SPHERE_MESH=$3
magnitude=$4
source "$(dirname "$0")/sphere_case.sh"
sphere_case "$1" "$2" epsd_rolling "$magnitude"
python3 - "$dir/out/report.json" "$dir/gen/epsd_rolling-$magnitude/answer.json" "$magnitude" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
truth = json.load(open(sys.argv[2]))["effect_parameters"]["rolling_compliance"]
assert truth == {"strong": 30, "realistic": 3}[sys.argv[3]], truth
assert r["held_starts"], r["held_starts"]
assert r["verdict"] == "epsd_rolling", (r["verdict"], r["statement"])
c = r["effect_parameters"]["rolling_compliance"]
named = next(h for h in r["hypotheses"] if h["name"] == "epsd_rolling")
# Reached from a held start, not the first search (which ends on the null); the realistic case
# from the profile's minimum (Levenberg-Marquardt from compliance 16 alone crept to 9.65).
assert named["fit_start"] in ({"held_point", "profile"} if sys.argv[3] == "strong" else {"profile"}), named["fit_start"]
assert named["profile_searched"] or sys.argv[3] == "strong", named
if sys.argv[3] == "strong":
    # Within 5 % of the truth (measured: 29.56). Not its 95 % interval ([29.42, 29.70] excludes 30):
    # that interval is conditional on the coefficients (docs/diagnose.md, Limits), too narrow here.
    assert abs(c["value"] - truth) < 0.05 * truth, c
else:
    # The truth within its 95 % interval, and the interval within +-40 % of the value (measured:
    # 2.754 [1.882, 3.626]; the roll alone, by_recording, 3.24).
    assert c["low"] <= truth <= c["high"], c
    assert c["high"] - c["low"] < 0.8 * c["value"], c
PY
