#!/bin/bash
# A candidate that beats the null past the margin yet leaves the outcomes inconsistent is a gate
# of its own, compared again whole with 48 replays per recording (docs/diagnose.md, "An
# inconsistent candidate is a gate, and each rung's move is measured on 48 replays"). Lab-like
# case-10 (the independent simulator's sphere with its mass 1 mm off its centre), diagnosed as
# the bench does (its mesh, diagnose's defaults, seed 1; at 637a6d0): on 12 replays per recording
# the EPSD rolling law beats the null by delta-BIC 15.4 but leaves chi^2 275 over 32 recorded
# means and spreads (tail 1e-20); the comparison made again whole with 48 names the offset. A
# finer clump's move, where there is one, is measured on 48 replays from the start, so no move is
# a gate. Until 637a6d0 this test took the generated nine-set-up
# set's realistic static-kinetic friction drop, which its first comparison now leaves consistent
# (named with no gate, with the 32-sphere clump and with the 64-sphere one alike); which case
# reaches this gate moves with the replays' bits, and each report's gate_retry says which did.
# Usage: inconsistent_candidate_gate.sh CLUMPFORGE LAB_LIKE_SET
set -u
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$1" diagnose --recordings "$2/case-10" --mesh "$2/meshes/sphere.stl" --output "$dir/out" --json \
  >"$dir/report.json" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
python3 - "$dir/out/report.json" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
g = r.get("gate_retry")
assert g, "expected a gate: " + r["statement"]
assert g["gate"] == "candidate_inconsistent", g
assert g["value"] < g["threshold"], g  # inconsistent on the first draw
assert not g["held"] and g["checks"] == [], g  # no check: compared again whole
assert g["seconds_second"] > 10 * g["seconds_checks"], g
assert g["replays_first"] == 12 and g["replays_second"] == 48, g
assert any("only in a whole comparison" in n for n in r["notes"]), r["notes"]
for rung in (r.get("particle_model") or {}).get("rungs", []):
    shift = rung.get("outcome_shift")
    assert not shift or shift["replays"] == 48, rung  # every move measured on 48 replays
assert r["verdict"] == "com_offset", r["statement"]
PY
