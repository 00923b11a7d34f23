# Sourced by the slow gate test: generates one effect's cases of the bench's default set (four
# set-ups x 4 trials, the default seed; each case's seed is its own, whatever --effects picks) and
# diagnoses one of them as the bench does: against the ladder's 64-sphere clump (the one diagnose
# --mesh fills on this scan) and its two finer ones, with diagnose's defaults.
# Usage: diagnose_generated_case BENCH CLUMPFORGE LIBRARY EFFECT MAGNITUDE
# Sets `dir` (removed on exit) and writes the report to "$dir/out/report.json".
diagnose_generated_case() {
  local bench=$1 clumpforge=$2 library=$3 effect=$4 magnitude=$5
  dir=$(mktemp -d)
  trap 'rm -rf "$dir"' EXIT
  "$bench" --controls 0 --effects "$effect" --generate-only -o "$dir/gen" >"$dir/gen.log" 2>&1 ||
    { cat "$dir/gen.log"; return 1; }
  "$clumpforge" diagnose --recordings "$dir/gen/$effect-$magnitude/recordings" --library "$library" \
    --clump adaptive-64 --output "$dir/out" --json >"$dir/report.json" 2>"$dir/err" ||
    { cat "$dir/err"; return 1; }
}
