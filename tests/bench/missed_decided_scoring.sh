#!/bin/bash
# bench_diagnose's count of strong effects missed yet called decided, on stored reports
# (--existing-only): a `none` that leaves the truth out of `undecidable` counts; an `ambiguous`
# verdict whose candidates hold the truth does not (it claims no absence), nor does a truth
# listed as undecidable.
set -u
bench=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
case_dir() {  # name effect verdict candidates-json undecidable-json
  mkdir -p "$dir/out/$1"
  printf '{"format":"clumpforge-concealed-answer/1","effect":"%s","effect_parameters":{},"surface":"Q235","seed":1}\n' \
    "$2" >"$dir/out/$1/answer.json"
  printf '{"verdict":"%s","candidates":%s,"undecidable":%s,"seconds":1,"fit":{"before":{"heldout_rms_mm":0.1},"after":{"heldout_rms_mm":0.1}}}\n' \
    "$3" "$4" "$5" >"$dir/out/$1/report.json"
}
score() {
  "$bench" -o "$dir/out" --full-set --controls 1 --existing-only 2>&1 | grep "strong effects missed"
}
case_dir viscoelastic_restitution-strong viscoelastic_restitution ambiguous \
  '["viscoelastic_restitution","elastic_plastic_restitution"]' '[]'
case_dir adhesion-strong adhesion none '[]' '[]'
line=$(score)
case "$line" in *": 1/2") ;; *) echo "expected 1/2 (the none only): $line"; exit 1 ;; esac
case_dir adhesion-strong adhesion none '[]' '["adhesion"]'
line=$(score)
case "$line" in *": 0/2") ;; *) echo "expected 0/2 (adhesion undecidable): $line"; exit 1 ;; esac
echo ok
