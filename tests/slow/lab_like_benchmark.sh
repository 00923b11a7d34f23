#!/usr/bin/env bash
# The full blind benchmark on the independent simulator's set (label `slow`, about an hour on
# two cores): runs bench_diagnose --recordings-set and checks the targets of issue 12 that
# guard users against wrong answers: no control named as an effect, 10 or more of the 12
# controls `none`. The effects named right are printed (the 10-of-14 target is reported, see
# docs/diagnose.md).
set -euo pipefail
bench=$1 set=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$bench" --recordings-set "$set" --out "$out"
python3 - "$out/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"effects named right {s['effects_right']}/{s['effects']}, controls none {s['controls_none']}/{s['controls']}, "
      f"controls named {s['controls_named']}, median {s['median_seconds']:.1f} s")
ok = s['controls_named'] == 0 and s['controls_none'] >= 10
sys.exit(0 if ok else 1)
PY
