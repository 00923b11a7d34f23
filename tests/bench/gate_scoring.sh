#!/bin/bash
# bench_diagnose counts the cases whose comparison beyond the release horizon decided at a gate (the
# report's gate_retry), by gate, how many of them held when judged again with more replays (not
# compared again), with the median time of those cases, of the others and of every case without
# what followed its first comparison (its seconds less seconds_second), on stored reports
# (--existing-only), in both scorers.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
source "$(dirname "$0")/scoring_common.sh"
report='{"verdict":"none","candidates":[],"undecidable":[],"seconds":%s,%s"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n'
gate='"gate_retry":{"gate":"%s","value":1e-4,"threshold":5e-5,"replays_first":12,"replays_second":48,"replayed_first":100,"seconds_second":%s,"held":%s,"statement":"x"},'
case_dir() {  # name effect seconds gate seconds_second [held]
  mkdir -p "$dir/gen/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/gen/$1/answer.json"
  local g=""
  [ -n "$4" ] && g=$(printf "$gate" "$4" "$5" "${6:-false}")
  printf "$report" "$3" "$g" >"$dir/gen/$1/report.json"
}
case_dir air_drag-strong air_drag 10 ""
case_dir adhesion-strong adhesion 100 null_consistency 60
case_dir control-01 none 20 candidate_margin 5 true  # held: not compared again
case_dir control-02 none 30 null_consistency 10
score_generated "$dir/gen"
expect_line "$dir/gen/summary.md" "compared again beyond the release horizon" \
  "compared again beyond the release horizon with more replays, the first draw at a gate: 3/4 (candidate_margin 1, null_consistency 2); of those, the gates' decisions held with more replays (not compared again): 1; median time of those at a gate 30.0 s, of the others 10.0 s; of every case without what followed its first comparison 17.5 s"
# An independent set scored with --recordings-set: no case at a gate.
two_case_set
printf "$report" 5 "" >"$dir/out/case-a/report.json"
printf "$report" 7 "$(printf "$gate" convergence 3 false)" >"$dir/out/case-b/report.json"
score_set
expect_line "$dir/out/summary.md" "compared again beyond the release horizon" \
  "compared again beyond the release horizon with more replays, the first draw at a gate: 1/2 (convergence 1); of those, the gates' decisions held with more replays (not compared again): 0; median time of those at a gate 7.0 s, of the others 5.0 s; of every case without what followed its first comparison 4.5 s"
python3 - "$dir/out/summary.json" <<'PY' || exit 1
import json, sys
s = json.load(open(sys.argv[1]))["second_comparisons"]
assert s["cases"] == 1 and s["of"] == 2 and s["held"] == 0 and s["gates"] == {"convergence": 1}, s
assert s["median_seconds_again"] == 7 and s["median_seconds_once"] == 5 and s["median_seconds_without"] == 4.5, s
PY
# A second draw too small to have a spread is refused before any case is made.
if "$bench" -o "$dir/refused" --ensemble-replays-at-gate 2 >"$dir/log" 2>&1; then
  echo "--ensemble-replays-at-gate 2 was accepted"; exit 1
fi
grep -q -- "--ensemble-replays-at-gate" "$dir/log" || { cat "$dir/log"; exit 1; }
[ ! -e "$dir/refused" ] || { echo "a refused run wrote $dir/refused"; exit 1; }
echo ok
