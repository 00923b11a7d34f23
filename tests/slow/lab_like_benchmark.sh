#!/usr/bin/env bash
# The full blind benchmark on the independent simulator's set (label `slow`, about an hour on
# two cores): runs bench_diagnose --recordings-set and checks issue 12's targets on it: no
# control named as an effect, 10 or more of the 12 controls `none`, and 10 or more of the 14
# effects named right (docs/diagnose.md, "At a glance"; asserted since stop 102, where it was
# printed only).
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
ok = s['controls_named'] == 0 and s['controls_none'] >= 10 and s['effects_right'] >= 10
sys.exit(0 if ok else 1)
PY
