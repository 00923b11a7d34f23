#!/bin/bash
# A rolling law the fit from the null never reaches is named from a held start (docs/diagnose.md,
# "A held start for a fit that ends on the null"). The sphere benchmark's strong EPSD rolling case
# (the bench's default seed; an exact sphere of the independent simulator's radius with the EPSD
# rolling resistance at compliance 30, concealed; diagnosed with its mesh's one-sphere fill): from
# the null, the candidate's fit never left compliance 0 (constant torque and the EPSD spring are
# two rolling models, and the truth needs the compliance up and mu_r down together), and the case
# ended `unexplained`. Held at the first search's two points nearest the null (compliance 16 and
# 40, neither the truth) with the coefficients refitted first, the fit reaches 30 and the law is
# named. At compliance 12, 20, 25, 40 and 60 (the same seed) the fit from the null finds it alone.
# Usage: sphere_epsd_held_start.sh SOURCE_DIR BUILD_DIR SPHERE_MESH
set -u
export SPHERE_MESH=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
bash "$1/bench/bench_diagnose_sphere.sh" "$dir/gen" "$2" -- --effects epsd_rolling --controls 0 --generate-only \
  >"$dir/gen.log" 2>&1 || { cat "$dir/gen.log"; exit 1; }
"$2/tools/clumpforge" diagnose --recordings "$dir/gen/epsd_rolling-strong/recordings" --library "$dir/gen/sphere.h5" \
  --finer-clumps 0 --output "$dir/out" --json >"$dir/report.json" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
python3 - "$dir/out/report.json" "$dir/gen/epsd_rolling-strong/answer.json" <<'PY' || exit 1
import json, sys
r = json.load(open(sys.argv[1]))
truth = json.load(open(sys.argv[2]))["effect_parameters"]["rolling_compliance"]
assert truth == 30, truth
assert r["held_starts"], r["held_starts"]
assert r["verdict"] == "epsd_rolling", (r["verdict"], r["statement"])
# Within 5 % of the truth (measured: 29.56). Not its 95 % interval ([29.42, 29.70] excludes 30):
# that interval is conditional on the coefficients (docs/diagnose.md, Limits), too narrow here.
c = r["effect_parameters"]["rolling_compliance"]
assert abs(c["value"] - truth) < 0.05 * truth, c
PY
