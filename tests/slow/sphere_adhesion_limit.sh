#!/bin/bash
# A `none` claims no smallest detectable effect the recordings themselves prefer (docs/diagnose.md,
# "The sphere again"). The sphere benchmark's realistic adhesion (the bench's default seed; an exact
# sphere, a work of adhesion of 0.08 J/m^2 concealed by moving the static and rolling friction;
# diagnosed with its mesh's one-sphere fill) comes out `none`. Its replays show adhesion from
# 0.0133 J/m^2 with the coefficients absorbing it to first order, and until the commit after
# f01998e that was the claimed limit. Refitted, the coefficients absorb more: the recordings fit
# 0.0133 better than the null (by about 2,900), and 0.073 and 0.171 too. The claim must pass the
# whole check its strong magnitude passes, so none at or below the concealed 0.08 may stand. And
# a law that departs from the null's at any magnitude (epsd_rolling) is claimed as such.
# Usage: sphere_adhesion_limit.sh SOURCE_DIR BUILD_DIR SPHERE_MESH
set -u
export SPHERE_MESH=$3
source "$(dirname "$0")/sphere_case.sh"
sphere_case "$1" "$2" adhesion realistic
python3 - "$dir/out/report.json" "$dir/gen/adhesion-realistic/answer.json" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
truth = json.load(open(sys.argv[2]))["effect_parameters"]["work_of_adhesion_j_m2"]
assert truth == 0.08, truth
# As measured (f01998e and after): `none`, adhesion not named. A name would need its own test.
assert r["verdict"] == "none", (r["verdict"], r["statement"])
adhesion = next(h for h in r["hypotheses"] if h["name"] == "adhesion")
# The replay alone shows a smaller adhesion than the concealed one (measured: 0.0133)...
assert adhesion["replay_shown"] is not None and adhesion["replay_shown"] < truth, adhesion["replay_shown"]
# ...but no limit at or below it is claimed (measured: 0.4, the strong magnitude, the only one rejected).
claimed = adhesion["smallest_detectable"]
assert claimed is None or claimed > truth, (claimed, r["statement"])
# The check is reported, with the replay's figure not rejected.
checked = [n for n in r["notes"] if n.startswith("adhesion's smallest detectable") and "checked against" in n]
assert len(checked) == 1 and "not rejected" in checked[0], r["notes"]
# Every limit claimed lies at or above what the replays showed.
for h in r["hypotheses"]:
    if h["smallest_detectable"] is not None:
        assert h["replay_shown"] is not None and h["smallest_detectable"] >= h["replay_shown"] * (1 - 1e-9), h
# A law that departs from the null's at any magnitude claims no edge: on these rolls any rolling
# compliance swaps the constant torque for the spring (measured: 6.29, 0.673, 0.0417 and 3e-5 of a
# strong 30 show, and the recordings reject 3e-5 by 1.7e7). Before, 0.0417 was claimed as an edge.
# The other candidates' responses vanish with their magnitude, and they claim an edge.
for h in r["hypotheses"]:
    assert h["detectable_at_any_magnitude"] == (h["name"] == "epsd_rolling"), h
epsd = next(h for h in r["hypotheses"] if h["name"] == "epsd_rolling")
assert epsd["smallest_detectable"] is not None and epsd["smallest_detectable"] < 1e-4, epsd
assert "epsd_rolling at any rolling_compliance" in r["statement"], r["statement"]
PY
