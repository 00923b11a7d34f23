#!/usr/bin/env bash
# README command 1: set up, build, and run the main job on the bundled default scan.
# Results go to out/main/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
cf=./build/tools/clumpforge
scan=meshes/tuber-default.stl
mkdir -p out/main
echo
echo "== 1. repair the raw scan ($scan)"
$cf repair "$scan" -o out/main/tuber-default.stl
echo
echo "== 2. mass properties of the repaired body at the study's density (1085 kg/m^3)"
$cf props out/main/tuber-default.stl --density 1085
$cf props out/main/tuber-default.stl --density 1085 --json > out/main/tuber-default.props.json
echo
echo "main job done: out/main/tuber-default.stl, out/main/tuber-default.props.json"
