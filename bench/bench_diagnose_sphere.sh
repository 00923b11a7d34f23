#!/usr/bin/env bash
# The blind benchmark of `diagnose` on a sphere of the tuber's material: the experiment its
# reports advise when a tuber's unknown release orientation hides an effect ("repeat the tests
# with a sphere of the same material, whose path does not depend on it"). The recordings come
# from the exact sphere the mesh was made of (the radius of its vertices, density 1085 kg/m^3:
# a tessellated mesh holds a little less volume than the body, as a scan does); the diagnosed
# clump is the mesh's adaptive fill of one sphere (what `diagnose --mesh` takes for it by
# convergence: the mesh's volume and mass), without a finer ladder (a sphere has none). Then
# bench_diagnose with those, and any further options (for example --controls 10).
#
#   bash bench/bench_diagnose_sphere.sh OUT [BUILD_DIR] [-- bench_diagnose options]
#   bash bench/bench_diagnose_sphere.sh bench-out/sphere -- --controls 10
# Writes OUT/sphere.h5 (the diagnosed clump), OUT/exact-sphere.h5 (the generator's body) and
# bench_diagnose's OUT/summary.md and OUT/summary.json. The mesh is the independent simulator's
# sphere (../shared/data/lab-like/meshes/sphere.stl, r 9.35 mm), or $SPHERE_MESH.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
[ $# -ge 1 ] || { echo "usage: bench_diagnose_sphere.sh OUT [BUILD_DIR] [-- options]" >&2; exit 2; }
out=$1
shift
script=bench_diagnose_sphere
source "$here/bench/bench_tools.sh"
mesh="${SPHERE_MESH:-$here/../shared/data/lab-like/meshes/sphere.stl}"
[ -f "$mesh" ] || { echo "bench_diagnose_sphere: no $mesh" >&2; exit 1; }
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$cli" fill "$mesh" -o "$work/sphere.h5" --method adaptive --max-spheres 1 --density 1085 > /dev/null
PYTHONPATH="$build/python" /usr/bin/python3 - "$mesh" "$work/sphere.h5" "$work/exact-sphere.h5" <<'PY'
import math, sys
import numpy as np
import clumpforge as cf
vertices = np.asarray(cf.load_mesh(sys.argv[1], units="mm").vertices)
r = float(np.median(np.linalg.norm(vertices - vertices.mean(axis=0), axis=1)))
fill = cf.read_library(sys.argv[2])[0]
volume = 4.0 / 3.0 * math.pi * r**3
mass = fill.density * volume
moment = 0.4 * mass * r * r
exact = cf.Clump("exact-sphere", np.zeros((1, 3)), np.array([r]), fill.density, mass,
                 np.array([moment, moment, moment]), volume)
cf.write_library(sys.argv[3], [exact])
print(f"recordings from an exact sphere of r {r * 1e3:.4f} mm, {mass * 1e3:.4f} g; diagnosed with the mesh's "
      f"fill, r {fill.radii[0] * 1e3:.4f} mm, {fill.mass * 1e3:.4f} g")
PY
mv "$work/sphere.h5" "$out/sphere.h5"
mv "$work/exact-sphere.h5" "$out/exact-sphere.h5"
"$bench" --generator-library "$out/exact-sphere.h5" --generator-clump exact-sphere --library "$out/sphere.h5" \
  --clump adaptive-1 --finer-clumps 0 -o "$out" "$@"
