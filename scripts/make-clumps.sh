#!/usr/bin/env bash
# Regenerates clumps/ from the bundled scans in meshes/ (run after scripts/build.sh):
#  clumps/<scan>.h5       clump library: lattice 1, 2, 4 mm (the study's method) and adaptive
#                         clumps with as many spheres as the 4 and 2 mm lattices and a tenth
#                         of the 1 mm lattice's;
#  clumps/<scan>/<clump>/ exports of each clump in every format (the 1 mm lattice, eight
#                         times larger, only in the library: `clumpforge export` writes it).
# For the batch scans (tuber-01..10) the exports are those of the 2 mm lattice and of the
# adaptive clump of the same size.
set -euo pipefail
cd "$(dirname "$0")/.."
cf=build/tools/clumpforge
[ -x "$cf" ] || { echo "build first: bash scripts/build.sh" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
names() { /usr/bin/python3 -c 'import json, sys; print(" ".join(c["name"] for c in json.load(sys.stdin)["clumps"]))'; }
counts() { /usr/bin/python3 -c 'import json, sys; print(" ".join(str(c["sphere_count"]) for c in json.load(sys.stdin)["clumps"]))'; }
source scripts/export-all.sh
rm -rf clumps
mkdir -p clumps
for scan in meshes/*.stl; do
  name=$(basename "$scan" .stl)
  body="$work/$name.stl"
  lib="clumps/$name.h5"
  $cf repair "$scan" -o "$body" > /dev/null
  read -r n1 n2 n4 <<< "$($cf fill "$body" -o "$lib" --diameters 1,2,4mm --json | counts)"
  adaptive=()
  for n in "$n4" "$n2" $((n1 / 10)); do
    adaptive+=("$($cf fill "$body" -o "$lib" --append --method adaptive --max-spheres "$n" --json | names)")
  done
  if [ "$name" = tuber-default ]; then
    for clump in lattice-2mm lattice-4mm "${adaptive[@]}"; do export_all "$lib" "$clump" "clumps/$name"; done
  else
    for clump in lattice-2mm "${adaptive[1]}"; do export_all "$lib" "$clump" "clumps/$name"; done
  fi
  echo "clumps/$name.h5: lattice $n1 / $n2 / $n4 spheres; ${adaptive[*]}"
done
# The diagnosis's particle: the default scan as a small adaptive clump (the diagnosis replays
# every tracked trial a few thousand times), and the bundled concealed-effect recordings.
$cf repair meshes/tuber-default.stl -o "$work/diagnosis.stl" > /dev/null
$cf fill "$work/diagnosis.stl" -o clumps/tuber-default-diagnosis.h5 --method adaptive --max-spheres 32 > /dev/null
# The same 32-sphere clump with finer fills of the scan (64, 128, 256; not the generator's 340):
# the generated benchmark's diagnosis checks its particle model against them.
$cf fill "$work/diagnosis.stl" -o clumps/tuber-default-ladder.h5 --method adaptive --max-spheres 32 > /dev/null
for n in 64 128 256; do
  $cf fill "$work/diagnosis.stl" -o clumps/tuber-default-ladder.h5 --append --method adaptive --max-spheres $n > /dev/null
done
# Made from a finer clump of the same scan (adaptive-340) with the generator's finer time step,
# and, like a lab's, with no release orientation recorded.
build/tools/clumpforge-conceal clumps/tuber-default.h5 --clump adaptive-340 --effect air_drag --magnitude realistic --small --trials 4 --seed 7 \
  --output clumps/tuber-default-diagnosis/recordings --answer clumps/tuber-default-diagnosis/answer.json
echo "clumps/tuber-default-diagnosis.h5: adaptive-32; concealed-effect recordings (from adaptive-340) in clumps/tuber-default-diagnosis/"
echo "clumps/tuber-default-ladder.h5: adaptive-32, -64, -128, -256"
