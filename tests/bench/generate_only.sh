#!/bin/bash
# bench_diagnose --generate-only makes each case's recordings and answer and diagnoses none; the
# answer of an effect case carries each trial's summary with the effect and without it (its
# twin, from the same release), a control's none; --generate-only with --existing-only is refused.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
if "$bench" --generate-only --existing-only -o "$dir/refused" >"$dir/log" 2>&1; then
  echo "--generate-only with --existing-only was accepted"; exit 1
fi
# Two trials per recording: what is checked holds trial by trial (174 s with the default four).
"$bench" --generate-only --effects air_drag --controls 1 --trials 2 -o "$dir/out" >"$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
for c in air_drag-realistic air_drag-strong control-01; do
  [ -f "$dir/out/$c/answer.json" ] && [ -d "$dir/out/$c/recordings" ] || { echo "$c: not made"; exit 1; }
  [ ! -e "$dir/out/$c/report.json" ] || { echo "$c: diagnosed"; exit 1; }
done
[ ! -e "$dir/out/summary.md" ] || { echo "scored"; exit 1; }
python3 - "$dir/out" <<'PY' || exit 1
import json, os, sys
out = sys.argv[1]
a = json.load(open(f"{out}/air_drag-strong/answer.json"))
recs = a["recordings"]
assert sorted(recs) == sorted(os.listdir(f"{out}/air_drag-strong/recordings")), recs.keys()
for name, r in recs.items():
    manifest = json.load(open(f"{out}/air_drag-strong/recordings/{name}/recording.json"))
    assert r["test"] == manifest["test"] and len(r["trials"]) == len(manifest["trials"]) == 2, name
    for t, m in zip(r["trials"], manifest["trials"]):
        # The recorded summary is the trial's value with the effect.
        assert abs(t["value"] - next(iter(m["summary"].values()))) < 1e-6, (name, t, m)
# Drag slows every flight: a 1 m drop's rebounds differ from their twins'.
assert any(t["value"] != t["value_without_effect"] for t in recs["drop-1m"]["trials"]), recs["drop-1m"]
assert json.load(open(f"{out}/control-01/answer.json"))["recordings"] == {}
PY
echo ok
