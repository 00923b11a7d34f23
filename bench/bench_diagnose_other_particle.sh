#!/usr/bin/env bash
# The blind benchmark of `diagnose` on another bundled scan than the one it was developed on:
# the scan repaired, the generator's body its library's finest adaptive clump (clumps/SCAN.h5,
# as scripts/make-clumps.sh made it: a tenth of its 1 mm lattice's spheres, 260-650 for the
# bundled scans; choose one above 256 by more than a little, e.g. tuber-03 341, tuber-05 514),
# the diagnosed clump an adaptive fill of 32 spheres and its particle-model ladder 64, 128 and
# 256 spheres, made here from the repaired scan exactly as clumps/tuber-default-ladder.h5 is.
# Then bench_diagnose with those, and any further options (for example --controls 20, --fps 240
# --noise 5e-4).
#
#   bash bench/bench_diagnose_other_particle.sh SCAN OUT [BUILD_DIR] [-- bench_diagnose options]
#   bash bench/bench_diagnose_other_particle.sh tuber-03 bench-out/tuber-03 -- --controls 20
# Writes OUT/ladder.h5 and bench_diagnose's OUT/summary.md and OUT/summary.json.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
[ $# -ge 2 ] || { echo "usage: bench_diagnose_other_particle.sh SCAN OUT [BUILD_DIR] [-- options]" >&2; exit 2; }
scan=$1
out=$2
shift 2
script=bench_diagnose_other_particle
source "$here/bench/bench_tools.sh"
mesh="$here/meshes/$scan.stl"
library="$here/clumps/$scan.h5"
for f in "$mesh" "$library"; do [ -f "$f" ] || { echo "bench_diagnose_other_particle: no $f" >&2; exit 1; }; done
# The generator's body: the library's adaptive clump with the most spheres.
generator=$(h5ls "$library/clumps" | awk '$1 ~ /^adaptive-/ { n = substr($1, 10) + 0; if (n > best) { best = n; name = $1 } } END { print name }')
[ -n "$generator" ] || { echo "bench_diagnose_other_particle: no adaptive clump in $library" >&2; exit 1; }
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$cli" repair "$mesh" -o "$work/body.stl" > /dev/null
"$cli" fill "$work/body.stl" -o "$work/ladder.h5" --method adaptive --max-spheres 32 > /dev/null
for n in 64 128 256; do
  "$cli" fill "$work/body.stl" -o "$work/ladder.h5" --append --method adaptive --max-spheres "$n" > /dev/null
done
mv "$work/ladder.h5" "$out/ladder.h5"
echo "$scan: recordings from $library:$generator, diagnosed with $out/ladder.h5 (adaptive-32; 64, 128, 256)"
"$bench" --generator-library "$library" --generator-clump "$generator" --library "$out/ladder.h5" --clump adaptive-32 \
  -o "$out" "$@"
