# Sourced by the slow sphere tests: sphere_case SOURCE_DIR BUILD_DIR EFFECT MAGNITUDE makes the
# sphere benchmark's recordings of EFFECT (the bench's default seed; bench_diagnose_sphere.sh,
# SPHERE_MESH set by the caller) in a temporary $dir, removed on exit, and diagnoses the
# EFFECT-MAGNITUDE case as a user would: $dir/out/report.json, and its answer in
# $dir/gen/EFFECT-MAGNITUDE/answer.json. Exits 1, printing the log, if either step fails.
sphere_case() {
  dir=$(mktemp -d)
  trap 'rm -rf "$dir"' EXIT
  bash "$1/bench/bench_diagnose_sphere.sh" "$dir/gen" "$2" -- --effects "$3" --controls 0 --generate-only \
    >"$dir/gen.log" 2>&1 || { cat "$dir/gen.log"; exit 1; }
  "$2/tools/clumpforge" diagnose --recordings "$dir/gen/$3-$4/recordings" --library "$dir/gen/sphere.h5" \
    --finer-clumps 0 --output "$dir/out" --json >"$dir/report.json" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
}
