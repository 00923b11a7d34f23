#!/usr/bin/env bash
# README command 1: set up, build, and run the main job on the bundled default scan:
# repair -> mass properties -> fill (lattice 1, 2, 4 mm and adaptive) -> error report -> exports
# -> the study's drop, tilt and roll tests in the built-in DEM.
# Results go to out/main/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cf=./build/tools/clumpforge
scan=meshes/tuber-default.stl
out=out/main
rm -rf "$out"
mkdir -p "$out/exports"
echo
echo "== 1. repair the raw scan ($scan)"
$cf repair "$scan" -o "$out/tuber-default.stl"
echo
echo "== 2. mass properties of the repaired body at the study's density (1085 kg/m^3)"
$cf props "$out/tuber-default.stl" --density 1085
$cf props "$out/tuber-default.stl" --density 1085 --json > "$out/tuber-default.props.json"
echo
echo "== 3. fill: the study's lattice (1, 2, 4 mm spheres) and the adaptive method, with error reports"
$cf fill "$out/tuber-default.stl" -o "$out/tuber-default.h5" --diameters 1,2,4mm
$cf fill "$out/tuber-default.stl" -o "$out/tuber-default.h5" --append --method adaptive --max-spheres 427
$cf fill "$out/tuber-default.stl" -o "$out/tuber-default.h5" --append --method adaptive --max-spheres 128
echo
echo "== 4. exports of the 2 mm lattice (the study's model) and the 128-sphere adaptive clump"
source scripts/export-all.sh
for clump in lattice-2mm adaptive-128; do
  export_all "$out/tuber-default.h5" "$clump" "$out/exports"
  echo "$out/exports/$clump/: $(ls "$out/exports/$clump" | tr '\n' ' ')"
done
echo
echo "== 5. the study's drop, tilt and roll tests on the 2 mm lattice clump in the built-in DEM (study's coefficients)"
for surface in Q235 soil; do
  $cf validate "$out/tuber-default.h5" --clump lattice-2mm --test drop --surface "$surface" --trials 10 --output "$out/dem/drop-$surface"
  $cf validate "$out/tuber-default.h5" --clump lattice-2mm --test tilt --surface "$surface" --trials 1 --output "$out/dem/tilt-$surface"
  $cf validate "$out/tuber-default.h5" --clump lattice-2mm --test roll --surface "$surface" --trials 10 --output "$out/dem/roll-$surface"
done
echo
echo "== 6. diagnosis of a bundled recording set with a concealed effect (clumps/tuber-default-diagnosis/recordings:"
echo "      drops from 0.2 and 1 m, a roll from 100 mm, a tilt; 4 tracked trials each, made by clumpforge-conceal"
echo "      from a 340-sphere clump of the scan, no release orientation recorded)"
$cf diagnose --recordings clumps/tuber-default-diagnosis/recordings --library clumps/tuber-default-diagnosis.h5 --output "$out/diagnosis"
echo
echo "   the generator's answer (read only now, after the diagnosis): $(python3 -c 'import json; a=json.load(open("clumps/tuber-default-diagnosis/answer.json")); print(a["effect"], a["effect_parameters"])')"
echo
echo "main job done: $out/ (repaired mesh, props JSON, clump library tuber-default.h5, exports/, dem/ recordings, diagnosis/ report and plots)"
