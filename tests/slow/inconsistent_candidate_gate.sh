#!/bin/bash
# A candidate that beats the null far past the margin yet leaves the outcomes inconsistent is a
# gate of its own, compared again whole with 48 replays per recording (docs/diagnose.md, "An
# inconsistent candidate is a gate, and each rung's move is measured on 48 replays"). The
# generated nine-set-up set's realistic static-kinetic friction drop (the bench's default seed):
# on 12 replays per recording the drop beats the null by delta-BIC 101.8 but leaves chi^2 80.6
# over 36 means and spreads (tail 1.8e-5); with 48 it is calibrated to consistency and named.
# Each finer clump's move is measured on 48 replays from the start, so no move is a gate.
set -u
source "$(dirname "$0")/generated_case.sh"
diagnose_generated_case "$1" "$2" "$3" nine static_kinetic_friction realistic || exit 1
python3 - "$dir/out/report.json" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
g = r.get("gate_retry")
assert g, "expected a gate: " + r["statement"]
assert g["gate"] == "candidate_inconsistent", g
assert g["value"] < g["threshold"], g  # inconsistent on the first draw
assert not g["held"] and g["checks"] == [], g  # no check: compared again whole
assert g["seconds_second"] > 10 * g["seconds_checks"], g
assert g["replays_second"] == 48, g
assert any("only in a whole comparison" in n for n in r["notes"]), r["notes"]
for rung in r["particle_model"]["rungs"]:
    shift = rung.get("outcome_shift")
    assert not shift or shift["replays"] == 48, rung  # every move measured on 48 replays
assert r["verdict"] == "static_kinetic_friction", r["statement"]
PY
