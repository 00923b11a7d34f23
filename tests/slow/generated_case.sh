# Sourced by the slow gate tests: generates the nine-set-up, 8-trial set's cases of one effect
# (the bench's default seed) and diagnoses one of them against the ladder's 32-sphere clump and its
# three finer ones (the bench's diagnosis until it took diagnose's own 64-sphere fill and two finer
# clumps): the gates these tests read are reached there.
# Usage: diagnose_generated_case BENCH CLUMPFORGE LIBRARY EFFECT MAGNITUDE; sets `dir` (removed
# on exit) and writes the report to "$dir/out/report.json".
diagnose_generated_case() {
  local bench=$1 clumpforge=$2 library=$3 effect=$4 magnitude=$5
  dir=$(mktemp -d)
  trap 'rm -rf "$dir"' EXIT
  "$bench" --nine-set-ups --trials 8 --controls 0 --effects "$effect" --generate-only -o "$dir/gen" \
    >"$dir/gen.log" 2>&1 || { cat "$dir/gen.log"; return 1; }
  "$clumpforge" diagnose --recordings "$dir/gen/$effect-$magnitude/recordings" --library "$library" \
    --clump adaptive-32 --finer-clumps 3 --output "$dir/out" --json >"$dir/report.json" 2>"$dir/err" ||
    { cat "$dir/err"; return 1; }
}
