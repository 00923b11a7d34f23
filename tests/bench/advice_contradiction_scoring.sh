#!/bin/bash
# bench_diagnose's count of reports whose advice contradicts their verdict, on stored reports
# (--existing-only): `decided` must be said of exactly the effects left out of `undecidable`, and
# `not_judged` of none; a report that judged no candidate on the outcomes is not counted.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
case_dir() {  # name effect undecidable-json detectability-json (null: no ensemble)
  mkdir -p "$dir/out/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/out/$1/answer.json"
  local ensemble=null
  [ "$4" != null ] && ensemble="{\"detectability\":$4}"
  printf '{"verdict":"none","candidates":[],"undecidable":%s,"ensemble":%s,"seconds":1,"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n' \
    "$3" "$ensemble" >"$dir/out/$1/report.json"
}
score() {
  "$bench" -o "$dir/out" --full-set --controls 2 --existing-only 2>&1 | grep "advice contradicts"
}
expect() {  # what the line must end with, why
  line=$(score)
  case "$line" in *": $1") ;; *) echo "expected $1 ($2): $line"; exit 1 ;; esac
}
agree='[{"name":"adhesion","advice":"decided"},{"name":"air_drag","advice":"floor"}]'
case_dir control-01 none '["air_drag"]' "$agree"
case_dir control-02 none '[]' null
case_dir adhesion-strong adhesion '["air_drag"]' "$agree"
expect "0/2" "both agree; the report without an ensemble is not counted"
case_dir adhesion-strong adhesion '["adhesion","air_drag"]' "$agree"
expect "1/2" "decided said of an effect listed undecidable"
case_dir adhesion-strong adhesion '[]' "$agree"
expect "1/2" "air_drag left out of undecidable, yet not said decided"
case_dir adhesion-strong adhesion '["air_drag"]' '[{"name":"adhesion","advice":"not_judged"},{"name":"air_drag","advice":"floor"}]'
expect "1/2" "not_judged in a final report"
echo ok
