#!/bin/bash
# A comparison at a gate whose decision holds when judged again with 48 replays keeps its first
# comparison (docs/diagnose.md, "Each gate judged again before the comparison is"). The generated
# four-set-up set's realistic EPSD rolling resistance (the bench's default seed; at 637a6d0): on 12
# replays per recording its law beats the null by delta-BIC 8.2, within reach of the margin of 10;
# judged again on 48 fresh replays at the same coefficients it beats it by -1.7, below the margin
# again, so the first comparison stands (`none`) and nothing is compared again. Which generated
# case sits at a held gate moves with the replays' bits: `bench/bench_diagnose -o OUT`, then the
# reports' gate_retry, finds today's. What holds of any report: a gate_retry has its checks,
# `held` is whether all held, a check that did not hold is the last, a held retry adds no replay
# to the first comparison's and says so in a note, and its time after the first comparison is
# its checks'.
set -u
source "$(dirname "$0")/generated_case.sh"
diagnose_generated_case "$1" "$2" "$3" epsd_rolling realistic || exit 1
python3 - "$dir/out/report.json" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
g = r.get("gate_retry")
assert g, "expected a gate: " + r["statement"]
checks = g["checks"]
assert checks, g
assert g["held"] == all(c["held"] for c in checks), g
assert all(c["held"] for c in checks[:-1]), g  # the checks stop at the first that does not hold
assert 0 < g["seconds_checks"] <= g["seconds_second"], g
# This case's gate and what its check found: below the margin on both draws.
assert checks[0]["gate"] == "candidate_margin", checks
assert checks[0]["first"] < checks[0]["threshold"] and checks[0]["second"] < checks[0]["threshold"], checks
assert checks[0]["first"] >= 0.5 * checks[0]["threshold"], checks  # within the draw's reach
assert g["held"], g
assert r["ensemble"]["replays"] == g["replayed_first"], (r["ensemble"]["replays"], g)
assert g["seconds_second"] - g["seconds_checks"] < 1.0, g
assert any("decided the same" in n for n in r["notes"]), r["notes"]
assert r["verdict"] == "none", r["statement"]
PY
